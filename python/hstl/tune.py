"""``hstl.tune``: a spec's ``learn`` values tuned with Ray Tune.

``trainable`` is a Tune function trainable: it trains one spec with the ``learn`` values of
Tune's config set over the spec's own, in chunks of episodes, and after each chunk reports
the greedy policy's window rate W (and W/W*), its task robustness and the reward per
episode, so that Tune's schedulers (ASHA, for example) stop poor trials early::

    from ray import tune
    from ray.tune.schedulers import ASHAScheduler
    import hstl.tune

    tuner = tune.Tuner(
        hstl.tune.trainable_for("examples/specs/surveillance_memory.hstl"),
        param_space={"flat_alpha": tune.loguniform(0.05, 1.0),
                     "options_alpha": tune.loguniform(0.05, 1.0)},
        tune_config=tune.TuneConfig(metric="window_rate", mode="max", num_samples=8,
                                    scheduler=ASHAScheduler(time_attr="episodes", max_t=1200)),
    )
    best = tuner.fit().get_best_result().config

The training is the facade's (``hstl::train::train_in_chunks``): run to the end, a trial
is the run ``hstl.train`` does with the same values, draw for draw, whatever the chunks.
The ``learn`` keys are ``hstl.tune.LEARN_KEYS``: ``episodes``, ``choices``, ``max_steps``,
and ``flat_`` or ``options_`` followed by ``gamma``, ``alpha``, ``epsilon``,
``min_epsilon`` or ``decay``; each value is held to the range the spec's ``learn { ... }``
is checked against.
"""

from __future__ import annotations

import os
from typing import Any, Callable, Dict, Mapping, Optional, Union

from . import _hstl
from ._hstl import Spec, World
from ._train import _seed_of, world_of

#: The ``learn`` values a config may set.
LEARN_KEYS = tuple(_hstl.LEARN_KEYS)

#: Episodes between two reports, unless the config says otherwise.
DEFAULT_CHUNK = 50

#: Config keys that are not ``learn`` values.
_OWN_KEYS = ("spec", "world", "seed", "chunk", "optimum")


def _report_function() -> Callable[[Dict[str, Any]], None]:
    """Tune's report call: ``ray.tune.report`` (Ray 2.43 and later, the function API's own),
    else ``ray.train.report`` (the earlier Ray 2 releases)."""
    from ray import tune

    report: Optional[Callable[[Dict[str, Any]], None]] = getattr(tune, "report", None)
    if report is None:  # pragma: no cover - older Ray
        from ray import train

        report = train.report
    return report


def trainable(config: Mapping[str, Any]) -> None:
    """A Ray Tune function trainable for one spec.

    ``config`` holds ``spec`` (a ``hstl.Spec`` or a spec file's path), and may hold
    ``world`` (a ``hstl.World``, a built-in name or a world file; default: the one the spec
    names, else ``"paper"``),
    ``seed`` (default 0), ``chunk`` (episodes between reports, default ``DEFAULT_CHUNK``),
    ``optimum`` (W*, to report ``ratio``; see ``trainable_for``) and any of
    ``LEARN_KEYS``. Each report holds ``episodes`` (trained so far), ``reward`` (per
    episode, the mean of the last 100), and for a persistent task ``window_rate`` (W of the
    greedy policy now), ``robustness`` (its task robustness, mean over the evaluation's
    runs) and, given ``optimum``, ``ratio`` (W/W*). Use ``time_attr="episodes"`` in a
    scheduler to count in episodes rather than reports.
    """
    if "spec" not in config:
        raise ValueError(
            "the config has no `spec`: pass hstl.tune.trainable_for(SPEC) to Tune, or put "
            "`spec` in the param space"
        )
    spec = config["spec"]
    spec = spec if isinstance(spec, Spec) else Spec.load(os.fspath(spec))
    world = _grid_world(spec, config.get("world"))
    seed = _seed_of(config.get("seed", 0))
    chunk = config.get("chunk", DEFAULT_CHUNK)
    if isinstance(chunk, (bool, float)) or not hasattr(chunk, "__index__") or int(chunk) < 1:
        raise ValueError(f"`chunk` must be a whole number of episodes >= 1; got {chunk!r}")
    optimum = config.get("optimum")
    learn = {k: v for k, v in config.items() if k not in _OWN_KEYS}
    report = _report_function()

    def on_chunk(episodes: int, reward: float, rate: Optional[float], robustness: Optional[float]) -> bool:
        metrics: Dict[str, Any] = {"episodes": episodes, "reward": reward}
        if rate is not None:
            metrics["window_rate"] = rate
            metrics["robustness"] = robustness
            if optimum:
                metrics["ratio"] = rate / optimum
        report(metrics)
        return False

    _hstl._train_chunks(spec, world, seed, int(chunk), on_chunk, learn)


def trainable_for(
    spec: Union[Spec, str, "os.PathLike[str]"],
    world: Union[World, str, "os.PathLike[str]", None] = None,
    *,
    seed: int = 0,
    chunk: int = DEFAULT_CHUNK,
    optimum: bool = True,
) -> Callable[[Mapping[str, Any]], None]:
    """``trainable`` with the spec, world, seed and chunk bound, for ``tune.Tuner``; the
    param space then holds only ``learn`` values (and may override ``seed`` or ``chunk``).

    The spec is checked against the world here (``hstl.SpecError`` before any trial
    starts), and with ``optimum`` W* is solved here once (value iteration, a few seconds),
    so that every trial reports ``ratio`` = W/W*.
    """
    spec = spec if isinstance(spec, Spec) else Spec.load(os.fspath(spec))
    world = _grid_world(spec, world)
    _hstl._study_task(spec, world, None)
    w_star = _hstl._study_optimum(spec, world) if optimum else None
    bound = {"spec": spec, "world": world, "seed": seed, "chunk": chunk, "optimum": w_star}

    def hstl_trainable(config: Mapping[str, Any]) -> None:
        trainable({**bound, **config})

    hstl_trainable.__doc__ = f"hstl.tune.trainable for `{spec.name}`"
    return hstl_trainable


def _grid_world(spec: Spec, world: Any) -> World:
    """The grid world ``spec`` is tuned in; a continuous world is refused in words."""
    resolved = world_of(spec, world)
    if not isinstance(resolved, World):
        raise TypeError(
            f"hstl.tune trains in grid worlds; `{spec.name}` is on world `{resolved.name}`, a continuous one\n"
            "  help: compare settings of a continuous spec with hstl.study over specs that differ in them"
        )
    return resolved


__all__ = ["DEFAULT_CHUNK", "LEARN_KEYS", "trainable", "trainable_for"]
