"""`hstl.study` gives `hstlc study`'s figures and folder, the same on this machine and on a
local Ray cluster (one per module: `ray.init(num_cpus=2)`, on the loopback); a killed worker
loses no seed; errors arrive as hstl's exceptions; `hstl.tune` reports to Ray Tune what
training reaches."""

from __future__ import annotations

import csv
import os

import pytest
import ray

import hstl
import hstl.tune
from hstl import _study
from conftest import CLI_FIXTURES, REPO, run_cli

SMALL = CLI_FIXTURES / "small.hstl"
OTHER = CLI_FIXTURES / "small_other.hstl"
PLANE = REPO / "examples" / "specs" / "surveillance_plane.hstl"
PLANE_REACH = hstl.Spec.parse(
    """spec PlaneReach {
        world "paper-plane";
        state { x: float in 0..=14, y: float in 0..=14 }
        let A = x > 11 && y > 11;
        task eventually[0..40] A;
        option A;
        learn { preset: auto }
    }""",
    filename="plane_reach.hstl",
)


def without_time(rows):
    return [{k: v for k, v in r.items() if k != "seconds"} for r in rows]


@pytest.fixture(scope="module")
def cluster():
    ray.init(num_cpus=2, include_dashboard=False, logging_level="warning", _node_ip_address="127.0.0.1")
    yield
    ray.shutdown()


@pytest.fixture(scope="module")
def local():
    """Two specs, three seeds (not in order), 10 episodes each, on this machine."""
    return hstl.study([SMALL, OTHER], seeds=[2, 0, 5], episodes=10)


def test_rows_hold_the_contract_s_fields(local):
    assert [(r["spec"], r["seed"]) for r in local] == [
        (s, seed) for s in ("Small", "SmallOther") for seed in (2, 0, 5)
    ]
    w_star = local[0]["optimum"]
    assert 0 < w_star <= 1
    for r in local:
        assert r["file"] in (str(SMALL), str(OTHER))
        assert 0 <= r["window_rate"] <= 1 and r["ratio"] == r["window_rate"] / r["optimum"]
        assert len(r["curve"]) == 10 and r["reward"] == sum(r["curve"]) / 10
        assert r["seconds"] > 0 and r["steps"] > 0
    # The summary is each spec's mean, sd, min and max over its seeds.
    first = local.summary[0]
    ws = [r["window_rate"] for r in local[:3]]
    assert first["spec"] == "Small" and first["optimum"] == w_star
    assert first["window_rate"]["min"] == min(ws) and first["window_rate"]["max"] == max(ws)
    assert first["ratio"]["max"] == max(ws) / w_star
    assert abs(first["window_rate"]["mean"] - sum(ws) / 3) < 1e-15


def test_a_seed_s_figures_do_not_depend_on_the_threads_or_the_company(local):
    alone = hstl.study(OTHER, seeds=[5], episodes=10, num_cpus=1)
    assert without_time(alone) == without_time(local[5:])


def test_out_writes_what_hstlc_study_out_writes(hstlc, tmp_path):
    cli, py = tmp_path / "cli", tmp_path / "py"
    result = run_cli(
        hstlc, "study", str(SMALL), str(OTHER), "--seeds", "3", "--episodes", "10", "--no-optimum", "--out", str(cli)
    )
    assert result.returncode == 0, result.stderr
    rows = hstl.study([SMALL, OTHER], seeds=3, episodes=10, optimum=False, out=py)
    files = sorted(p.relative_to(cli) for p in cli.rglob("*") if p.is_file())
    assert files == sorted(p.relative_to(py) for p in py.rglob("*") if p.is_file())
    assert len(files) > 10
    for f in files:
        if f.name == "summary.csv":
            # Every figure but the mean training time.
            a, b = (list(csv.DictReader((d / f).open())) for d in (cli, py))
            for x, y in zip(a, b):
                del x["train_secs_mean"], y["train_secs_mean"]
            assert a == b and len(a) == 2
            continue
        if f.name != "seeds.csv":
            assert (cli / f).read_bytes() == (py / f).read_bytes(), f
            continue
        # Every figure but the training time; and they are the rows' figures.
        a, b = (list(csv.DictReader((d / f).open())) for d in (cli, py))
        for x, y in zip(a, b):
            del x["train_secs"], y["train_secs"]
        assert a == b
        spec = "Small" if f.parts[0] == "small" else "SmallOther"
        mine = [r for r in rows if r["spec"] == spec]
        assert [float(x["window_rate"]) for x in a] == [r["window_rate"] for r in mine]
        assert [float(x["reward_last_100"]) for x in a] == [r["reward"] for r in mine]


def test_a_folder_that_is_not_a_run_s_is_refused_before_training(tmp_path):
    (tmp_path / "small").mkdir()
    (tmp_path / "small" / "notes.txt").write_text("mine")
    with pytest.raises(ValueError, match=r"holds `notes.txt`, which no hstl run writes") as e:
        hstl.study(SMALL, seeds=1, episodes=2, optimum=False, out=tmp_path)
    assert "choose a new or empty `out=`" in str(e.value)
    assert (tmp_path / "small" / "notes.txt").read_text() == "mine"


def test_bad_arguments_are_refused_in_words():
    with pytest.raises(ValueError, match='`backend` must be "local" or "ray"'):
        hstl.study(SMALL, backend="slurm")
    with pytest.raises(ValueError, match="`seeds` is empty"):
        hstl.study(SMALL, seeds=[])
    with pytest.raises(ValueError, match="`seeds` must be in 1..=100000"):
        hstl.study(SMALL, seeds=0)
    with pytest.raises(ValueError, match="`specs` is empty"):
        hstl.study([])
    with pytest.raises(hstl.WorldError):
        hstl.study(SMALL, world="nowhere")


def test_a_spec_that_does_not_fit_the_world_is_a_spec_error():
    with pytest.raises(hstl.SpecError) as e:
        hstl.study(SMALL, seeds=1, world="four-rooms", optimum=False)
    assert e.value.diagnostics


def test_batches_grow_with_the_sweep():
    assert _study._batch_size(100, 2) == 1
    assert _study._batch_size(1000, 2) == 4
    assert _study._batch_size(10**5, 2) == _study._MAX_BATCH


# On Ray.


def test_ray_gives_the_local_figures_bit_for_bit(cluster, local):
    for batch in (None, 2):
        on_ray = hstl.study([SMALL, OTHER], seeds=[2, 0, 5], episodes=10, backend="ray", batch=batch)
        assert without_time(on_ray) == without_time(local)
        assert [s["window_rate"] for s in on_ray.summary] == [s["window_rate"] for s in local.summary]


@pytest.fixture(scope="module")
def plane_local():
    """A persistent and a reach spec on `paper-plane`, two seeds, 6 episodes, here."""
    return [hstl.study(spec, seeds=[3, 1], episodes=6) for spec in (PLANE, PLANE_REACH)]


def test_ray_gives_the_local_figures_of_plane_specs_bit_for_bit(cluster, plane_local):
    for spec, local_rows in zip((PLANE, PLANE_REACH), plane_local):
        on_ray = hstl.study(spec, seeds=[3, 1], episodes=6, backend="ray", batch=1)
        assert without_time(on_ray) == without_time(local_rows)
        assert without_time(on_ray.summary) == without_time(local_rows.summary)


def test_a_plane_study_gives_hstlc_study_s_figures(hstlc, tmp_path, plane_local):
    persistent, reach = plane_local
    out = tmp_path / "cli"
    result = run_cli(hstlc, "study", str(PLANE), "--seeds", "4", "--episodes", "6", "--out", str(out), cwd=REPO)
    assert result.returncode == 0, result.stderr
    seeds_csv = next(out.glob("*/seeds.csv"))
    by_seed = {int(r["seed"]): float(r["W"]) for r in csv.DictReader(open(seeds_csv))}
    for row in persistent:
        assert row["window_rate"] == by_seed[row["seed"]]
        assert row["optimum"] is None and row["ratio"] is None
        # The seed's policy, measured on its evaluation seed's runs, has the same W.
        policy = hstl.train(PLANE, seed=row["seed"], episodes=6)
        assert policy.evaluate(seed=row["seed"] ^ hstl.EVAL_SEED, optimum=False)["window_rate"] == row["window_rate"]
    for row in reach:
        assert row["window_rate"] is None and 0.0 <= row["satisfaction"] <= 1.0
    with pytest.raises(ValueError, match="`out=` writes a study's folder in a grid world"):
        hstl.study(PLANE, seeds=1, episodes=2, out=tmp_path / "py")
    with pytest.raises(TypeError, match="hstl.tune trains in grid worlds"):
        hstl.tune.trainable_for(PLANE)


def test_a_killed_worker_does_not_lose_a_seed(cluster, local, tmp_path):
    marker = str(tmp_path / "killed")

    def kill_once(seeds):
        # The first attempt at the batch with seed 0 ends its worker process.
        if 0 in seeds and not os.path.exists(marker):
            open(marker, "w").close()
            os._exit(1)

    rows = _study._study(
        [SMALL, OTHER],
        [2, 0, 5],
        "paper",
        "ray",
        None,
        None,
        episodes=10,
        optimum=True,
        num_cpus=None,
        batch=2,
        max_retries=2,
        before_batch=kill_once,
    )
    assert os.path.exists(marker)
    assert without_time(rows) == without_time(local)


def test_an_error_in_a_task_is_raised_as_itself(cluster):
    def refuse(seeds):
        raise hstl.SpecError("small.hstl:1:1: error[HSTL001] refused in the task")

    with pytest.raises(hstl.SpecError, match="refused in the task") as e:
        _study._study(
            SMALL,
            2,
            "paper",
            "ray",
            None,
            None,
            episodes=2,
            optimum=False,
            num_cpus=None,
            batch=1,
            max_retries=0,
            before_batch=refuse,
        )
    assert not isinstance(e.value, ray.exceptions.RayError)


def test_a_spec_error_on_ray_is_raised_before_any_task(cluster, tmp_path):
    bad = tmp_path / "bad.hstl"
    bad.write_text("spec Bad { state { x: int in 0..=14 } task eventually[0..5] Nowhere; option Nowhere; }")
    with pytest.raises(hstl.SpecError) as e:
        hstl.study(bad, seeds=2, backend="ray")
    assert not isinstance(e.value, ray.exceptions.RayError)
    assert any(d.code for d in e.value.diagnostics)


def test_ray_writes_the_folder_local_writes(cluster, tmp_path):
    hstl.study([SMALL], seeds=2, episodes=10, optimum=False, out=tmp_path / "local")
    hstl.study([SMALL], seeds=2, episodes=10, optimum=False, out=tmp_path / "ray", backend="ray")
    for d in ("local", "ray"):
        # The training times differ: seeds.csv's second column, summary.csv's last.
        seeds = tmp_path / d / "small" / "seeds.csv"
        rows = list(csv.reader(seeds.open()))
        seeds.write_text("\n".join(",".join(r[:1] + r[2:]) for r in rows))
        summary = tmp_path / d / "summary.csv"
        rows = list(csv.reader(summary.open()))
        summary.write_text("\n".join(",".join(r[:-1]) for r in rows))
    for f in (tmp_path / "local").rglob("*"):
        if f.is_file():
            assert f.read_bytes() == (tmp_path / "ray" / f.relative_to(tmp_path / "local")).read_bytes(), f


# Ray Tune.


def test_chunks_report_where_training_stands():
    spec, world = hstl.Spec.load(SMALL), hstl.World.builtin("paper")
    seen = []
    done = hstl._hstl._train_chunks(spec, world, 0, 4, lambda *a: seen.append(a) or False, {"episodes": 10})
    assert done == 10 and [s[0] for s in seen] == [4, 8, 10]
    # The last report is the study's figures for that seed.
    row = hstl.study(SMALL, seeds=[0], episodes=10, optimum=False)[0]
    assert seen[-1][1:3] == (row["reward"], row["window_rate"])
    # True stops training after that chunk.
    assert hstl._hstl._train_chunks(spec, world, 0, 4, lambda *a: True, {"episodes": 10}) == 4
    with pytest.raises(ValueError, match="`flat_alpha` must be in \\(0, 1\\], found `2`"):
        hstl._hstl._train_chunks(spec, world, 0, 4, lambda *a: False, {"flat_alpha": 2})
    with pytest.raises(ValueError, match="`alpha` is not a `learn` value that can be set"):
        hstl._hstl._train_chunks(spec, world, 0, 4, lambda *a: False, {"alpha": 0.5})


def test_tune_trials_report_w_and_w_over_w_star(cluster, tmp_path):
    from ray import tune

    tuner = tune.Tuner(
        hstl.tune.trainable_for(SMALL, chunk=5),
        # The spec's own flat step size, and another.
        param_space={"episodes": 10, "flat_alpha": tune.grid_search([0.2, 0.6])},
        tune_config=tune.TuneConfig(metric="window_rate", mode="max"),
        run_config=tune.RunConfig(storage_path=str(tmp_path), verbose=0),
    )
    results = tuner.fit()
    assert not results.errors
    by_alpha = {r.config["flat_alpha"]: r.metrics for r in results}
    row = hstl.study(SMALL, seeds=[0], episodes=10)[0]
    own = by_alpha[0.2]
    # Two reports (5 and 10 episodes); the last is what the study measures for seed 0.
    assert own["training_iteration"] == 2 and own["episodes"] == 10
    assert (own["window_rate"], own["reward"], own["ratio"]) == (row["window_rate"], row["reward"], row["ratio"])
    assert by_alpha[0.6]["window_rate"] != own["window_rate"]


ZERO = """spec Zero {
    world "paper";
    state { x: int in 0..=14, y: int in 0..=14 }
    let A = x < 3 && y < 3;
    let B = x > 11 && y > 11;
    task always[0..] (eventually[0..2] A && eventually[0..2] B);
    option A;
    option B;
    learn { episodes: 5, choices: 5 }
}
"""


def test_no_policy_keeps_the_task_and_w_over_w_star_is_undefined(tmp_path):
    """Hostile round 2: W* = 0 raised ZeroDivisionError after training every seed."""
    spec = tmp_path / "zero.hstl"
    spec.write_text(ZERO)
    rows = hstl.study(spec, seeds=2, out=tmp_path / "out")
    assert [r["optimum"] for r in rows] == [0.0, 0.0]
    assert [r["ratio"] for r in rows] == [None, None]
    assert "ratio" not in rows.summary[0]
    summary = (tmp_path / "out" / "summary.csv").read_text()
    assert summary.splitlines()[1].split(",")[1:5] == ["W/W*", "0", "", ""], summary
    assert "NaN" not in summary and "inf" not in summary


def test_a_users_summary_is_kept_unless_force(tmp_path):
    """Hostile round 2: `out=` replaced a user's own summary.csv without a word."""
    (tmp_path / "summary.csv").write_text("mine\n")
    with pytest.raises(ValueError, match=r"summary.csv` was not written by a study") as e:
        hstl.study(SMALL, seeds=1, episodes=2, optimum=False, out=tmp_path)
    assert "`force=True`" in str(e.value)
    assert (tmp_path / "summary.csv").read_text() == "mine\n"
    hstl.study(SMALL, seeds=1, episodes=2, optimum=False, out=tmp_path, force=True)
    assert (tmp_path / "summary.csv").read_text().startswith("spec,measure")


def test_a_seed_s_window_rate_is_evaluate_with_its_evaluation_seed(local):
    row = next(r for r in local if r["spec"] == "Small" and r["seed"] == 5)
    policy = hstl.train(SMALL, seed=5, episodes=10)
    report = policy.evaluate(seed=5 ^ hstl.EVAL_SEED, optimum=False)
    assert report["window_rate"] == row["window_rate"]


@pytest.mark.parametrize("world", ["paper", "plane"])
def test_ctrl_c_ends_a_study_within_its_episode_under_way(tmp_path, world):
    # Issue 30: Ctrl-C only kept further seeds from starting, so a long seed trained to its
    # end first. Training stops after the episode under way; the call raises
    # KeyboardInterrupt. A child process, so that a study that does not stop fails the
    # test at the timeout instead of hanging it; no time is asserted beyond that guard.
    import signal
    import subprocess
    import sys
    import time

    spec = SMALL if world == "paper" else PLANE
    code = (
        "import sys, hstl\n"
        "print('started', flush=True)\n"
        "try:\n"
        "    hstl.study(sys.argv[1], seeds=2, episodes=10_000_000, optimum=False)\n"
        "except KeyboardInterrupt:\n"
        "    print('interrupted', flush=True)\n"
    )
    # Ctrl-C as at a terminal, whatever the test runner inherited (a background job has
    # SIGINT ignored, and Python then installs no handler).
    child = subprocess.Popen(
        [sys.executable, "-c", code, str(spec)],
        stdout=subprocess.PIPE,
        text=True,
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )
    assert child.stdout is not None
    assert child.stdout.readline().strip() == "started"
    time.sleep(1.5)
    child.send_signal(signal.SIGINT)
    try:
        out, _ = child.communicate(timeout=60)
    except subprocess.TimeoutExpired:
        child.kill()
        raise AssertionError("the study went on training after Ctrl-C")
    assert "interrupted" in out, out
