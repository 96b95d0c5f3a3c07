"""Unit tests of the field's wrappers and stand-in (bench/field/.venv/bin/pytest
bench/field). Not in CI: the venv has torch."""

from __future__ import annotations

import pathlib
import pickle

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import hstl
from standin import StandinPlane
from tasks import horizon_task
from wrappers import Columns, FlagMDP, NoTermination, TauMDP, sparse_task_env


@pytest.fixture(scope="module")
def task50(tmp_path_factory: pytest.TempPathFactory) -> hstl.Spec:
    return hstl.Spec.load(horizon_task(50, tmp_path_factory.mktemp("t50")))


def test_standin_is_a_clean_seeded_env() -> None:
    env = StandinPlane(side=10.0)
    check_env(env, skip_render_check=True)
    runs = []
    for _ in range(2):
        env = StandinPlane(side=10.0)
        obs, _ = env.reset(seed=7)
        trace = [obs]
        for a in [0, 1, 2, 3, 4, 5, 6, 7] * 5:
            trace.append(env.step(a)[0])
        runs.append(np.array(trace))
    assert np.array_equal(runs[0], runs[1])
    assert (runs[0] >= 0).all() and (runs[0] <= 10).all()
    env.reset(seed=8)
    assert not np.array_equal(env.step(0)[0], runs[0][1])


def test_tau_mdp_stacks_the_last_states_oldest_first() -> None:
    env = TauMDP(StandinPlane(side=10.0, slip=0.0, noise=0.0), tau=3)
    assert env.observation_space.shape == (8,)
    obs, _ = env.reset(seed=0)
    start = obs[-2:].copy()
    assert np.allclose(obs.reshape(4, 2), start)
    moves = []
    for a in [0, 2, 0]:
        obs, *_ = env.step(a)
        moves.append(obs[-2:].copy())
    hist = obs.reshape(4, 2)
    assert np.allclose(hist[0], start) and np.allclose(hist[1:], moves)
    # East then north then east: x grows by 2, y by 1.
    assert np.allclose(hist[3] - hist[0], [2.0, 1.0])
    check_env(TauMDP(StandinPlane(), tau=2), skip_render_check=True)  # warns: a wrapper


def test_flags_rise_once_and_in_order(task50: hstl.Spec) -> None:
    # Field of side 10: A is x > 9, y < 1; B is x > 9, y > 9; C is x < 1, y > 9.
    env = FlagMDP(StandinPlane(side=10.0, slip=0.0, noise=0.0), task50, Columns([0, 1]), ["A", "B", "C"], ordered=True)
    obs, _ = env.reset(seed=0)
    assert list(obs[2:]) == [0, 0, 0]
    seen = []
    # North to C, east to B, south to A (only A's flag may rise before here), north to B,
    # west to C.
    path = [2] * 12 + [0] * 12 + [6] * 12 + [2] * 12 + [4] * 12
    for a in path:
        obs, *_ = env.step(a)
        seen.append(tuple(obs[2:]))
    assert seen[-1] == (1.0, 1.0, 1.0)
    first = {k: next(i for i, f in enumerate(seen) if f[k] == 1) for k in range(3)}
    # C and B were visited before A: ordered, their flags waited for A (step ~36).
    assert first[0] < first[1] < first[2]
    assert all(seen[i][0] <= seen[i + 1][0] for i in range(len(seen) - 1))
    unordered = FlagMDP(StandinPlane(side=10.0, slip=0.0, noise=0.0), task50, Columns([0, 1]), ["A", "B"])
    unordered.reset(seed=0)
    for a in [2] * 12 + [0] * 12:
        obs, *_ = unordered.step(a)
    assert list(obs[2:]) == [0.0, 1.0]
    with pytest.raises(ValueError, match="no let `Z`"):
        FlagMDP(StandinPlane(), task50, Columns([0, 1]), ["Z"])


def test_sparse_reward_is_the_task_robustness_at_the_end(task50: hstl.Spec) -> None:
    env = sparse_task_env(StandinPlane(side=10.0), task50, Columns([0, 1]), 50, observation="tau", tau=2)
    obs, _ = env.reset(seed=3)
    states = [obs[-2:]]
    rewards, done = [], False
    rng = np.random.default_rng(0)
    while not done:
        obs, r, term, trunc, info = env.step(int(rng.integers(0, 8)))
        states.append(obs[-2:])
        rewards.append(r)
        done = term or trunc
    assert len(rewards) == 50 and all(r == 0 for r in rewards[:-1])
    trace = {"x": np.array([s[0] for s in states]), "y": np.array([s[1] for s in states])}
    assert rewards[-1] == pytest.approx(task50.robustness(trace))
    assert rewards[-1] == info["task_robustness"]


def test_no_termination_goes_past_the_goal() -> None:
    from gymnasium.envs.classic_control import MountainCarEnv

    env = gymnasium.wrappers.TimeLimit(NoTermination(MountainCarEnv()), 300)
    env.reset(seed=0)
    env.unwrapped.state = np.array([0.49, 0.07])
    _, _, term, trunc, info = env.step(2)
    assert info["env_terminated"] and not term and not trunc
    steps = 1
    while not (trunc or term):
        _, _, term, trunc, _ = env.step(1)
        steps += 1
    assert steps == 300 and not term


def test_wrappers_pickle(task50: hstl.Spec) -> None:
    env = sparse_task_env(StandinPlane(side=10.0), task50, Columns([0, 1]), 50, observation="flags", flags=["A", "B", "C"])
    env.reset(seed=0)
    env.step(0)
    copy = pickle.loads(pickle.dumps(env))
    assert np.array_equal(copy.step(1)[0][:2].shape, (2,))
