"""Continuous tasks from Python: `hstl.train` on a plane or `mountain-car` spec writes what
`hstlc train` writes, byte for byte; the learned function's `policy.json` loads and saves to
the same bits; `Policy.act` on `PlaneEnv` takes the greedy run `hstlc eval --runs` writes;
`hstl.train(env=...)` learns on a gymnasium `Box` observation space; and bad observations,
states, spaces and valuations are refused in words."""

from __future__ import annotations

import csv
import json
import pickle
import re

import gymnasium
import numpy as np
import pytest
from gymnasium import spaces

import hstl
from conftest import REPO, run_cli

SPECS = REPO / "examples" / "specs"
PLANE = SPECS / "surveillance_plane.hstl"
CAR = SPECS / "mountain_car_patrol.hstl"
YARD_SPEC = SPECS / "yard_patrol.hstl"


def cli_train(hstlc, tmp_path, spec, *args):
    out = tmp_path / "cli"
    result = run_cli(hstlc, "train", str(spec), "--out", str(out), *args, cwd=REPO)
    assert result.returncode == 0, result.stderr
    return (out / "policy.json").read_text()


@pytest.mark.parametrize(
    "spec, world, seed, episodes",
    [(PLANE, None, 3, 20), (CAR, None, 1, 5), (YARD_SPEC, None, 2, 10), (PLANE, "paper-plane", 0, 8)],
    ids=["plane", "mountain-car", "yard", "world="],
)
def test_train_on_a_continuous_world_writes_the_bytes_hstlc_train_writes(hstlc, tmp_path, spec, world, seed, episodes):
    args = ["--seed", str(seed), "--episodes", str(episodes)] + (["--world", world] if world else [])
    want = cli_train(hstlc, tmp_path, spec, *args)
    policy = hstl.train(spec, world=world, seed=seed, episodes=episodes)
    assert policy.json == want
    assert policy.learned_function and json.loads(want)["learner"] == "tiles"
    assert len(policy.curve) == episodes and policy.steps > 0
    # Saved and loaded back: the same bytes, the same policy.
    policy.save(tmp_path / "policy.json")
    assert (tmp_path / "policy.json").read_text() == want
    back = hstl.Policy.load(tmp_path / "policy.json")
    assert back == policy and back.json == want and back.curve is None
    assert pickle.loads(pickle.dumps(policy)).json == want
    assert isinstance(back.world, hstl.ContinuousWorld) and back.world.name == json.loads(want)["env"]["name"]


def test_a_continuous_spec_that_names_no_world_trains_in_paper_plane(hstlc, tmp_path):
    text = PLANE.read_text().replace('world "paper-plane";', "")
    spec_file = tmp_path / "noworld.hstl"
    spec_file.write_text(text)
    want = cli_train(hstlc, tmp_path, spec_file, "--seed", "5", "--episodes", "4")
    assert hstl.train(spec_file, seed=5, episodes=4).json == want
    assert hstl.train(hstl.Spec.parse(text), seed=5, episodes=4, world=hstl.ContinuousWorld.builtin("paper-plane")).json == want


def test_act_on_plane_env_takes_the_greedy_run_hstlc_eval_writes(hstlc, tmp_path):
    cli_train(hstlc, tmp_path, PLANE, "--seed", "2", "--episodes", "30")
    runs = tmp_path / "runs"
    result = run_cli(hstlc, "eval", str(tmp_path / "cli" / "policy.json"), "--starts", "1", "--steps", "300",
                     "--seed", "9", "--runs", str(runs), cwd=REPO)
    assert result.returncode == 0, result.stderr
    rows = list(csv.DictReader(open(runs / "run_1.csv")))
    policy = hstl.Policy.load(tmp_path / "cli" / "policy.json")
    env = hstl.PlaneEnv()
    obs, _ = env.reset(seed=9)
    policy.reset()
    for row in rows[:-1]:
        # The same state, bit for bit, and the same action there.
        assert obs.tolist() == [float(row["x"]), float(row["y"])]
        action = policy.act(obs)
        assert policy.actions[action] == row["action"]
        obs, *_ = env.step(action)
    assert obs.tolist() == [float(rows[-1]["x"]), float(rows[-1]["y"])]


def test_evaluate_reports_hstlc_evals_window_rate(hstlc, tmp_path):
    cli_train(hstlc, tmp_path, PLANE, "--seed", "4", "--episodes", "20")
    result = run_cli(hstlc, "eval", str(tmp_path / "cli" / "policy.json"), "--starts", "10", "--seed", "3", cwd=REPO)
    printed = float(re.search(r"window rate (\d\.\d+)", result.stdout).group(1))
    report = hstl.Policy.load(tmp_path / "cli" / "policy.json").evaluate(starts=10, seed=3)
    assert f"{report['window_rate']:.4f}" == f"{printed:.4f}"
    assert len(report["window_rates"]) == 10 and report["optimum"] is None
    planned = re.search(r"planned reference: window rate (\d\.\d+)", result.stdout)
    assert f"{report['reference']:.4f}" == planned.group(1)
    # In the gymnasium environment, stepped through Python: a rate of its own runs.
    through = hstl.Policy.load(tmp_path / "cli" / "policy.json").evaluate(starts=3, steps=300, env=hstl.PlaneEnv())
    assert 0.0 <= through["window_rate"] <= 1.0 and through["reference"] is None
    with pytest.raises(ValueError, match="the policy was trained on world `paper-plane`"):
        hstl.Policy.load(tmp_path / "cli" / "policy.json").evaluate(env=hstl.PlaneEnv(REPO / "examples" / "worlds" / "yard.toml"))


def test_act_refuses_states_outside_the_world():
    policy = hstl.train(PLANE, seed=0, episodes=3)
    assert policy.act(np.array([1.0, 2.0])) in range(4)
    assert policy.act({"x": 1.0, "y": 2.5}) in range(4)
    for state, words in [
        ([float("nan"), 1.0], "`x` = NaN is outside world `paper-plane`"),
        ([1.0, float("inf")], "`y` = inf is outside"),
        ([15.0, 1.0], "`x` = 15 is outside"),
        ([1.0, 2.0, 3.0], "has 2 numbers (x, y), not 3"),
    ]:
        with pytest.raises(ValueError) as e:
            policy.act(state)
        assert words in str(e.value)
    with pytest.raises(hstl.MissingVariableError):
        policy.act({"x": 1.0})
    with pytest.raises(ValueError, match="a learned function has no Q-tables"):
        policy.q_tables


def small_car_spec(episodes=6):
    text = CAR.read_text().replace("learn { preset: auto }", f"learn {{ preset: auto, episodes: {episodes}, choices: 4 }}")
    return hstl.Spec.parse(text, filename="car.hstl")


def test_train_on_a_box_env_learns_and_replays_through_the_env(tmp_path):
    spec = small_car_spec()
    env = hstl.MountainCarEnv()
    policy = hstl.train(spec, env=env, seed=7)
    again = hstl.train(spec, env=hstl.MountainCarEnv(), seed=7)
    assert policy.json == again.json, "the same seed gives the same weights"
    doc = json.loads(policy.json)
    assert doc["env"]["params"]["gymnasium"] is True and doc["learner"] == "tiles"
    assert doc["env"]["params"]["observation"] == {"low": [-1.2, -0.07], "high": [0.6, 0.07]}
    policy.save(tmp_path / "p.json")
    back = hstl.Policy.load(tmp_path / "p.json")
    assert back.json == policy.json and back.world is None
    # A dict valuation and a function valuation train alike: the same states.
    by_index = hstl.train(spec, env=hstl.MountainCarEnv(), seed=7, valuation={"x": 0, "v": 1})
    by_function = hstl.train(spec, env=hstl.MountainCarEnv(), seed=7, valuation=lambda o: {"x": o[0], "v": o[1]})
    assert by_index.json == by_function.json == policy.json
    report = back.evaluate(starts=2, steps=300, env=hstl.MountainCarEnv())
    assert 0.0 <= report["window_rate"] <= 1.0
    with pytest.raises(TypeError, match="pass `env=`"):
        back.evaluate()
    obs, _ = hstl.MountainCarEnv().reset(seed=0)
    assert back.act(obs) in (0, 1, 2)


class Scripted(gymnasium.Env):
    """A Box environment whose observations are given: to feed the learner bad ones."""

    def __init__(self, observations, low=0.0, high=1.0, shape=(2,)):
        self.observation_space = spaces.Box(low=low, high=high, shape=shape, dtype=np.float64)
        self.action_space = spaces.Discrete(2)
        self.observations = observations
        self.t = 0

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.t = 0
        return np.asarray(self.observations[0], dtype=np.float64), {}

    def step(self, action):
        self.t = min(self.t + 1, len(self.observations) - 1)
        return np.asarray(self.observations[self.t], dtype=np.float64), 0.0, False, False, {}


UNIT = hstl.Spec.parse(
    """spec Unit {
        state { a: float in 0..=1, b: float in 0..=1 }
        let Hi = a > 0.8;
        let Lo = a < 0.2;
        task always[0..] (eventually[0..20] Hi && eventually[0..20] Lo);
        option Hi;
        option Lo;
        learn { preset: auto, episodes: 2, choices: 2 }
    }""",
    filename="unit.hstl",
)


@pytest.mark.parametrize(
    "env, valuation, kind, words",
    [
        (Scripted([[0.5, 0.5]], low=-np.inf, high=np.inf), None, ValueError, "the observation space is unbounded"),
        (Scripted([[0.5, 0.5], [float("nan"), 0.5]]), None, ValueError, "component 0 is NaN, outside its `Box`"),
        (Scripted([[0.5, 0.5], [0.5, 2.0]]), None, ValueError, "component 1 is 2, outside its `Box` [0, 1]"),
        (Scripted([[0.5, 0.5], [0.5, 0.5, 0.5]]), None, ValueError, "an observation of 3 components; its `Box` has 2"),
        (Scripted([[0.5, 0.5, 0.5]], shape=(3,)), None, ValueError, "pass valuation="),
        (Scripted([[0.5, 0.5]]), lambda o: {"a": 2.0, "b": 0.0}, ValueError, "`a` = 2 is outside its declared range 0..=1"),
        (Scripted([[0.5, 0.5]]), lambda o: {"a": 0.5}, hstl.MissingVariableError, "b"),
        (Scripted([[0.5, 0.5]]), {"a": 0}, hstl.MissingVariableError, "no entry for state variable `b`"),
        (Scripted([[0.5, 0.5]]), lambda o: 1 / 0, ZeroDivisionError, "valuation (after env.reset)"),
    ],
    ids=["unbounded", "nan", "outside", "shape", "components", "range", "missing", "dict", "raises"],
)
def test_bad_observations_and_valuations_are_refused_in_words(env, valuation, kind, words):
    with pytest.raises(kind) as e:
        hstl.train(UNIT, env=env, valuation=valuation, seed=0)
    assert words in str(e.value)


def test_a_box_env_with_the_wrong_spaces_or_spec_is_refused():
    tabular = hstl.Spec.load(REPO / "hstlc" / "tests" / "cli" / "surveillance.hstl")
    with pytest.raises(TypeError, match="needs a `Discrete` observation space; this environment's is Box") as e:
        hstl.train(tabular, env=hstl.PlaneEnv(), valuation=lambda o: {"x": 0, "y": 0}, seed=0)
    assert "declare the spec's state variables as `float` ranges" in str(e.value)
    policy = hstl.train(UNIT, env=Scripted([[0.5, 0.5], [0.9, 0.1], [0.1, 0.9]]), seed=0)
    with pytest.raises(ValueError, match="the policy was trained on `Scripted`"):
        policy.evaluate(env=Scripted([[0.5, 0.5]], high=2.0), starts=1, steps=150)
    with pytest.raises(ValueError, match="the observation space is unbounded: component 1 lies in"):
        policy.evaluate(env=gymnasium.make("CartPole-v1").unwrapped, starts=1, steps=150)
    for state, words in [
        ([0.5, float("nan")], "`b` = NaN is outside its declared range"),
        ([1.5, 0.5], "`a` = 1.5"),
        ([0.5, 0.5, 0.5], "a state of the policy has 2 numbers (a, b), not 3"),
        ([0.5], "not 1"),
    ]:
        with pytest.raises(ValueError) as e:
            policy.act(state)
        assert words in str(e.value)


def test_the_continuous_example_script_runs(tmp_path):
    import subprocess
    import sys

    script = REPO / "examples" / "python" / "continuous.py"
    result = subprocess.run([sys.executable, str(script), "--episodes", "5"], capture_output=True, text=True, timeout=600)
    assert result.returncode == 0, result.stderr
    assert "window rate W =" in result.stdout and "hstl/MountainCarPatrol-v0:" in result.stdout


class Ending(Scripted):
    """Terminates every episode after 3 steps, never in a region, and counts the steps it
    is asked for."""

    def __init__(self):
        super().__init__([[0.5, 0.5], [0.6, 0.5], [0.4, 0.5], [0.5, 0.5]])
        self.calls = []

    def reset(self, *, seed=None, options=None):
        self.calls.append(0)
        return super().reset(seed=seed, options=options)

    def step(self, action):
        self.calls[-1] += 1
        obs, reward, _, truncated, info = super().step(action)
        return obs, reward, self.t == 3, truncated, info


def test_a_terminated_step_holds_the_learner_there_until_it_resets():
    env = Ending()
    policy = hstl.train(UNIT, env=env, seed=1)
    # One reset per learner episode, never a step past the end of an episode.
    assert env.calls == [3, 3]
    assert policy.steps > sum(env.calls), "the learner's steps in the held state call nothing"
