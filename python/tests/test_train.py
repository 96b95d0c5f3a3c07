"""`hstl.train` writes what `hstlc train` writes, byte for byte; `Policy.load` refuses what
`hstlc eval` refuses, in its words; `policy.evaluate` reports `hstlc eval`'s figures."""

from __future__ import annotations

import json
import re
import shutil

import numpy as np
import pytest

import hstl
from conftest import CLI_FIXTURES, REPO, run_cli

SMALL = CLI_FIXTURES / "small.hstl"
REACH = CLI_FIXTURES / "reach.hstl"


def cli_train(hstlc, tmp_path, spec, *args):
    out = tmp_path / "cli"
    result = run_cli(hstlc, "train", str(spec), "--out", str(out), *args)
    assert result.returncode == 0, result.stderr
    return (out / "policy.json").read_bytes()


@pytest.mark.parametrize(
    "spec, world, seed, episodes",
    [
        (SMALL, "paper", 0, 4),
        (SMALL, "paper", 2**64 - 1, 3),
        (REPO / "examples" / "specs" / "corridors_patrol.hstl", REPO / "examples" / "worlds" / "corridors.toml", 5, 2),
        (REPO / "examples" / "specs" / "four_rooms_patrol.hstl", "four-rooms", 1, 2),
        (CLI_FIXTURES / "nook.hstl", CLI_FIXTURES / "worlds" / "nook.toml", 3, None),
    ],
    ids=["paper", "the largest seed", "a world file with walls", "four rooms", "the spec's episodes"],
)
def test_train_writes_the_bytes_hstlc_train_writes(hstlc, tmp_path, spec, world, seed, episodes):
    args = ["--world", str(world), "--seed", str(seed)] + (["--episodes", str(episodes)] if episodes else [])
    want = cli_train(hstlc, tmp_path, spec, *args)
    policy = hstl.train(spec, world=world, seed=seed, episodes=episodes)
    assert policy.json.encode() == want
    policy.save(tmp_path / "py.json")
    assert (tmp_path / "py.json").read_bytes() == want
    # From a Spec and a World object too, and the same Q-tables for the same seed.
    again = hstl.train(hstl.Spec.load(spec), world=hstl.World._resolve(str(world)), seed=seed, episodes=episodes)
    assert again == policy and again.curve.tolist() == policy.curve.tolist()
    assert policy.seed == seed and policy.spec_name == json.loads(want)["spec"]
    assert len(policy.curve) == (episodes or len(policy.curve)) and policy.steps > 0


def test_policies_load_save_and_expose_their_tables(tmp_path):
    policy = hstl.train(SMALL, seed=1, episodes=3)
    path = tmp_path / "policy.json"
    policy.save(path)
    loaded = hstl.Policy.load(path)
    assert loaded == policy and loaded.curve is None and loaded.steps is None
    assert (loaded.world, loaded.env_name, loaded.state_vars) == (hstl.World.builtin("paper"), "paper", ["x", "y"])
    assert loaded.actions == ["Up", "Down", "Left", "Right"] and loaded.options == ["A", "B", "AB"]
    assert loaded.spec.name == "Small" and loaded.spec.source == SMALL.read_text()
    q = loaded.q_tables
    doc = json.loads(policy.json)
    assert set(q["flat"]) == {"A", "B"} and q["options"].shape == (225, 3)
    for name, table in q["flat"].items():
        assert table.shape == (225, 4) and table.dtype == np.float64
        bits = [f"{v:016x}" for v in table.ravel().view(np.uint64)]
        assert bits == doc["q_tables"]["flat"][name]
    # The greedy choices are the tables' argmax (ties to the lowest index).
    flat_a = {(e["state"]["x"], e["state"]["y"]): e["choice"] for e in doc["flat_policies"]["A"]}
    for s, (x, y) in enumerate(loaded.world.free_cells):
        assert flat_a[(x, y)] == loaded.actions[int(np.argmax(q["flat"]["A"][s]))]
    # Saving replaces a file whole and leaves nothing else behind.
    path.write_text("old")
    policy.save(path)
    assert path.read_text() == policy.json and sorted(p.name for p in tmp_path.iterdir()) == ["policy.json"]


def eval_figures(stdout: str) -> dict:
    figures = {"window_rate": re.search(r"window rate (\d\.\d+) \(runs", stdout)}
    figures["baseline"] = re.search(r"baseline .*window rate (\d\.\d+)", stdout)
    figures["optimum"] = re.search(r"optimum W\* = (\d\.\d+)", stdout)
    figures["mean"] = re.search(r"task robustness over each run \(windows clipped at the run's end\): mean (-?[\d.]+|-?inf)", stdout)
    figures["satisfied"] = re.search(r"satisfied in (\d+) of", stdout)
    return {k: m.group(1) for k, m in figures.items() if m}


@pytest.mark.parametrize(
    "spec, args",
    [(SMALL, dict(starts=5, steps=300, burn_in=40, seed=2)), (REACH, dict(starts=6, steps=60, seed=1))],
    ids=["persistent, with W*", "another task"],
)
def test_evaluate_reports_hstlc_evals_figures(hstlc, tmp_path, spec, args):
    cli_train(hstlc, tmp_path, spec, "--seed", "4", "--episodes", "5")
    policy = hstl.Policy.load(tmp_path / "cli" / "policy.json")
    flags = [f"--{k.replace('_', '-')}={v}" for k, v in args.items()]
    result = run_cli(hstlc, "eval", str(tmp_path / "cli" / "policy.json"), *flags)
    assert result.returncode == 0, result.stderr
    want = eval_figures(result.stdout)
    got = policy.evaluate(**args)
    assert f"{got['robustness_mean']:.3f}" == want["mean"] and str(got["satisfied"]) == want["satisfied"]
    assert len(got["robustness"]) == args["starts"]
    if spec == REACH:
        assert got["window_rate"] is None and got["optimum"] is None and "window_rate" not in want
        return
    assert f"{got['window_rate']:.4f}" == want["window_rate"] and len(got["window_rates"]) == 5
    assert f"{got['baseline']:.4f}" == want["baseline"]
    assert f"{got['optimum']:.4f}" == want["optimum"] and got["optimum_converged"]
    lower, upper = got["optimum_bounds"]
    assert lower <= got["optimum"] <= upper
    assert policy.evaluate(**args, optimum=False)["optimum"] is None


def first_error(result) -> list[str]:
    assert result.returncode in (1, 2), result.stderr
    lines = result.stderr.splitlines()
    assert lines[0].startswith("error: "), result.stderr
    return [lines[0][len("error: "):], *lines[1:]]


def test_a_spec_that_does_not_fit_the_world_raises_hstlc_checks_diagnostics(hstlc, monkeypatch):
    monkeypatch.chdir(CLI_FIXTURES)
    concise = run_cli(hstlc, "check", "--world", "four-rooms", "--format", "concise", "surveillance.hstl")
    listed = json.loads(run_cli(hstlc, "check", "--world", "four-rooms", "--format", "json", "surveillance.hstl").stdout)
    assert concise.returncode == 1 and listed
    with pytest.raises(hstl.SpecError) as e:
        hstl.train("surveillance.hstl", world="four-rooms", episodes=1)
    assert str(e.value) == concise.stdout.rstrip("\n")
    assert [(d.code, d.line, d.column, d.message) for d in e.value.diagnostics] == [
        (d["code"], d["line"], d["column"], d["message"]) for d in listed
    ]
    # A world file names itself in the diagnostics as it does for hstlc.
    file_check = run_cli(hstlc, "check", "--world", "worlds/nook.toml", "--format", "concise", "small.hstl")
    with pytest.raises(hstl.SpecError) as in_file:
        hstl.train("small.hstl", world="worlds/nook.toml", episodes=1)
    assert file_check.returncode == 1 and str(in_file.value) == file_check.stdout.rstrip("\n")


@pytest.mark.parametrize(
    "cli, call, kind",
    [
        (["train", "no_options.hstl"], lambda: hstl.train("no_options.hstl"), ValueError),
        (["train", "small.hstl", "--episodes", "0"], lambda: hstl.train("small.hstl", episodes=0), ValueError),
        (["eval", "not_a_policy.json"], lambda: hstl.Policy.load("not_a_policy.json"), hstl.PolicyError),
        (["eval", "nowhere.json"], lambda: hstl.Policy.load("nowhere.json"), FileNotFoundError),
        (["eval", "surveillance.hstl"], lambda: hstl.Policy.load("surveillance.hstl"), hstl.PolicyError),
    ],
    ids=["no options", "zero episodes", "not a policy", "no file", "a spec as a policy"],
)
def test_bad_input_raises_what_hstlc_prints(hstlc, monkeypatch, cli, call, kind):
    monkeypatch.chdir(CLI_FIXTURES)
    want = first_error(run_cli(hstlc, *cli, "--out", "unused") if cli[0] == "train" else run_cli(hstlc, *cli))
    with pytest.raises(kind) as e:
        call()
    got = str(e.value).splitlines()
    if "--episodes" in cli:
        # clap words its own flag; the range is the same.
        assert "0 is not in 1..=10000000" in want[0] and got[0] == "`episodes` must be in 1..=10000000; got 0"
    elif "nowhere.json" in cli:
        assert got[0] == want[0]
    else:
        assert got == want


def test_a_spec_with_errors_raises_hstlc_checks_diagnostics(hstlc, monkeypatch):
    monkeypatch.chdir(CLI_FIXTURES)
    concise = run_cli(hstlc, "check", "--format", "concise", "float_state.hstl")
    assert run_cli(hstlc, "train", "float_state.hstl", "--out", "unused").returncode == 1
    with pytest.raises(hstl.SpecError) as e:
        hstl.train("float_state.hstl")
    # The diagnostics and their summary line; the notes that follow are check's own.
    diagnostics = concise.stdout.split("\nnote: ")[0].rstrip("\n")
    assert str(e.value) == diagnostics and e.value.diagnostics[0].code == "HSTL025"


def test_bad_arguments_raise():
    with pytest.raises(ValueError, match=r"`seed` must be in 0\.\.=18446744073709551615; got -1"):
        hstl.train(SMALL, seed=-1)
    with pytest.raises(TypeError, match="`seed` must be an integer"):
        hstl.train(SMALL, seed=1.5)
    with pytest.raises(ValueError, match=r"`episodes` must be in 1\.\.=10000000; got 10000001"):
        hstl.train(SMALL, episodes=10_000_001)
    policy = hstl.train(SMALL, episodes=1)
    with pytest.raises(ValueError, match="more than the 200000000 steps an evaluation may take"):
        policy.evaluate(starts=100_000, steps=1_000_000)
    with pytest.raises(ValueError, match=r"`starts` must be in 1\.\.=100000; got 0"):
        policy.evaluate(starts=0)
    with pytest.raises(ValueError, match="a burn-in of 300 steps leaves nothing of 300-step runs"):
        policy.evaluate(steps=300, burn_in=300)
    with pytest.raises(TypeError, match="for a policy trained on a gymnasium environment"):
        policy.evaluate(env=object(), valuation=lambda o: o)
    with pytest.raises(ValueError, match="the policy has no state x = 20, y = 3"):
        policy.act((20, 3))
    with pytest.raises(FileNotFoundError, match="cannot write"):
        policy.save(CLI_FIXTURES / "no" / "such" / "folder" / "policy.json")


@pytest.mark.parametrize(
    "want, edit",
    [
        ("holds NaN", lambda d: d["q_tables"]["options"].__setitem__(3, "7ff8000000000001")),
        ("not 16 hex digits", lambda d: d["q_tables"]["flat"]["A"].__setitem__(5, "garbage")),
        ("`flat_policies` is not what its `q_tables` give",
         lambda d: d["flat_policies"]["A"][40].__setitem__("choice", "Down" if d["flat_policies"]["A"][40]["choice"] == "Up" else "Up")),
        ("`primitives` is not what its `q_tables` give",
         lambda d: d.__setitem__("spec_source", d["spec_source"].replace("x < 3", "x < 4"))),
    ],
    ids=["NaN", "hex", "choices", "spec"],
)
def test_tampered_policies_are_refused_as_hstlc_eval_refuses_them(hstlc, tmp_path, want, edit):
    doc = json.loads(hstl.train(SMALL, seed=2, episodes=2).json)
    # Without its checksum (which refuses any edit first), each edit meets its field's check.
    del doc["checksum"]
    edit(doc)
    path = tmp_path / "edited.json"
    path.write_text(json.dumps(doc))
    cli = first_error(run_cli(hstlc, "eval", str(path), "--no-optimum"))
    with pytest.raises(hstl.PolicyError) as e:
        hstl.Policy.load(path)
    assert want in str(e.value) and str(e.value).splitlines() == cli


def test_a_policy_from_before_worlds_still_loads(tmp_path):
    doc = json.loads(hstl.train(SMALL, seed=2, episodes=2).json)
    doc["env"] = {"name": "gridworld", "params": {"width": 15, "height": 15, "p": 0.7}}
    del doc["checksum"]  # written before worlds, it was written before checksums too
    path = tmp_path / "old.json"
    path.write_text(json.dumps(doc))
    old = hstl.Policy.load(path)
    assert old.world.width == 15 and old.evaluate(starts=2, steps=200, optimum=False)["window_rate"] >= 0


def test_an_edited_policy_is_refused_by_its_checksum(hstlc, tmp_path):
    # Issue 30: an edit that every field's check lets through (here the world's slip) is
    # refused by the document's checksum, by Python as by `hstlc eval`.
    doc = json.loads(hstl.train(SMALL, seed=2, episodes=2).json)
    path = tmp_path / "same.json"
    path.write_text(json.dumps(doc, indent=1))
    assert hstl.Policy.load(path).seed == 2  # reformatted, it reads back
    doc["env"]["params"]["slip"] = 0.1
    path = tmp_path / "edited.json"
    path.write_text(json.dumps(doc))
    cli = first_error(run_cli(hstlc, "eval", str(path), "--no-optimum"))
    with pytest.raises(hstl.PolicyError, match="changed after it was written") as e:
        hstl.Policy.load(path)
    assert str(e.value).splitlines() == cli


def test_progress_shows_a_bar_only_when_asked_or_on_a_terminal(capfd):
    hstl.train(SMALL, episodes=2, progress=False)
    assert capfd.readouterr().err == ""
    hstl.train(SMALL, episodes=2)  # standard error is not a terminal here
    assert capfd.readouterr().err == ""
    hstl.train(SMALL, episodes=2, progress=True)
    err = capfd.readouterr().err
    assert "2/2" in err, err


def test_the_gil_is_free_while_training():
    import threading
    import time

    ticks = []
    done = threading.Event()

    def tick():
        while not done.is_set():
            ticks.append(time.perf_counter())
            time.sleep(0.001)

    t = threading.Thread(target=tick)
    t.start()
    start = time.perf_counter()
    try:
        hstl.train(REPO / "examples" / "specs" / "surveillance_ot1.hstl", episodes=40)
    finally:
        done.set()
        t.join()
    during = [x for x in ticks if x > start]
    # Another thread ran all along: with the GIL held it would have had no turn.
    assert len(during) > 20


def test_the_example_script_trains_evaluates_and_runs_in_gymnasium(tmp_path):
    import subprocess
    import sys

    script = REPO / "examples" / "python" / "train.py"
    out = tmp_path / "policy.json"
    args = [sys.executable, str(script), "--episodes", "20", "--no-optimum", "--out", str(out)]
    result = subprocess.run(args, capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stderr
    assert "window rate" in result.stdout and "FrozenLake" in result.stdout
    assert hstl.Policy.load(out).spec_name == "SurveillanceAuto"
    shutil.rmtree(tmp_path)
