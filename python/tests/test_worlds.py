"""`hstl.World`: the built-in worlds and world files, their properties, and every bad
world refused with the words of `hstlc --world`."""

from __future__ import annotations

import os
import pickle

import pytest

import hstl
from conftest import CLI_FIXTURES, REPO, run_cli

INVALID = sorted((CLI_FIXTURES / "worlds" / "invalid").glob("*.toml"))


def test_the_built_in_worlds_are_the_contracts():
    paper = hstl.World.builtin("paper")
    assert (paper.name, paper.width, paper.height, paper.slip) == ("paper", 15, 15, 0.3)
    assert paper.map == ["." * 15] * 15 and paper.num_states == 225 and paper.file is None
    # Free cells are the states, row by row from the bottom; every cell starts.
    assert paper.free_cells[:3] == [(0, 0), (1, 0), (2, 0)] and paper.free_cells[15] == (0, 1)
    assert paper.starts == paper.free_cells
    assert paper.actions == ["Up", "Down", "Left", "Right"]
    rooms = hstl.World.builtin("four-rooms")
    assert (rooms.width, rooms.height, rooms.num_states) == (13, 13, 13 * 13 - 65)
    assert rooms.map == (REPO / "examples" / "worlds" / "four-rooms.toml").read_text().split('"""')[1].split()
    assert not rooms.is_free(0, 0) and rooms.is_free(1, 1) and not rooms.is_free(-1, 3)
    assert not rooms.is_free(13, 1)
    with pytest.raises(OverflowError):
        rooms.is_free(2**70, 1)


def test_a_world_file_has_its_walls_starts_and_name():
    path = REPO / "examples" / "worlds" / "corridors.toml"
    world = hstl.World.load(path)
    assert world.file == str(path) and world.name == "corridors" and world.slip == 0.1
    text = path.read_text()
    assert world.map == [line for line in text.split('"""')[1].splitlines() if line.strip()]
    assert len(world.starts) < len(world.free_cells)
    assert all(world.map[world.height - 1 - y][x] == "S" for x, y in world.starts)
    assert all(world.is_free(x, y) for x, y in world.free_cells)
    parsed = hstl.World.parse(text, filename="corridors.toml", name="corridors")
    assert parsed == world and hash(parsed) == hash(world)
    # A file without `name` is named after the file.
    assert hstl.World.parse('map = """\n.S\n"""\n', name="tiny").name == "tiny"


@pytest.mark.parametrize("world", ["paper", "four-rooms", "corridors"])
def test_worlds_pickle_by_their_contents(world):
    w = hstl.World.load(REPO / "examples" / "worlds" / "corridors.toml") if world == "corridors" else hstl.World.builtin(world)
    for protocol in range(pickle.HIGHEST_PROTOCOL + 1):
        back = pickle.loads(pickle.dumps(w, protocol))
        assert back == w and (back.name, back.slip, back.map, back.file) == (w.name, w.slip, w.map, w.file)
        assert back.starts == w.starts and back.free_cells == w.free_cells


def first_error(result) -> list[str]:
    assert result.returncode == 2, result.stderr
    lines = result.stderr.splitlines()
    assert lines[0].startswith("error: "), result.stderr
    return [lines[0][len("error: "):], *lines[1:]]


@pytest.mark.parametrize("path", INVALID, ids=[p.stem for p in INVALID])
def test_every_bad_world_file_raises_what_hstlc_prints(hstlc, monkeypatch, path):
    monkeypatch.chdir(CLI_FIXTURES)
    relative = os.path.relpath(path, CLI_FIXTURES)
    want = first_error(run_cli(hstlc, "check", "small.hstl", "--world", relative))
    with pytest.raises(hstl.WorldError) as e:
        hstl.World.load(relative)
    assert str(e.value).splitlines() == want
    # Training there says the same before anything runs.
    with pytest.raises(hstl.WorldError) as trained:
        hstl.train("small.hstl", world=relative, episodes=1)
    assert str(trained.value) == str(e.value)


@pytest.mark.parametrize(
    "arg, kind",
    [("mars", hstl.WorldError), ("mars.toml", FileNotFoundError), ("worlds/", IsADirectoryError)],
    ids=["unknown name", "missing file", "a folder"],
)
def test_unknown_and_unreadable_worlds_raise_what_hstlc_prints(hstlc, monkeypatch, arg, kind):
    monkeypatch.chdir(CLI_FIXTURES)
    want = first_error(run_cli(hstlc, "train", "small.hstl", "--world", arg, "--out", "unused"))
    with pytest.raises(kind) as e:
        hstl.train("small.hstl", world=arg, episodes=1)
    assert str(e.value).splitlines() == want
    if arg == "mars":
        with pytest.raises(hstl.WorldError) as builtin:
            hstl.World.builtin("mars")
        assert str(builtin.value) == str(e.value)


@pytest.mark.parametrize("load", ["hstl.World.load", "hstl.ContinuousWorld.load"])
def test_a_named_pipe_is_refused_not_waited_on(tmp_path, load):
    # Opening a named pipe for reading waits for a writer: `World.load` and
    # `ContinuousWorld.load` refuse it first, as `hstlc --world` does (issue 30: the
    # continuous one waited). A child process, so that a hang fails the test instead of it.
    import subprocess
    import sys

    fifo = tmp_path / "world.toml"
    os.mkfifo(fifo)
    code = (
        "import sys, hstl\n"
        "try:\n"
        f"    {load}(sys.argv[1])\n"
        "except ValueError as e:\n"
        "    print(type(e).__name__, e)\n"
    )
    run = subprocess.run(
        [sys.executable, "-c", code, str(fifo)], capture_output=True, text=True, timeout=60
    )
    assert run.returncode == 0, run.stderr
    assert "is a named pipe, not a regular file" in run.stdout, run.stdout
    assert "read only from a regular file" in run.stdout, run.stdout
