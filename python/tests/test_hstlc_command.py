"""The `hstlc` command that `pip install` puts beside the interpreter: the native
binary's output and exit status, Ctrl-C and closed pipes as the binary has them."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from conftest import CLI_FIXTURES, REPO

#: The installed command (the wheel's `[project.scripts]` entry), in this interpreter's
#: own bin directory.
INSTALLED = Path(sys.executable).parent / "hstlc"


def both(hstlc: Path, *args: str, stdin: str = "") -> tuple[subprocess.CompletedProcess, subprocess.CompletedProcess]:
    def run(program: Path) -> subprocess.CompletedProcess:
        return subprocess.run(
            [str(program), *args], cwd=CLI_FIXTURES, input=stdin, capture_output=True, text=True, timeout=120
        )

    return run(INSTALLED), run(hstlc)


def test_the_wheel_installs_the_command():
    assert INSTALLED.is_file() and os.access(INSTALLED, os.X_OK), INSTALLED


@pytest.mark.parametrize(
    "args",
    [
        ["check", str(REPO / "examples" / "specs" / "surveillance_auto.hstl")],
        ["check", "errors.hstl"],
        ["check", "--format", "json", "errors.hstl", "reach.hstl"],
        ["check", "--format", "concise", "nook.hstl", "--world", "four-rooms"],
        ["check", "no-such-file.hstl"],
        ["check", "--no-such-flag"],
        ["explain", "HSTL150"],
        ["monitor", "surveillance.hstl", "--trace", "cycle.csv", "--signal"],
        ["--version"],
        ["--help"],
        [],
    ],
    ids=lambda a: " ".join(a[:2]) or "no-args",
)
def test_the_command_prints_and_exits_as_the_native_binary(hstlc, args):
    installed, native = both(hstlc, *args)
    assert installed.returncode == native.returncode, installed.stderr
    assert installed.stdout == native.stdout
    assert installed.stderr == native.stderr


def test_the_command_reads_standard_input_as_the_native_binary(hstlc):
    text = (CLI_FIXTURES / "errors.hstl").read_text()
    installed, native = both(hstlc, "check", "-", "--stdin-filename", "piped.hstl", stdin=text)
    assert (installed.returncode, installed.stdout, installed.stderr) == (native.returncode, native.stdout, native.stderr)
    assert native.returncode == 1 and "piped.hstl" in native.stdout


def test_a_closed_pipe_ends_the_command_with_status_141_as_the_native_binary(hstlc):
    # `hstlc fmt --help` into a pipe whose reader has gone.
    statuses = []
    for program in (INSTALLED, hstlc):
        # The reader is closed before the program starts, so its first write fails with
        # EPIPE (closing it after the start races with a program that has written it all).
        read, write = os.pipe()
        os.close(read)
        try:
            p = subprocess.Popen([str(program), "fmt", "--help"], stdout=write, stderr=subprocess.PIPE)
        finally:
            os.close(write)
        _, err = p.communicate(timeout=60)
        statuses.append((p.returncode, err))
    assert statuses[0] == statuses[1] == (141, b"")


def start_training(program: Path, out: Path, sigint: "signal.Handlers") -> subprocess.Popen:
    """A long training run, started with SIGINT's disposition set to `sigint` (a test run in
    the background of a script inherits it ignored, so it is set either way)."""
    spec = REPO / "examples" / "specs" / "surveillance_entry.hstl"
    return subprocess.Popen(
        [str(program), "train", str(spec), "--episodes", "1000000", "--out", str(out)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        preexec_fn=lambda: signal.signal(signal.SIGINT, sigint),
    )


def test_ctrl_c_ends_the_command_at_once_as_the_native_binary(hstlc, tmp_path):
    # Both die by SIGINT (no Python traceback).
    results = []
    for program in (INSTALLED, hstlc):
        p = start_training(program, tmp_path / program.parent.name, signal.SIG_DFL)
        time.sleep(2)
        assert p.poll() is None, "the run ended before Ctrl-C"
        p.send_signal(signal.SIGINT)
        _, err = p.communicate(timeout=30)
        results.append((p.returncode, err))
    assert results[0] == results[1]
    assert results[1][0] == -signal.SIGINT


def test_an_inherited_ignored_sigint_stays_ignored_as_in_the_native_binary(hstlc, tmp_path):
    # Under `nohup` or in a script's background job, SIGINT starts ignored: neither program
    # ends on it.
    for program in (INSTALLED, hstlc):
        p = start_training(program, tmp_path / program.parent.name, signal.SIG_IGN)
        try:
            time.sleep(2)
            p.send_signal(signal.SIGINT)
            time.sleep(1)
            assert p.poll() is None, f"{program} ended on an ignored SIGINT"
        finally:
            p.kill()
            p.communicate(timeout=30)
