"""``hstl.study``: specs trained over many seeds and compared, on this machine or on Ray.

Every figure is the facade's (``hstl::study`` in Rust, what ``hstlc study`` prints), so the
numbers are the same, bit for bit, whatever the backend: a seed trains in one Rust call
wherever it runs, and only plain numbers come back.
"""

from __future__ import annotations

import math
import os
import logging
from typing import Any, Callable, Dict, Iterable, List, Mapping, Optional, Sequence, Tuple, Union

from . import _hstl
from ._hstl import ContinuousWorld, Spec, World
from ._train import _count_of, _seed_of, world_of

#: What a Ray task costs beside its training, as a share of one seed's training. Measured
#: (BENCHMARKS.md, "Sweeps on Ray"): on a local cluster an empty task takes about 1 ms and
#: a task that unpickles the spec and world and checks the spec about 2.4 ms of the
#: cluster's time (about 5 ms of a core), against 0.15-0.4 s to train a seed of the case
#: study: about 1-2%. Across machines each task also pays the network, so this takes 2%.
_TASK_COST = 0.02
#: Seeds per Ray task at most.
_MAX_BATCH = 16


class StudyResult(List[Dict[str, Any]]):
    """The list ``hstl.study`` returns: one dict per (spec, seed), specs in the order given
    and seeds in the order asked, with ``summary``, one dict per spec (in the same order)
    with ``spec``, ``file``, ``optimum`` and the figures ``hstlc study`` prints over the
    seeds, each a dict of ``mean``, ``sd`` (sample), ``min`` and ``max``: ``seconds``,
    ``reward``, and where every seed has them ``window_rate`` and ``ratio`` (W/W*)."""

    summary: List[Dict[str, Any]]

    def __init__(self, rows: Iterable[Dict[str, Any]] = (), summary: Optional[List[Dict[str, Any]]] = None) -> None:
        super().__init__(rows)
        self.summary = list(summary or [])

    def __reduce__(self) -> Tuple[Any, ...]:
        return (StudyResult, (list(self), self.summary))


def study(
    specs: Union[Spec, str, "os.PathLike[str]", Sequence[Union[Spec, str, "os.PathLike[str]"]]],
    seeds: Union[int, Iterable[int]] = 20,
    world: Union[World, ContinuousWorld, str, "os.PathLike[str]", None] = None,
    backend: str = "local",
    address: Optional[str] = None,
    out: Optional[Union[str, "os.PathLike[str]"]] = None,
    *,
    episodes: Optional[int] = None,
    optimum: bool = True,
    num_cpus: Optional[int] = None,
    batch: Optional[int] = None,
    max_retries: int = 3,
    force: bool = False,
) -> StudyResult:
    """Trains each spec for each seed and returns one dict per (spec, seed).

    Each dict holds ``spec`` (the spec's name), ``file`` (its path, or None for a spec
    parsed from text), ``seed``, ``window_rate`` (W of the greedy policy, for a persistent
    task; else None), ``optimum`` (W*, or None), ``ratio`` (W/W*, or None), ``reward``
    (per episode, the mean of the last 100 episodes), ``seconds`` (training time),
    ``steps`` (primitive steps) and ``curve`` (reward per episode). ``ratio`` is None when
    W* = 0 (no policy keeps the task: W/W* is undefined), and the summary then has no
    ``ratio`` either. The numbers are those
    of ``hstlc study``, bit for bit, whatever the backend (training time excepted); the
    list's ``summary`` holds each spec's mean, sd, min and max (see ``StudyResult``). The
    policy of seed ``s`` (``hstl.train(spec, seed=s)``, the same bit for bit) is measured
    on the runs of evaluation seed ``s ^ hstl.EVAL_SEED``, so
    ``policy.evaluate(seed=s ^ hstl.EVAL_SEED)["window_rate"]`` is its ``window_rate``
    (``policy.evaluate()`` alone uses seed 0, other runs).

    ``specs``: spec files' paths or ``hstl.Spec`` objects (one or a list); each is checked
    against ``world`` first (``hstl.SpecError`` with the diagnostics of ``hstlc check
    --world``), before anything trains. ``seeds``: a count (seeds 0, 1, ... N-1, as
    ``hstlc study --seeds N``) or the seeds themselves. ``world``: a ``hstl.World``, a
    ``hstl.ContinuousWorld``, a built-in name or a world file; by default the world the
    specs name (``paper`` when they name none, ``paper-plane`` for specs over ``float``
    variables; specs that name different worlds are studied apart). In a continuous world
    (a plane, ``mountain-car``) each seed trains with the approximate learner, as
    ``hstlc study`` trains it: ``window_rate`` is W for a persistent task, a row's
    ``satisfaction`` the satisfaction rate P of another, and ``optimum`` is None (no exact
    optimum exists; ``hstlc study`` prints a planned reference beside W). ``episodes`` overrides each spec's ``learn {
    episodes }``; ``optimum=False`` skips W* (value iteration, a few seconds per set of
    regions).

    ``backend="local"`` trains on this machine's cores (``num_cpus`` threads, default
    all), the GIL released. ``backend="ray"`` sends the seeds to Ray as tasks of one or a
    few seeds each (``batch``; by default chosen from the seeds and the cluster's CPUs so
    that neither the cost of a task, about 1-2% of a seed's training, nor the cores idle
    at the end of the sweep add much: one seed a task for 100 seeds on 2 CPUs, see
    ``_batch_size``). It joins the cluster at ``address`` (``"auto"`` for one started with
    ``ray start``), or, without one, starts a local cluster of ``num_cpus`` CPUs and shuts
    it down when done; a Ray already initialised in this process is used as it is. Specs and worlds travel pickled; a task
    whose worker dies is retried up to ``max_retries`` times; an error in a task (a spec
    the worker cannot train) is raised here as the exception it was.

    ``out``: a folder to write as ``hstlc study --out`` does (each spec's folder with the
    median seed's policy and pictures, ``seeds.csv`` and ``curve.svg``; ``curves.svg`` and
    ``curves.csv`` beside them). The folders are taken before training starts (one another
    run holds is refused at once) and written only when every result is in, each whole or
    not at all. A file at the folder's top that no study wrote (a ``summary.csv`` of your
    own), or another run's folder in it that this study would leave undescribed, is refused
    then too (a ``ValueError``), unless ``force=True``, which replaces the file and removes
    the folder, as ``hstlc study --force``.
    """
    return _study(
        specs,
        seeds,
        world,
        backend,
        address,
        out,
        episodes=episodes,
        optimum=optimum,
        num_cpus=num_cpus,
        batch=batch,
        max_retries=max_retries,
        force=force,
    )


def _study(
    specs: Any,
    seeds: Any,
    world: Any,
    backend: str,
    address: Optional[str],
    out: Any,
    *,
    episodes: Optional[int],
    optimum: bool,
    num_cpus: Optional[int],
    batch: Optional[int],
    max_retries: int,
    force: bool = False,
    before_batch: Optional[Callable[[List[int]], None]] = None,
) -> StudyResult:
    """``study``, with ``before_batch(seeds)`` called in each Ray task before it trains (the
    test suite's way to kill a worker)."""
    if backend not in ("local", "ray"):
        raise ValueError(f'`backend` must be "local" or "ray"; got {backend!r}')
    if backend == "local" and address is not None:
        raise ValueError('`address` joins a Ray cluster: pass it with backend="ray"')
    spec_list = _specs_of(specs)
    seed_list = _seeds_of(seeds)
    if episodes is not None:
        episodes = _count_of(episodes, "episodes")
    if num_cpus is not None:
        num_cpus = _whole(num_cpus, "num_cpus", 1, 4096)
    if batch is not None:
        batch = _whole(batch, "batch", 1, 100_000)
    max_retries = _whole(max_retries, "max_retries", 0, 1000)
    world = _one_world(spec_list, world)
    if out is not None and isinstance(world, ContinuousWorld):
        raise ValueError(
            f"`out=` writes a study's folder in a grid world; world `{world.name}` is continuous\n"
            "  help: run `hstlc study SPEC... --out DIR` for a continuous world's folder"
        )
    # Every spec checked against the world here, before anything trains or is sent away.
    tasks = [_hstl._study_task(spec, world, episodes) for spec in spec_list]
    paths = [_path_of(spec) for spec in spec_list]
    folder = _hstl._StudyOut(os.fspath(out), paths, bool(force)) if out is not None else None
    # One W* per distinct set of regions, as hstlc study solves it.
    wanted = {}
    if optimum:
        for spec, (_, _, regions) in zip(spec_list, tasks):
            if regions is not None and regions not in wanted:
                wanted[regions] = spec
    if backend == "local":
        threads = num_cpus or os.cpu_count() or 1
        runs = [_hstl._study_seeds(s, world, seed_list, episodes, threads) for s in spec_list]
        optima = {key: _hstl._study_optimum(spec, world) for key, spec in wanted.items()}
    else:
        runs, optima = _on_ray(
            spec_list,
            world,
            seed_list,
            episodes,
            wanted,
            address=address,
            num_cpus=num_cpus,
            batch=batch,
            max_retries=max_retries,
            before_batch=before_batch,
        )
    rows, summary, w_stars = [], [], []
    for spec, (name, _, regions), spec_runs in zip(spec_list, tasks, runs):
        w_star = optima.get(regions) if regions is not None else None
        w_stars.append(w_star)
        file = _file_of(spec)
        for run in spec_runs:
            w = run["window_rate"]
            rows.append(
                {
                    "spec": name,
                    "file": file,
                    "seed": run["seed"],
                    "window_rate": w,
                    "optimum": w_star,
                    "ratio": _ratio(w, w_star),
                    "reward": run["reward"],
                    "seconds": run["seconds"],
                    "steps": run["steps"],
                    "curve": run["curve"],
                }
            )
            if isinstance(world, ContinuousWorld):
                rows[-1]["satisfaction"] = run["satisfaction"]
        figures = _hstl._study_summary(spec_runs, w_star)
        summary.append({"spec": name, "file": file, "optimum": w_star, **figures})
    if folder is not None:
        folder.write(spec_list, world, runs, episodes, w_stars)
    return StudyResult(rows, summary)


#: W* at or below this is 0: no policy keeps the task (the facade's ``MIN_OPTIMUM``).
_MIN_OPTIMUM = 1e-9


def _ratio(w: Optional[float], w_star: Optional[float]) -> Optional[float]:
    """W/W*, or None when either is unknown or W* = 0 (no policy keeps the task: the
    ratio is undefined, as ``hstlc study`` says)."""
    if w is None or w_star is None or not w_star > _MIN_OPTIMUM:
        return None
    return w / w_star


def _whole(n: Any, name: str, lo: int, hi: int) -> int:
    if isinstance(n, (bool, float)) or not hasattr(n, "__index__"):
        raise TypeError(f"`{name}` must be an integer; got {type(n).__name__}")
    if not lo <= int(n) <= hi:
        raise ValueError(f"`{name}` must be in {lo}..={hi}; got {int(n)}")
    return int(n)


def _specs_of(specs: Any) -> List[Spec]:
    if isinstance(specs, (Spec, str, os.PathLike)):
        specs = [specs]
    try:
        items = list(specs)
    except TypeError:
        raise TypeError(
            f"`specs` must be a spec, a path or a list of them; got {type(specs).__name__}"
        ) from None
    if not items:
        raise ValueError("`specs` is empty: pass at least one spec or spec file")
    return [s if isinstance(s, Spec) else Spec.load(os.fspath(s)) for s in items]


def _seeds_of(seeds: Any) -> List[int]:
    if isinstance(seeds, (bool, float)):
        raise TypeError(f"`seeds` must be a count or a list of seeds; got {seeds!r}")
    if hasattr(seeds, "__index__"):
        n = int(seeds)
        if not 1 <= n <= 100_000:
            raise ValueError(f"`seeds` must be in 1..=100000, as `hstlc study --seeds`; got {n}")
        return list(range(n))
    try:
        items = [_seed_of(s) for s in seeds]
    except TypeError as e:
        if "seed" in str(e):
            raise
        raise TypeError(
            f"`seeds` must be a count or a list of seeds; got {type(seeds).__name__}"
        ) from None
    if not items:
        raise ValueError("`seeds` is empty: pass a count or at least one seed")
    if len(items) > 100_000:
        raise ValueError(f"`seeds` holds {len(items)} seeds; at most 100000")
    return items


def _file_of(spec: Spec) -> Optional[str]:
    """The spec's path, or None for a spec parsed from text (whose file name is not a
    file)."""
    name = spec.filename
    return name if os.path.isfile(name) else None


def _path_of(spec: Spec) -> str:
    """What names the spec's folder and its curves: its path, as ``hstlc study`` is given
    it, or ``NAME.hstl`` for a spec parsed from text."""
    return _file_of(spec) or f"{spec.name}.hstl"


def _batch_size(seeds: int, cpus: int) -> int:
    """Seeds per Ray task: the batch ``b`` that makes the least of what tasks cost
    (``_TASK_COST / b`` of the sweep) and of the cores left idle at its end (on average
    half a batch per core: ``b * cpus / (2 * seeds)`` of the sweep), which is
    ``sqrt(2 * _TASK_COST * seeds / cpus)``: one seed a task for 100 seeds on 2 cores,
    4 for 1,000, 10 for 10,000 on 4 cores; at most ``_MAX_BATCH``."""
    best = math.sqrt(2 * _TASK_COST * seeds / max(1, cpus))
    return max(1, min(_MAX_BATCH, round(best)))


def _train_batch(
    spec: Spec,
    world: Union[World, ContinuousWorld],
    seeds: List[int],
    episodes: Optional[int],
    before_batch: Optional[Callable[[List[int]], None]],
) -> List[Dict[str, Any]]:
    """One Ray task: a batch of seeds of one spec, on one thread (Ray runs a task per CPU)."""
    if before_batch is not None:
        before_batch(seeds)
    return _hstl._study_seeds(spec, world, seeds, episodes, 1)


def _optimum_task(spec: Spec, world: Union[World, ContinuousWorld]) -> Optional[float]:
    return _hstl._study_optimum(spec, world)


def _on_ray(
    specs: List[Spec],
    world: Union[World, ContinuousWorld],
    seeds: List[int],
    episodes: Optional[int],
    wanted: Mapping[str, Spec],
    *,
    address: Optional[str],
    num_cpus: Optional[int],
    batch: Optional[int],
    max_retries: int,
    before_batch: Optional[Callable[[List[int]], None]],
) -> Tuple[List[List[Dict[str, Any]]], Dict[str, Optional[float]]]:
    try:
        import ray
    except ImportError:
        raise ImportError(
            'backend="ray" needs Ray: pip install "ray[tune]" (see README, "Sweeps on a cluster")'
        ) from None
    started = False
    if not ray.is_initialized():
        if address is None:
            # A cluster of this machine alone: its processes talk over the loopback.
            ray.init(
                num_cpus=num_cpus,
                include_dashboard=False,
                logging_level=logging.WARNING,
                _node_ip_address="127.0.0.1",
            )
        else:
            ray.init(address=address, logging_level=logging.WARNING)
        started = True
    try:
        cpus = int(ray.cluster_resources().get("CPU", 1))
        size = batch or _batch_size(len(seeds), cpus)
        train = ray.remote(num_cpus=1, max_retries=max_retries)(_train_batch)
        solve = ray.remote(num_cpus=1, max_retries=max_retries)(_optimum_task)
        world_ref = ray.put(world)
        # W* first: value iteration is the longest single task.
        optimum_refs = {key: solve.remote(spec, world_ref) for key, spec in wanted.items()}
        refs = []
        for spec in specs:
            spec_ref = ray.put(spec)
            refs.append(
                [
                    train.remote(spec_ref, world_ref, seeds[i : i + size], episodes, before_batch)
                    for i in range(0, len(seeds), size)
                ]
            )
        try:
            runs = [[run for part in ray.get(parts) for run in part] for parts in refs]
            optima = {key: ray.get(ref) for key, ref in optimum_refs.items()}
        except ray.exceptions.RayTaskError as e:
            # The task's own exception (hstl.SpecError, ValueError, ...), not Ray's wrapper.
            cause = getattr(e, "cause", None)
            if isinstance(cause, BaseException):
                raise cause from None
            raise
        return runs, optima
    finally:
        if started:
            ray.shutdown()


def _one_world(spec_list: List[Spec], world: Any) -> Union[World, ContinuousWorld]:
    """The world a study trains in: ``world`` when given, else the one every spec names (or
    ``paper`` when none names one); specs that name different worlds are studied apart."""
    if world is not None:
        return world_of(spec_list[0], world)
    worlds = [world_of(spec, None) for spec in spec_list]
    first = worlds[0]
    if any(w != first for w in worlds[1:]):
        names = sorted({w.name for w in worlds})
        raise ValueError(
            f"the specs name different worlds ({', '.join(names)}): study each world's specs "
            "apart, or train them all in one with world="
        )
    return first
