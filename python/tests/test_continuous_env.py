"""Continuous worlds in gymnasium: `PlaneEnv` and `MountainCarEnv` pass gymnasium's checker,
draw from one seeded Rust generator (the same seed gives the same states bit for bit, and a
pickled or copied environment continues the same draws), the car's states are gymnasium's
MountainCar-v0's bit for bit, the registered ids make them, and bad actions, starts and
worlds are refused in words."""

from __future__ import annotations

import copy
import pickle
import warnings

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import hstl
from conftest import REPO

YARD = REPO / "examples" / "worlds" / "yard.toml"
FOUR_ROOMS = REPO / "examples" / "worlds" / "four-rooms.toml"

ENVS = [
    pytest.param(lambda: hstl.PlaneEnv(), id="paper-plane"),
    pytest.param(lambda: hstl.PlaneEnv(YARD), id="yard"),
    pytest.param(lambda: hstl.MountainCarEnv(), id="mountain-car"),
]


def bits(a):
    return np.asarray(a, dtype=np.float64).view(np.uint64).tolist()


def run(env, seed, actions):
    obs, _ = env.reset(seed=seed)
    states = [bits(obs)]
    for a in actions:
        obs, reward, terminated, truncated, _ = env.step(a)
        assert (reward, terminated, truncated) == (0.0, False, False)
        assert env.observation_space.contains(obs)
        states.append(bits(obs))
    return states


@pytest.mark.parametrize("make", ENVS)
def test_a_continuous_env_passes_the_env_checker(make):
    env = make()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        check_env(env)
    # Made directly it has no registration to make its render modes from; nothing else.
    assert all("alternative render modes" in str(w.message) for w in caught), [str(w.message) for w in caught]
    assert env.observation_space.dtype == np.float64
    assert env.observation_space.is_bounded()
    assert env.action_space.n == len(env.world.actions)


@pytest.mark.parametrize("make", ENVS)
def test_the_same_seed_gives_the_same_states_and_reset_continues_the_generator(make):
    env = make()
    actions = np.random.default_rng(3).integers(0, env.action_space.n, size=300).tolist()
    a, b = run(env, 11, actions), run(make(), 11, actions)
    assert a == b and len({tuple(s) for s in a}) > 50
    assert run(env, 12, actions) != a
    env.reset(seed=11)
    for x in actions:
        env.step(x)
    second = [bits(env.reset()[0])] + [bits(env.step(x)[0]) for x in actions]
    assert second != a


@pytest.mark.parametrize("make", ENVS)
def test_a_continuous_env_pickles_and_copies_mid_episode(make):
    env = make()
    actions = np.random.default_rng(5).integers(0, env.action_space.n, size=100).tolist()
    env.reset(seed=7)
    for a in actions[:40]:
        env.step(a)
    copies = [pickle.loads(pickle.dumps(env)), copy.deepcopy(env)]
    want = [bits(env.step(a)[0]) for a in actions[40:]]
    for other in copies:
        assert other.world == env.world
        assert [bits(other.step(a)[0]) for a in actions[40:]] == want


def swing(v):
    """Push the way the car moves: it climbs both hills within a few hundred steps."""
    return 2 if v >= 0 else 0


@pytest.mark.parametrize("controller", ["random", "swing"])
def test_the_car_s_states_are_gymnasium_s_mountain_car_s_bit_for_bit(controller):
    ours = hstl.MountainCarEnv()
    theirs = gymnasium.make("MountainCar-v0").unwrapped
    rng = np.random.default_rng(1)
    for seed in range(5):
        obs, _ = ours.reset(seed=seed)
        theirs.reset(seed=seed)
        theirs.state = np.array(obs, dtype=np.float64)  # the same start
        reached = False
        for _ in range(1000):
            a = int(rng.integers(0, 3)) if controller == "random" else swing(obs[1])
            obs, *_ = ours.step(a)
            their_obs, _, terminated, _, _ = theirs.step(a)
            # The state bit for bit; gymnasium's observation is its float32 rounding.
            assert bits(obs) == bits(theirs.state)
            assert np.array_equal(obs.astype(np.float32), their_obs)
            reached |= terminated
        # The goal ends gymnasium's episode, not ours; both walls were met on the way.
        assert reached == (controller == "swing")


def test_a_start_can_be_given_and_is_checked():
    env = hstl.PlaneEnv(YARD)
    obs, _ = env.reset(seed=0, options={"start": (1.5, 2.0)})
    assert obs.tolist() == [1.5, 2.0]
    car = hstl.MountainCarEnv()
    assert car.reset(options={"start": np.array([-0.5, 0.01])})[0].tolist() == [-0.5, 0.01]
    bad = [
        (env, (12.0, 5.0), ValueError, "inside an obstacle of world `yard`"),
        (env, (25.0, 5.0), ValueError, "`x` = 25 is outside world `yard`"),
        (env, (float("nan"), 1.0), ValueError, "`x` = NaN is outside"),
        (env, (1.0, float("inf")), ValueError, "`y` = inf is outside"),
        (env, (1.0, 2.0, 3.0), ValueError, "has 2 numbers (x, y), not 3"),
        (car, (0.0, 0.5), ValueError, "`v` = 0.5 is outside world `mountain-car`"),
        (car, "home", ValueError, "could not convert string to float"),
    ]
    for e, start, kind, words in bad:
        with pytest.raises(kind) as caught:
            e.reset(options={"start": start})
        assert words in str(caught.value)


@pytest.mark.parametrize(
    "action, kind, words",
    [
        (1.5, TypeError, "action 1.5 is not an integer of Discrete(4)"),
        (1.0, TypeError, "is not an integer"),
        (np.float64(2.0), TypeError, "is not an integer"),
        (True, TypeError, "is not an integer"),
        ("1", TypeError, "is not an integer"),
        (np.array([1.0]), TypeError, "is not an integer"),
        (np.array([1, 2]), TypeError, "is not an integer"),
        (None, TypeError, "is not an integer"),
        (-1, ValueError, "action -1 is not in Discrete(4)"),
        (4, ValueError, "action 4 is not in Discrete(4)"),
        (2**70, ValueError, "is not in Discrete(4)"),
    ],
)
def test_actions_that_are_not_the_space_s_are_refused(action, kind, words):
    for env in (hstl.PlaneEnv(), hstl.GridWorldEnv()):
        env.reset(seed=0)
        with pytest.raises(kind) as caught:
            env.step(action)
        assert words in str(caught.value)
    # Integers as agents give them are taken.
    env = hstl.PlaneEnv()
    env.reset(seed=0)
    for a in (np.int64(1), np.array(2), np.array([3]), np.uint8(0)):
        env.step(a)


def test_a_step_before_reset_is_refused():
    with pytest.raises(gymnasium.error.ResetNeeded):
        hstl.MountainCarEnv().step(1)


def test_worlds_that_are_not_the_env_s_are_refused_in_words(tmp_path):
    with pytest.raises(hstl.WorldError, match="is a grid world, not a continuous one"):
        hstl.PlaneEnv(FOUR_ROOMS)
    with pytest.raises(hstl.WorldError, match="is a grid world"):
        hstl.PlaneEnv("paper")
    with pytest.raises(ValueError, match="world `mountain-car` is not a plane world") as e:
        hstl.PlaneEnv("mountain-car")
    assert "use hstl.MountainCarEnv" in str(e.value)
    with pytest.raises(hstl.WorldError, match="unknown world `nowhere`"):
        hstl.PlaneEnv("nowhere")
    huge = tmp_path / "huge.toml"
    with open(huge, "wb") as f:
        f.truncate(9 << 20)
    with pytest.raises(ValueError, match="larger than 8 MiB, the limit for a world file"):
        hstl.PlaneEnv(huge)
    broken = tmp_path / "broken.toml"
    broken.write_text('kind = "plane"\nx = [0.0, 1.0]\ny = [0.0, 1.0]\nstep = -1\nheadings = 4\n')
    with pytest.raises(hstl.WorldError, match=r"broken.toml:4:\d+: "):
        hstl.PlaneEnv(broken)
    with pytest.raises(ValueError, match="render_mode must be None"):
        hstl.PlaneEnv(render_mode="human")


def test_the_registered_ids_make_the_continuous_worlds():
    plane = gymnasium.make("hstl/Plane-v0")
    assert plane.unwrapped.world == hstl.ContinuousWorld.builtin("paper-plane")
    assert plane.spec.max_episode_steps == hstl.MAX_EPISODE_STEPS
    yard = gymnasium.make("hstl/Plane-v0", world=str(YARD))
    assert yard.unwrapped.world.name == "yard" and yard.action_space.n == 8
    car = gymnasium.make("hstl/MountainCar-v0")
    assert car.unwrapped.world.kind == "mountain-car"
    for env in (plane, yard, car):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            check_env(env.unwrapped)
        assert not caught, [str(w.message) for w in caught]
    plane.reset(seed=0)
    for t in range(1, hstl.MAX_EPISODE_STEPS + 1):
        _, _, terminated, truncated, _ = plane.step(t % 4)
        assert not terminated and truncated == (t == hstl.MAX_EPISODE_STEPS)


def test_the_mountain_car_patrol_rewards_the_steps_whose_windows_are_kept():
    env = gymnasium.make("hstl/MountainCarPatrol-v0")
    assert isinstance(env.unwrapped, hstl.MountainCarEnv)
    example = hstl.Spec.load(REPO / "examples" / "specs" / "mountain_car_patrol.hstl")
    assert env.get_wrapper_attr("stl_spec").source == example.source
    obs, info = env.reset(seed=4)
    rewards, kept = [], []
    for _ in range(600):
        obs, reward, terminated, truncated, info = env.step(swing(obs[1]))
        rewards.append(reward)
        kept.append(info["window_kept"])
    # The window reward is 1 exactly on the steps whose windows are all kept.
    assert rewards == [1.0 if k else 0.0 for k in kept]
    assert 0 < sum(rewards) < 600
    short = gymnasium.make("hstl/MountainCarPatrol-v0", window=20)
    assert "eventually[0..20] left" in short.get_wrapper_attr("stl_spec").source
    for window, kind, words in [(0, ValueError, "must be 1 to 1000000 steps; got 0"), (1.5, TypeError, "integer")]:
        with pytest.raises(kind, match=words):
            gymnasium.make("hstl/MountainCarPatrol-v0", window=window)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        check_env(env.unwrapped)
    assert not caught, [str(w.message) for w in caught]
