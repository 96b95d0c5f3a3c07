"""`hstl.train(spec, env=..., valuation=...)`: the learner over a gymnasium environment with
`Discrete` spaces, deterministic for a seed, with what `terminated` does, what bad
environments and valuations raise, and the policy's round trip."""

from __future__ import annotations

import gymnasium
import numpy as np
import pytest
from gymnasium import spaces

import hstl

LAKE = hstl.Spec.parse(
    """spec Lake {
        state { row: int in 0..=3, col: int in 0..=3 }
        let Goal = row > 2 && col > 2;
        task eventually[0..40] Goal;
        option Goal;
        learn { episodes: 25, choices: 3, max_steps: 40 }
    }""",
    filename="lake.hstl",
)


def lake_state(obs):
    return {"row": obs // 4, "col": obs % 4}


def tables(policy):
    q = policy.q_tables
    return [t.tobytes() for t in q["flat"].values()] + [q["options"].tobytes()]


class Line(gymnasium.Env):
    """Cells 0..n-1 on a line; action 1 moves right, 0 left; cell n-1 terminates. Counts
    its calls, and slips (from its own np_random) with probability `slip`."""

    def __init__(self, n=6, slip=0.2, fail_at=None):
        self.n, self.slip, self.fail_at = n, slip, fail_at
        self.observation_space = spaces.Discrete(n)
        self.action_space = spaces.Discrete(2, start=10)
        self.steps_after_end = 0
        self.calls = 0
        self.resets = 0

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.resets += 1
        self.cell, self.ended = 0, False
        return 0, {}

    def step(self, action):
        self.calls += 1
        if self.fail_at is not None and self.calls == self.fail_at:
            raise RuntimeError("the robot fell over")
        if self.ended:
            self.steps_after_end += 1
        move = 1 if action == 11 else -1
        if self.np_random.random() < self.slip:
            move = -move
        self.cell = min(self.n - 1, max(0, self.cell + move))
        self.ended = self.cell == self.n - 1
        return self.cell, 0.0, self.ended, False, {}


LINE = hstl.Spec.parse(
    """spec Reach {
        state { s: int in 0..=5 }
        let End = s > 4;
        task eventually[0..30] End;
        option End;
        learn { episodes: 15, choices: 2, max_steps: 30 }
    }"""
)


def test_frozen_lake_trains_deterministically():
    a = hstl.train(LAKE, env=gymnasium.make("FrozenLake-v1"), valuation=lake_state, seed=3)
    b = hstl.train(LAKE, env=gymnasium.make("FrozenLake-v1"), valuation=lake_state, seed=3)
    c = hstl.train(LAKE, env=gymnasium.make("FrozenLake-v1"), valuation=lake_state, seed=4)
    assert tables(a) == tables(b) and a.json == b.json and a.curve.tolist() == b.curve.tolist()
    assert tables(a) != tables(c)
    assert a.env_name == "FrozenLake-v1" and a.actions == ["0", "1", "2", "3"] and a.world is None
    assert a.q_tables["flat"]["Goal"].shape == (16, 4) and np.any(a.q_tables["flat"]["Goal"] != 0)


def test_a_terminated_step_ends_the_learners_episode_and_only_real_steps_count():
    env = Line()
    policy = hstl.train(LINE, env=env, valuation=lambda o: {"s": o}, seed=1)
    # The learner never stepped past the end; each of its episodes reset the environment,
    # and every step it counts is a call of env.step.
    assert env.steps_after_end == 0 and env.calls == policy.steps
    assert env.resets == 15
    assert hstl.train(LINE, env=Line(), valuation=lambda o: {"s": o}, seed=1) == policy
    # Actions are the environment's own (Discrete(2, start=10)).
    assert policy.actions == ["10", "11"]
    policy.reset()
    assert policy.act(0) in (10, 11) and policy.act({"s": 3}) in (10, 11)
    report = policy.evaluate(starts=4, steps=30, env=Line(), valuation=lambda o: {"s": o})
    assert len(report["robustness"]) == 4 and report["window_rate"] is None


class Counted(gymnasium.Wrapper):
    """Counts the steps and episodes of the environment it wraps, and the steps taken
    after an episode ended without a reset between."""

    def __init__(self, env):
        super().__init__(env)
        self.steps = self.episodes = self.after_end = 0
        self.ended = False

    def reset(self, **kwargs):
        self.episodes += 1
        self.ended = False
        return self.env.reset(**kwargs)

    def step(self, action):
        self.after_end += self.ended
        self.steps += 1
        obs, reward, terminated, truncated, info = self.env.step(action)
        self.ended = terminated or truncated
        return obs, reward, terminated, truncated, info


def test_frozen_lake_episodes_end_where_gymnasiums_do():
    env = Counted(gymnasium.make("FrozenLake-v1"))
    policy = hstl.train(LAKE, env=env, valuation=lake_state, seed=3, episodes=200)
    assert env.after_end == 0 and env.steps == policy.steps and env.episodes == 200
    # An episode is at most choices x max_steps = 120 steps, and most end in a hole sooner.
    assert policy.steps < 200 * 40


def test_a_saved_policy_loads_and_needs_its_environment_to_evaluate(tmp_path):
    policy = hstl.train(LINE, env=Line(), valuation=lambda o: {"s": o}, seed=2)
    policy.save(tmp_path / "policy.json")
    loaded = hstl.Policy.load(tmp_path / "policy.json")
    assert loaded == policy and tables(loaded) == tables(policy)
    with pytest.raises(TypeError, match="pass `env=`"):
        loaded.evaluate()
    with pytest.raises(ValueError, match="outside Discrete"):
        loaded.act(6)
    same = loaded.evaluate(starts=3, steps=20, env=Line(), valuation=lambda o: {"s": o})
    assert same == policy.evaluate(starts=3, steps=20, env=Line(), valuation=lambda o: {"s": o})
    with pytest.raises(ValueError, match=r"trained on `Line` \(Discrete\(6\) observations, Discrete\(2, start=10\) actions\); `env` is `Line` \(Discrete\(5\)"):
        loaded.evaluate(env=Line(n=5), valuation=lambda o: {"s": o})
    # The states are named by their values: a relabelled environment replays the same policy.
    relabelled = loaded.evaluate(starts=3, steps=20, env=Line(), valuation=lambda o: {"s": 5 - o})
    assert len(relabelled["robustness"]) == 3


def test_bad_environments_and_valuations_raise():
    line = lambda o: {"s": o}  # noqa: E731
    with pytest.raises(TypeError, match="needs a `Discrete` observation space; this environment's is Box"):
        hstl.train(LINE, env=gymnasium.make("CartPole-v1"), valuation=line)
    with pytest.raises(TypeError, match="needs valuation="):
        hstl.train(LINE, env=Line())
    with pytest.raises(TypeError, match="either world= or env="):
        hstl.train(LINE, world="four-rooms", env=Line(), valuation=line)
    with pytest.raises(ValueError, match=r"valuation\(5\) gives `s` = 7, outside its declared domain 0..=5"):
        hstl.train(LINE, env=Line(), valuation=lambda o: {"s": o + 2 if o == 5 else o})
    with pytest.raises(ValueError, match="observations 0 and 1 have the same valuation"):
        hstl.train(LINE, env=Line(), valuation=lambda o: {"s": o // 2})
    with pytest.raises(hstl.MissingVariableError, match=r"valuation\(0\): missing state variable `s`"):
        hstl.train(LINE, env=Line(), valuation=lambda o: {"t": o})
    with pytest.raises(ZeroDivisionError):
        hstl.train(LINE, env=Line(), valuation=lambda o: 1 / 0)
    with pytest.raises(ValueError, match="observations; the learner's tables take 1 to"):
        big = Line()
        big.observation_space = spaces.Discrete(2**40)
        hstl.train(LINE, env=big, valuation=line)


def test_an_exception_in_the_environment_stops_training_and_is_raised():
    env = Line(fail_at=50)
    with pytest.raises(RuntimeError, match="the robot fell over"):
        hstl.train(LINE, env=env, valuation=lambda o: {"s": o}, episodes=1000)
    # Training stopped at the end of that episode: far fewer calls than 1000 episodes make.
    assert env.calls == 50

    class BadObservation(Line):
        def step(self, action):
            return "left", 0.0, False, False, {}

    with pytest.raises(ValueError, match="env.step gave the observation 'left', not an integer"):
        hstl.train(LINE, env=BadObservation(), valuation=lambda o: {"s": o})

    class OffTheLine(Line):
        def step(self, action):
            return 9, 0.0, False, False, {}

    with pytest.raises(ValueError, match=r"env.step gave the observation 9, outside Discrete\(6, start=0\)"):
        hstl.train(LINE, env=OffTheLine(), valuation=lambda o: {"s": o})


class Cliff(gymnasium.Env):
    """Cells 0..n-1 on a line, from cell 1: cell 0 is a hole and cell n-1 the goal, both
    terminal (action 1 moves right, 0 left; no slip). Every step earns robustness below 0
    on the way, so a learner that valued a terminal state as neutral (its episode over)
    would jump into the hole rather than walk to the goal."""

    def __init__(self, n=12, limit=None):
        self.n, self.limit = n, limit
        self.observation_space = spaces.Discrete(n)
        self.action_space = spaces.Discrete(2)

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.cell, self.t = 1, 0
        return 1, {}

    def step(self, action):
        self.t += 1
        self.cell = min(self.n - 1, max(0, self.cell + (1 if action == 1 else -1)))
        terminated = self.cell in (0, self.n - 1)
        truncated = self.limit is not None and self.t >= self.limit
        return self.cell, 0.0, terminated, truncated and not terminated, {}


CLIFF = hstl.Spec.parse(
    """spec Cliff {
        state { s: int in 0..=11 }
        let Goal = s > 10;
        task eventually[0..40] Goal;
        option Goal;
        learn { episodes: 400, choices: 1, max_steps: 40 }
    }"""
)


def test_a_terminal_state_is_valued_as_one_the_robot_never_leaves():
    policy = hstl.train(CLIFF, env=Cliff(), valuation=lambda o: {"s": o}, seed=0)
    q = policy.q_tables["flat"]["Goal"]
    # Right (1) from every cell on the way: the hole at 0 is worse than the long walk.
    assert q[1:11].argmax(axis=1).tolist() == [1] * 10, q
    report = policy.evaluate(starts=3, steps=40, env=Cliff(), valuation=lambda o: {"s": o})
    assert report["satisfied"] == 3


def test_the_examples_frozen_lake_spec_comes_within_a_tenth_of_the_optimum():
    from conftest import REPO

    source = (REPO / "examples" / "python" / "train.py").read_text()
    # The example's lake spec, valuation and optimum, without its case study.
    part = source[source.index("LAKE = ") : source.index("frozen = hstl.train")]
    ns: dict = {"gymnasium": gymnasium, "hstl": hstl}
    exec(part, ns)
    best = ns["lake_optimum"](100)
    assert 0.74 < best < 0.75
    policy = hstl.train(hstl.Spec.parse(ns["LAKE"]), env=gymnasium.make("FrozenLake-v1"), valuation=ns["cell"], seed=0)
    report = policy.evaluate(starts=500, steps=100, env=gymnasium.make("FrozenLake-v1"), valuation=ns["cell"])
    assert report["satisfied"] / 500 >= 0.9 * best
    assert policy.steps < 2000 * 100, "every counted step is a real one"
