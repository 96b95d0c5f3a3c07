"""Gymnasium: `GridWorldEnv` passes gymnasium's checker and draws from its one seeded
generator, the registered ids make the built-in worlds, and `STLReward`'s rewards and
task robustness are those of `hstlc monitor` on the same trace."""

from __future__ import annotations

import itertools
import subprocess
import sys
import warnings

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import hstl
from conftest import CLI_FIXTURES, REPO, run_cli

SURVEILLANCE = CLI_FIXTURES / "surveillance.hstl"
REACH = CLI_FIXTURES / "reach.hstl"
CORRIDORS = REPO / "examples" / "worlds" / "corridors.toml"


@pytest.mark.parametrize("world", ["paper", "four-rooms", CORRIDORS], ids=["paper", "four-rooms", "corridors"])
def test_grid_world_env_passes_the_env_checker(world):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        check_env(hstl.GridWorldEnv(world))
    # Made directly it has no registration to make its render modes from; nothing else.
    assert all("alternative render modes" in str(w.message) for w in caught), [str(w.message) for w in caught]


@pytest.mark.parametrize("env_id, world", sorted(hstl._registration.REGISTERED.items()))
def test_the_registered_ids_make_the_built_in_worlds(env_id, world):
    env = gymnasium.make(env_id)
    assert env.unwrapped.world == hstl.World.builtin(world)
    assert env.spec.max_episode_steps == hstl.MAX_EPISODE_STEPS == 2000
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        check_env(env.unwrapped)
    assert not caught, [str(w.message) for w in caught]
    assert gymnasium.make("hstl/GridWorld-v0").unwrapped.world.name == "paper"
    # The time limit truncates an episode after max_episode_steps.
    env.reset(seed=0)
    for t in range(1, 2001):
        _, _, terminated, truncated, _ = env.step(t % 4)
        assert not terminated and truncated == (t == 2000)


def run(env, seed, actions):
    obs, info = env.reset(seed=seed)
    cells = [tuple(obs)]
    for a in actions:
        obs, reward, terminated, truncated, info = env.step(a)
        assert (reward, terminated, truncated) == (0.0, False, False)
        cells.append(tuple(obs))
    return cells


def test_the_same_seed_gives_the_same_cells_and_reset_continues_the_generator():
    actions = np.random.default_rng(3).integers(0, 4, size=400)
    env = hstl.GridWorldEnv("four-rooms")
    a, b = run(env, 11, actions), run(hstl.GridWorldEnv("four-rooms"), 11, actions)
    assert a == b and len(set(a)) > 20
    assert run(env, 12, actions) != a
    # reset() without a seed continues the generator: another start and other slips.
    env.reset(seed=11)
    for x in actions:
        env.step(x)
    second = [tuple(env.reset()[0])] + [tuple(env.step(x)[0]) for x in actions]
    assert second != a
    world = env.world
    assert all(world.is_free(x, y) for x, y in a + second)
    # Slips happen at the world's rate: the chosen action is taken with p = 1 - slip.
    env.reset(seed=5)
    moved_up = 0
    for _ in range(4000):
        env.reset(options={"start": (3, 3)})
        moved_up += tuple(env.step(0)[0]) == (3, 4)
    assert abs(moved_up / 4000 - (1 - world.slip)) < 0.03


def test_bad_calls_raise():
    env = hstl.GridWorldEnv()
    with pytest.raises(gymnasium.error.ResetNeeded):
        env.step(0)
    env.reset(seed=0)
    with pytest.raises(ValueError, match="not in Discrete"):
        env.step(4)
    with pytest.raises(ValueError, match=r"`seed` must be in 0\.\.="):
        env.reset(seed=2**64)
    with pytest.raises(ValueError, match="not a free cell of world `four-rooms`"):
        hstl.GridWorldEnv("four-rooms").reset(options={"start": (0, 0)})
    with pytest.raises(ValueError, match="render_mode"):
        hstl.GridWorldEnv(render_mode="human")
    with pytest.raises(hstl.WorldError, match="unknown world `mars`"):
        hstl.GridWorldEnv("mars")
    env = hstl.GridWorldEnv("four-rooms", render_mode="ansi")
    env.reset(options={"start": (1, 1)})
    assert env.render().splitlines()[-2] == "#R....#.....#"


def write_csv(path, cells):
    path.write_text("x,y\n" + "".join(f"{x},{y}\n" for x, y in cells))
    return path


def cli_signal(hstlc, spec, trace, formula=None):
    args = ["monitor", str(spec), "--trace", str(trace), "--signal"] + (["--formula", formula] if formula else [])
    out = run_cli(hstlc, *args)
    assert out.returncode == 0, out.stderr
    return [float(line.split(",")[1]) for line in out.stdout.splitlines()[1:]]


def cli_robustness(hstlc, spec, trace):
    out = run_cli(hstlc, "monitor", str(spec), "--trace", str(trace))
    assert out.returncode == 0, out.stderr
    return float(out.stdout)


def episode(env, seed, steps, start=None, up=0.25):
    """A random episode through `env` (an `STLReward`), from `start`, moving up with
    probability `up`: its cells, rewards and infos."""
    rng = np.random.default_rng(seed)
    obs, info = env.reset(seed=seed, options={"start": start} if start else None)
    cells, rewards, infos = [tuple(int(v) for v in obs)], [], [info]
    down = (1 - up) / 3
    for _ in range(steps):
        obs, reward, _, _, info = env.step(rng.choice(4, p=[up, down, down, down]))
        cells.append(tuple(int(v) for v in obs))
        rewards.append(reward)
        infos.append(info)
    return cells, rewards, infos


def test_a_regions_rewards_are_hstlc_monitors_signal(hstlc, tmp_path):
    env = hstl.STLReward(gymnasium.make("hstl/GridWorld-v0"), SURVEILLANCE, formula="A")
    cells, rewards, infos = episode(env, 2016, 600, start=(6, 6), up=0.3)
    trace = write_csv(tmp_path / "walk.csv", cells)
    signal = cli_signal(hstlc, SURVEILLANCE, trace, "A")
    # The reward of the step into s_t is the region's signal at t, bit for bit.
    assert np.array_equal(np.array(rewards), np.array(signal[1:]))
    assert any(r > 0 for r in rewards) and any(r < 0 for r in rewards)
    assert all(i["env_reward"] == 0.0 for i in infos[1:])
    # The task's robustness over the whole episode is what hstlc monitor prints for it.
    assert infos[-1]["task_robustness"] == cli_robustness(hstlc, SURVEILLANCE, trace)
    kept = [i["window_kept"] for i in infos]
    assert kept[0] is False and kept.count(True) < len(kept)


def test_rewards_and_task_robustness_are_hstlc_monitors_on_every_prefix(hstlc, tmp_path):
    env = hstl.STLReward(hstl.GridWorldEnv(), REACH)
    cells, rewards, infos = episode(env, 7, 40)
    assert all("window_kept" not in i for i in infos), "not a persistent task"
    for t in [0, 1, 5, 17, 31, 40]:
        prefix = write_csv(tmp_path / f"prefix{t}.csv", cells[: t + 1])
        assert infos[t]["task_robustness"] == cli_robustness(hstlc, REACH, prefix), t
        if t > 0:
            # rho(task, t) over the trace so far: the last row of --signal on the prefix.
            assert rewards[t - 1] == cli_signal(hstlc, REACH, prefix)[-1], t


def test_state_variables_come_from_the_observation_as_the_user_maps_them():
    spec = hstl.Spec.parse("spec P { state { y: float, x: float } let Top = y > 12; task eventually[0..] Top; }")
    env = hstl.STLReward(hstl.GridWorldEnv(), spec, formula="Top")
    obs, _ = env.reset(options={"start": (2, 14)})
    assert env.step(2)[1] in (1.0, 2.0)  # y 13 or 14, whatever the order of the spec's variables
    # A dict of indices, a callable, or an observation that is a dict.
    mapped = hstl.STLReward(hstl.GridWorldEnv(), spec, valuation={"x": 0, "y": 1}, formula="Top")
    called = hstl.STLReward(hstl.GridWorldEnv(), spec, valuation=lambda o: {"x": o[0], "y": o[1]}, formula="Top")
    for wrapped in (mapped, called):
        wrapped.reset(options={"start": (2, 14)})
        assert wrapped.step(2)[1] in (1.0, 2.0)
    with pytest.raises(hstl.MissingVariableError, match="no entry for state variable `x`"):
        hstl.STLReward(hstl.GridWorldEnv(), spec, valuation={"y": 1})
    other = hstl.Spec.parse("spec Q { state { z: float } task always[0..] z > 0; }")
    with pytest.raises(TypeError, match="state variable `z`"):
        hstl.STLReward(hstl.GridWorldEnv(), other)
    with pytest.raises(TypeError, match="pass valuation="):
        hstl.STLReward(gymnasium.make("FrozenLake-v1"), other)
    with pytest.raises(ValueError, match="no `let` named `Nope`"):
        hstl.STLReward(hstl.GridWorldEnv(), spec, formula="Nope")
    nan = hstl.STLReward(hstl.GridWorldEnv(), spec, valuation=lambda o: {"x": float("nan"), "y": 1.0})
    with pytest.raises(ValueError, match="`x` is NaN at step 0"):
        nan.reset(seed=0)


def test_a_policy_replayed_in_gymnasium_is_hstlc_evals_run(tmp_path):
    """The greedy policy acting in GridWorldEnv, seeded as `evaluate` seeds its runs,
    visits the cells `evaluate` scores: STLReward's windows kept and task robustness give
    its window rate and robustness exactly."""
    policy = hstl.train(CLI_FIXTURES / "small.hstl", seed=3, episodes=10)
    steps, burn_in = 400, 50
    report = policy.evaluate(starts=1, steps=steps, burn_in=burn_in, seed=9, optimum=False)
    env = hstl.STLReward(hstl.GridWorldEnv(policy.world), CLI_FIXTURES / "small.hstl")
    obs, info = env.reset(seed=9)
    policy.reset()
    kept = [info["window_kept"]]
    for _ in range(steps - 1):
        obs, _, _, _, info = env.step(policy.act(obs))
        kept.append(info["window_kept"])
    assert sum(kept[burn_in:]) / (steps - burn_in) == report["window_rate"]
    assert info["task_robustness"] == report["robustness"][0]
    assert 0 < sum(kept) < steps


def test_increments_add_up_to_the_task_robustness_of_the_episode():
    env = hstl.STLReward(gymnasium.make("hstl/GridWorld-v0"), REACH, reward="increment")
    for seed in (1, 2, 3):
        _, rewards, infos = episode(env, seed, 120, up=0.4)
        final = infos[-1]["task_robustness"]
        assert sum(rewards) == pytest.approx(final if np.isfinite(final) else 0.0)
        assert all(np.isfinite(rewards))


PATROL = """spec Patrol {
    state { x: int in 0..=14, y: int in 0..=14 }
    let Low = y < 6;
    let Left = x < 6;
    task always[0..] (eventually[0..=10] Low && eventually[0..=10] Left);
}"""


def test_the_window_reward_is_one_per_kept_step_with_offset_and_scale():
    patrol = hstl.Spec.parse(PATROL)
    env = hstl.STLReward(hstl.GridWorldEnv(), patrol, reward="window")
    _, rewards, infos = episode(env, 2016, 300, start=(6, 6), up=0.3)
    assert rewards == [1.0 if i["window_kept"] else 0.0 for i in infos[1:]]
    assert 0 < sum(rewards) < len(rewards)
    shifted = hstl.STLReward(hstl.GridWorldEnv(), patrol, reward="window", offset=-0.5, scale=2.0)
    _, twice, _ = episode(shifted, 2016, 300, start=(6, 6), up=0.3)
    assert twice == [2.0 * r - 0.5 for r in rewards]
    assert (shifted.reward_form, shifted.reward_offset, shifted.reward_scale) == ("window", -0.5, 2.0)


def test_the_sparse_reward_comes_at_the_episodes_end_only():
    env = hstl.STLReward(gymnasium.make("hstl/GridWorld-v0", max_episode_steps=30), REACH, reward="sparse")
    env.reset(seed=5)
    rewards, truncated, info = [], False, {}
    while not truncated:
        _, reward, _, truncated, info = env.step(0)
        rewards.append(reward)
    assert len(rewards) == 30 and rewards[:-1] == [0.0] * 29
    assert rewards[-1] == info["task_robustness"]


def test_reward_forms_that_do_not_fit_say_what_to_pick():
    with pytest.raises(ValueError, match="unknown reward form `dense`\n  help: the forms are `robustness`, `increment`"):
        hstl.STLReward(hstl.GridWorldEnv(), REACH, reward="dense")
    with pytest.raises(ValueError, match="`window` needs a persistent task.*\n  help: .*use `increment` or `sparse`"):
        hstl.STLReward(hstl.GridWorldEnv(), REACH, reward="window")
    with pytest.raises(ValueError, match="`window` scores the task's windows, not the `let` `A`"):
        hstl.STLReward(hstl.GridWorldEnv(), SURVEILLANCE, reward="window", formula="A")
    with pytest.raises(ValueError, match="scale must be a positive finite number; got 0"):
        hstl.STLReward(hstl.GridWorldEnv(), REACH, scale=0.0)
    with pytest.raises(ValueError, match="offset must be a finite number; got NaN"):
        hstl.STLReward(hstl.GridWorldEnv(), REACH, offset=float("nan"))


def test_gymnasium_imports_hstl_itself_by_the_module_prefix():
    import subprocess
    import sys

    code = "import gymnasium; env = gymnasium.make('hstl:hstl/FourRooms-v0'); print(env.unwrapped.world.name)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0 and out.stdout.strip() == "four-rooms", out.stderr


def python(code: str) -> subprocess.CompletedProcess:
    """Runs `code` in a fresh interpreter (this one has imported gymnasium already)."""
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)


def test_import_hstl_leaves_gymnasium_unimported_until_a_gym_class_is_used():
    out = python(
        "import sys, hstl\n"
        "assert 'gymnasium' not in sys.modules, 'import hstl imported gymnasium'\n"
        "assert 'hstl._gym' not in sys.modules\n"
        "spec = hstl.formula('always[0..=2] x > 0')\n"
        "assert spec.robustness({'x': [1.0, 2.0, 3.0]}) == 1.0\n"
        "assert 'gymnasium' not in sys.modules, 'monitoring imported gymnasium'\n"
        "assert 'STLReward' in dir(hstl) and 'STLReward' in hstl.__all__\n"
        "env = hstl.GridWorldEnv('paper')\n"
        "assert 'gymnasium' in sys.modules and isinstance(env, sys.modules['gymnasium'].Env)\n"
        "assert hstl.STLReward.__module__ == 'hstl._gym'\n"
        "print('ok')\n"
    )
    assert out.returncode == 0 and out.stdout == "ok\n", out.stderr


@pytest.mark.parametrize(
    "code",
    [
        # gymnasium imported after hstl: the ids are registered when its import ends.
        "import hstl, gymnasium\nenv = gymnasium.make('hstl/FourRooms-v0')",
        # gymnasium imported before hstl: registered by `import hstl`.
        "import gymnasium, hstl\nenv = gymnasium.make('hstl/FourRooms-v0')",
        # gymnasium's `module:id` form imports hstl itself.
        "import gymnasium\nenv = gymnasium.make('hstl:hstl/FourRooms-v0')",
        # gymnasium imported by hstl's own first use.
        "import hstl\nhstl.STLReward\nimport gymnasium\nenv = gymnasium.make('hstl/FourRooms-v0')",
    ],
    ids=["hstl-then-gymnasium", "gymnasium-then-hstl", "module-id", "after-first-use"],
)
def test_the_ids_are_registered_whichever_is_imported_first(code):
    out = python(
        code + "\nassert env.unwrapped.world.name == 'four-rooms'\n"
        "assert env.spec.max_episode_steps == 2000\n"
        "import importlib\n"
        "importlib.reload(gymnasium)\n"
        "assert gymnasium.make('hstl/GridWorld-v0').unwrapped.world.name == 'paper'\n"
        "print('ok')\n"
    )
    assert out.returncode == 0 and out.stdout == "ok\n", out.stderr


def python_env(code: str, **env: str) -> subprocess.CompletedProcess:
    """`python(code)` with `env` added to the environment."""
    import os

    return subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=120, env={**os.environ, **env}
    )


def test_gymnasium_knows_the_ids_without_import_hstl():
    # gymnasium >= 1.0 has no plugin entry points: the wheel's `hstl-gymnasium.pth` imports
    # the top-level `_hstl_gym` at interpreter start, which waits for gymnasium's import
    # without importing hstl (its extension loads only when an environment is made).
    out = python(
        "import sys\n"
        "assert '_hstl_gym' in sys.modules, 'hstl-gymnasium.pth did not run'\n"
        "assert 'hstl' not in sys.modules and 'gymnasium' not in sys.modules\n"
        "import gymnasium\n"
        "assert 'hstl' not in sys.modules, 'registering imported hstl'\n"
        "env = gymnasium.make('hstl/FourRooms-v0')\n"
        "print(env.unwrapped.world.name)"
    )
    assert out.returncode == 0 and out.stdout == "four-rooms\n", out.stderr


def test_the_startup_registration_can_be_turned_off():
    out = python_env("import gymnasium\ngymnasium.make('hstl/GridWorld-v0')", HSTL_NO_GYMNASIUM_IDS="1")
    assert out.returncode != 0 and "NamespaceNotFound" in out.stderr, out.stderr
    # `import hstl` registers them all the same.
    out = python_env("import hstl, gymnasium\nprint(gymnasium.make('hstl/GridWorld-v0').unwrapped.world.name)", HSTL_NO_GYMNASIUM_IDS="1")
    assert out.returncode == 0 and out.stdout == "paper\n", out.stderr


PENDULUM = """spec Swing {
    state { cart: float, angle: float }
    let right = cart > 0.0;
    let left = cart < 0.0;
    let fallen = angle >= 0.2 || angle <= -0.2;
    task always[0..] (eventually[0..=5] right && eventually[0..=5] left) && always[0..] !fallen;
}"""


class _Wobble(gymnasium.Env):
    """Four observation entries from a seeded walk, in a given dtype (or a list), with an
    info of its own; the episode ends at step 40."""

    def __init__(self, dtype="float64"):
        self.dtype = dtype
        self.observation_space = gymnasium.spaces.Box(-10, 10, (4,), np.float64 if dtype == "list" else dtype)
        self.action_space = gymnasium.spaces.Discrete(2)
        self.infos = []

    def _obs(self):
        x = self.rng.normal(0, 0.15, 4)
        return [float(v) for v in x] if self.dtype == "list" else x.astype(self.dtype)

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.rng, self.t = np.random.default_rng(seed), 0
        return self._obs(), {"from_env": 0}

    def step(self, action):
        self.t += 1
        info = {"from_env": self.t}
        self.infos.append(info)
        return self._obs(), 0.5 * action, self.t == 40, False, info


@pytest.mark.parametrize("dtype", ["float64", "float32", "list"])
@pytest.mark.parametrize("reward", ["robustness", "window", "sparse"])
def test_a_dict_of_observation_indices_scores_as_a_valuation_function_does(dtype, reward):
    spec = hstl.Spec.parse(PENDULUM)
    by_index = hstl.STLReward(_Wobble(dtype), spec, valuation={"angle": 1, "cart": 0}, reward=reward)
    by_call = hstl.STLReward(_Wobble(dtype), spec, valuation=lambda o: [float(o[0]), float(o[1])], reward=reward)
    for env in (by_index, by_call):
        env.reset(seed=7)
    for t in range(1, 41):
        a = by_index.step(t % 2)
        b = by_call.step(t % 2)
        assert a[1:4] == b[1:4] and a[4] == b[4], t
        assert a[4]["from_env"] == t and a[4]["env_reward"] == 0.5 * (t % 2) and "window_kept" in a[4]
    # The wrapped environment's own info is left as it was.
    assert all(set(i) == {"from_env"} for i in by_index.env.infos)


def test_an_observation_index_past_the_end_says_which_variable():
    env = hstl.STLReward(_Wobble(), hstl.Spec.parse(PENDULUM), valuation={"cart": 0, "angle": 4})
    with pytest.raises(ValueError, match=r"the observation has 4 entries, and `angle` is read from index 4"):
        env.reset(seed=1)


CAR = """spec Car {
    state { x: float in -1.2..=0.6, v: float in -0.07..=0.07 }
    let Right = x > -0.4;
    let Left = x < -0.6;
    task always[0..] (eventually[0..20] Right && eventually[0..20] Left);
}
"""


def test_the_vector_reward_scores_each_environment_as_stlreward_does():
    # Three MountainCar environments cut at 25 steps, so that each resets itself within
    # the run; each row against its own STLReward driven by the same actions and seeds.
    spec = hstl.Spec.parse(CAR)

    def make() -> gymnasium.Env:
        return gymnasium.wrappers.TimeLimit(hstl.MountainCarEnv(), max_episode_steps=25)

    vector = hstl.STLVectorReward(gymnasium.vector.SyncVectorEnv([make for _ in range(3)]), spec, {"x": 0, "v": 1})
    singles = [hstl.STLReward(make(), spec, {"x": 0, "v": 1}) for _ in range(3)]
    obs, info = vector.reset(seed=10)
    for i, single in enumerate(singles):
        o, inf = single.reset(seed=10 + i)
        assert np.array_equal(obs[i], o) and info["task_robustness"][i] == inf["task_robustness"]
        assert info["window_kept"][i] == inf["window_kept"]
    rng = np.random.default_rng(3)
    done = [False] * 3
    restarts = 0
    for _ in range(80):
        actions = rng.integers(0, 3, size=3)
        obs, rewards, terminated, truncated, info = vector.step(actions)
        assert rewards.dtype == np.float64 and rewards.shape == (3,)
        for i, single in enumerate(singles):
            if done[i]:
                # The vector reset this environment: its row starts the next episode.
                o, inf = single.reset()
                want_reward, restarts = 0.0, restarts + 1
            else:
                o, want_reward, _, _, inf = single.step(int(actions[i]))
            assert np.array_equal(obs[i], o)
            assert rewards[i] == want_reward
            assert info["task_robustness"][i] == inf["task_robustness"]
            assert info["window_kept"][i] == inf["window_kept"]
        done = list(np.logical_or(terminated, truncated))
    assert restarts >= 6


def test_the_vector_reward_refuses_what_it_cannot_score():
    spec = hstl.Spec.parse(CAR)

    def make() -> gymnasium.Env:
        return hstl.MountainCarEnv()

    same_step = gymnasium.vector.SyncVectorEnv([make], autoreset_mode=gymnasium.vector.AutoresetMode.SAME_STEP)
    with pytest.raises(ValueError, match="NEXT_STEP"):
        hstl.STLVectorReward(same_step, spec, {"x": 0, "v": 1})
    with pytest.raises(hstl.MissingVariableError, match="`v`"):
        hstl.STLVectorReward(gymnasium.vector.SyncVectorEnv([make]), spec, {"x": 0})
    vector = hstl.STLVectorReward(gymnasium.vector.SyncVectorEnv([make, make]), spec, {"x": 0, "v": 5})
    with pytest.raises(ValueError, match="reads columns up to 5"):
        vector.reset(seed=0)
    # The batch underneath: a vector size past its budget is refused before anything is
    # allocated (it aborted the interpreter), and rows in Fortran order are not misread.
    with pytest.raises(ValueError, match="at most 4096 are scored together"):
        hstl._hstl.EpisodeBatch(spec, 10**12, [0, 1])
    batch = hstl._hstl.EpisodeBatch(spec, 2, [0, 1])
    with pytest.raises(ValueError, match="environment 1 of the vector: `x` is NaN"):
        batch._reset((np.array([[0.0, 0.0], [np.nan, 0.0]]), {}))
    with pytest.raises(TypeError, match="the vector environment's reset returned a list, not the tuple of gymnasium's"):
        batch._reset([np.zeros((2, 2)), {}])
    with pytest.raises(TypeError, match="the vector environment's info is a NoneType, not a dict"):
        batch._reset((np.zeros((2, 2)), None))
    with pytest.raises(TypeError, match="returned 4 values, not the 5 of gymnasium's"):
        batch._step((np.zeros((2, 2)), np.zeros(2), np.zeros(2, dtype=bool), {}))
    with pytest.raises(ValueError, match="`truncated` holds 3 values; this vector has 2 environments"):
        batch._step((np.zeros((2, 2)), np.zeros(2), np.zeros(2, dtype=bool), np.zeros(3, dtype=bool), {}))
    with pytest.raises(ValueError, match=r"the observations \(shape \(2, 2\)\) must be a 2-D array of numbers"):
        batch._step((np.array([["a", "b"], ["c", "d"]]), np.zeros(2), [False, False], [False, False], {}))
    with pytest.raises(ValueError, match=r"the observations \(shape \(2, 2, 1\)\) must be a 2-D array"):
        batch._step((np.zeros((2, 2, 1)), np.zeros(2), [False, False], [False, False], {}))
    # Flags that are not one boolean an environment say so (a 2-D array, a number).
    with pytest.raises(TypeError, match="`terminated` must be one boolean for each environment; got a value of type ndarray"):
        batch._step((np.zeros((2, 2)), np.zeros(2), np.zeros((2, 2), dtype=bool), [False, False], {}))
    with pytest.raises(TypeError, match="`truncated` must be one boolean for each environment; got a value of type int"):
        batch._step((np.zeros((2, 2)), np.zeros(2), [False, False], 3, {}))
    # An endless iterable of flags is refused after one value too many, not read forever.
    with pytest.raises(ValueError, match="`terminated` holds more values; this vector has 2 environments"):
        batch._step((np.zeros((2, 2)), np.zeros(2), itertools.repeat(False), [False, False], {}))


def test_the_vector_reward_reads_rows_in_any_order_and_float_type():
    # Rows in Fortran order (they were once misread), float32 rows and flags given as
    # lists score as C-ordered float64 rows and boolean arrays do.
    spec = hstl.Spec.parse(CAR)
    rows = np.array([[-1.1, 0.01], [0.5, -0.02], [0.0, 0.0]])
    other = np.array([[-0.3, 0.02], [-1.05, 0.0], [0.45, 0.01]])
    forms = [
        (rows, other, np.array([False, True, False])),
        (np.asfortranarray(rows), np.asfortranarray(other), [False, True, False]),
        (rows.astype(np.float32), other.astype(np.float32), (0, 1, 0)),
    ]
    got = []
    for first, second, flags in forms:
        batch = hstl._hstl.EpisodeBatch(spec, 3, [0, 1])
        _, info = batch._reset((first, {}))
        _, rewards, _, _, info2 = batch._step((second, np.zeros(3), flags, [False] * 3, {"k": 1}))
        assert info2["k"] == 1 and list(info2["_env_reward"]) == [True] * 3
        got.append((list(info["task_robustness"]), list(rewards), list(info2["task_robustness"]), list(info2["window_kept"])))
    want = got[0]
    assert got[1] == want
    # float32 rows are the float32 values, widened.
    assert np.allclose(got[2][1], want[1], atol=1e-6) and got[2][3] == want[3]
