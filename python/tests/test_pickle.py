"""Specs, diagnostics and spec errors pickle, so they cross process boundaries."""

from __future__ import annotations

import copy
import multiprocessing
import warnings
import pickle

import numpy as np
import pytest

import hstl
from conftest import CLI_FIXTURES

TRACE = {"x": [0, 5, 5, 3, 10, 12], "y": [0, 12, 12, 3, 3, 4]}


def test_a_loaded_spec_round_trips_by_its_source():
    spec = hstl.Spec.load(CLI_FIXTURES / "surveillance.hstl")
    back = pickle.loads(pickle.dumps(spec))
    assert back == spec and hash(back) == hash(spec)
    assert (back.name, back.filename, back.source) == (spec.name, spec.filename, spec.source)
    assert np.array_equal(back.signal(TRACE, "A"), spec.signal(TRACE, "A"))


def test_a_spec_picked_by_name_round_trips_with_its_name():
    text = (CLI_FIXTURES / "two_specs.hstl").read_text()
    spec = hstl.Spec.parse(text, filename="two.hstl", name="Second")
    for protocol in range(pickle.HIGHEST_PROTOCOL + 1):
        back = pickle.loads(pickle.dumps(spec, protocol))
        assert back.name == "Second" and back.filename == "two.hstl" and back == spec


def test_spec_errors_and_diagnostics_round_trip():
    with pytest.raises(hstl.SpecError) as e:
        hstl.Spec.load(CLI_FIXTURES / "errors.hstl")
    back = pickle.loads(pickle.dumps(e.value))
    assert type(back) is hstl.SpecError and str(back) == str(e.value)
    assert back.diagnostics == e.value.diagnostics and len(back.diagnostics) >= 3
    d = e.value.diagnostics[0]
    assert pickle.loads(pickle.dumps(d)) == d
    with pytest.raises(hstl.MissingVariableError) as missing:
        hstl.Spec.load(CLI_FIXTURES / "surveillance.hstl").signal({"x": [1]})
    assert str(pickle.loads(pickle.dumps(missing.value))) == str(missing.value)


def score(spec):
    return spec.signal(TRACE).tolist()


def test_a_spec_crosses_to_a_spawned_process():
    spec = hstl.Spec.load(CLI_FIXTURES / "surveillance.hstl")
    with multiprocessing.get_context("spawn").Pool(1) as pool:
        assert pool.map(score, [spec]) == [score(spec)]


def test_worlds_and_policies_round_trip_by_their_contents():
    from conftest import REPO

    world = hstl.World.load(REPO / "examples" / "worlds" / "warehouse.toml")
    policy = hstl.train(CLI_FIXTURES / "small.hstl", seed=4, episodes=2)
    for protocol in range(pickle.HIGHEST_PROTOCOL + 1):
        assert pickle.loads(pickle.dumps(world, protocol)) == world
        back = pickle.loads(pickle.dumps(policy, protocol))
        assert back == policy and back.json == policy.json
        assert back.curve.tolist() == policy.curve.tolist() and back.steps == policy.steps
        assert back.q_tables["options"].tobytes() == policy.q_tables["options"].tobytes()


def window_rate(policy):
    return policy.evaluate(starts=2, steps=300, optimum=False)["window_rate"]


def test_a_policy_crosses_to_a_spawned_process():
    policy = hstl.train(CLI_FIXTURES / "small.hstl", seed=4, episodes=2)
    with multiprocessing.get_context("spawn").Pool(1) as pool:
        assert pool.map(window_rate, [policy]) == [window_rate(policy)]


def _steps(env, actions):
    out = []
    for a in actions:
        obs, reward, terminated, truncated, info = env.step(a)
        out.append((tuple(int(v) for v in obs), reward, terminated, truncated, info))
    return out


@pytest.mark.parametrize("reward", ["robustness", "increment", "window", "sparse"])
def test_an_stl_reward_env_pickles_and_copies_mid_episode(reward):
    gymnasium = pytest.importorskip("gymnasium")
    env = hstl.STLReward(
        gymnasium.make("hstl/GridWorld-v0", max_episode_steps=40),
        CLI_FIXTURES / "surveillance.hstl",
        reward=reward,
        offset=0.5,
    )
    env.reset(seed=11)
    actions = np.random.default_rng(0).integers(0, 4, size=50).tolist()
    _steps(env, actions[:20])
    copies = [pickle.loads(pickle.dumps(env)), copy.deepcopy(env)]
    want = _steps(env, actions[20:])
    for other in copies:
        # The same cells (the generator continues), rewards and task robustness.
        assert _steps(other, actions[20:]) == want
    assert any(step[3] for step in want), "the episode ends by truncation"


def test_an_stl_reward_env_of_a_dict_valuation_pickles():
    gymnasium = pytest.importorskip("gymnasium")
    spec = hstl.Spec.parse("spec P { state { y: float, x: float } let Top = y > 12; task eventually[0..] Top; }")
    env = hstl.STLReward(hstl.GridWorldEnv(), spec, valuation={"x": 0, "y": 1}, formula="Top")
    env.reset(seed=3)
    back = pickle.loads(pickle.dumps(env))
    assert _steps(back, [0, 0, 3]) == _steps(env, [0, 0, 3])
    assert isinstance(back, gymnasium.Wrapper)


ONLINE_FORMULAS = [
    (CLI_FIXTURES / "surveillance.hstl", None),  # unbounded
    (CLI_FIXTURES / "surveillance.hstl", "A"),
    (None, "always[0..=3] eventually[1..=2] (x >= 4)"),  # bounded
    (None, "once[0..=4] (x > 6) && historically[0..] (y >= 0)"),  # past-time
]


@pytest.mark.parametrize("path, formula", ONLINE_FORMULAS)
def test_an_online_monitor_pickles_and_copies_mid_trace(path, formula):
    if path is None:
        spec = hstl.Spec.parse(f"spec T {{ state {{ x: float, y: float }} task {formula}; }}")
        formula = None
    else:
        spec = hstl.Spec.load(path)
    rng = np.random.default_rng(5)
    states = [{"x": float(x), "y": float(y)} for x, y in rng.integers(0, 15, size=(40, 2))]
    for cut in (0, 1, 17, 40):
        online = spec.online(formula)
        got = [online.update(s) for s in states[:cut]]
        copies = [pickle.loads(pickle.dumps(online)), copy.deepcopy(online)]
        want = [online.update(s) for s in states[cut:]] + [online.finish()]
        for other in copies:
            assert other.steps == cut and other.horizon == online.horizon
            assert [other.update(s) for s in states[cut:]] + [other.finish()] == want
        assert len(got) == cut


def test_gymnasium_checks_and_remakes_an_stl_reward_env():
    gymnasium = pytest.importorskip("gymnasium")
    from gymnasium.utils.env_checker import check_env

    env = hstl.STLReward(gymnasium.make("hstl/GridWorld-v0"), CLI_FIXTURES / "reach.hstl", reward="increment")
    with warnings.catch_warnings():
        # Only the advice to check the unwrapped env, which check_env gives every wrapper.
        warnings.filterwarnings("ignore", message=".*different from the unwrapped version")
        check_env(env)
    again = gymnasium.make(env.spec)
    assert isinstance(again, hstl.STLReward) and again.reward_form == "increment"
    env.reset(seed=4)
    again.reset(seed=4)
    assert _steps(again, [0, 3, 3, 1]) == _steps(env, [0, 3, 3, 1])


def test_stl_reward_envs_run_in_a_vector_env():
    gymnasium = pytest.importorskip("gymnasium")

    def make():
        return hstl.STLReward(gymnasium.make("hstl/GridWorld-v0"), CLI_FIXTURES / "reach.hstl", reward="increment")

    envs = gymnasium.vector.SyncVectorEnv([make, make])
    envs.reset(seed=[1, 2])
    _, rewards, _, _, infos = envs.step(np.array([0, 3]))
    assert rewards.shape == (2,) and "task_robustness" in infos
    envs.close()


def continue_episode(env):
    return _steps(env, [0, 3, 3, 1, 2])


def test_an_stl_reward_env_crosses_to_a_spawned_process_mid_episode():
    gymnasium = pytest.importorskip("gymnasium")
    env = hstl.STLReward(
        gymnasium.make("hstl/GridWorld-v0"), CLI_FIXTURES / "surveillance.hstl", valuation={"x": 0, "y": 1}, reward="window"
    )
    env.reset(seed=8)
    _steps(env, [0, 0, 3])
    with multiprocessing.get_context("spawn").Pool(1) as pool:
        there = pool.map(continue_episode, [env])[0]
    assert there == continue_episode(env)
