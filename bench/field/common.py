"""What the field's scripts share: the machine's description, spreads, CSV files and the
pictures (matplotlib, in bench/field/.venv only)."""

from __future__ import annotations

import csv
import os
import pathlib
import platform
import statistics
import time
from typing import Any, Iterable, Sequence

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parent.parent
OUT = HERE / "out"
SPECS = HERE / "specs"


def machine() -> str:
    """One line naming the machine and its load, for every table."""
    load = os.getloadavg()
    cpu = platform.processor() or platform.machine()
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return f"{os.cpu_count()} cores ({cpu}), load average {load[0]:.1f} {load[1]:.1f} {load[2]:.1f}, {time.strftime('%Y-%m-%d %H:%M')}"


def spread(values: Sequence[float]) -> tuple[float, float, float, float]:
    """Mean, sample sd (0 for one value), min and max."""
    m = statistics.fmean(values)
    sd = statistics.stdev(values) if len(values) > 1 else 0.0
    return m, sd, min(values), max(values)


def fmt_spread(values: Sequence[float], digits: int = 3) -> str:
    m, sd, lo, hi = spread(values)
    return f"{m:.{digits}f} ± {sd:.{digits}f} ({lo:.{digits}f}-{hi:.{digits}f}), n={len(values)}"


def write_csv(path: pathlib.Path, header: Sequence[str], rows: Iterable[Sequence[Any]]) -> None:
    """Writes a CSV whole: a temporary file, then renamed."""
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name("." + path.name + ".tmp")
    with open(tmp, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(header)
        w.writerows(rows)
    os.replace(tmp, path)


def read_csv(path: pathlib.Path) -> list[dict[str, str]]:
    with open(path) as f:
        return list(csv.DictReader(f))


def torch_one_thread() -> None:
    """SB3 on one thread, as the budget asks (2 cores shared)."""
    import torch

    torch.set_num_threads(1)
    if torch.get_num_interop_threads() != 1:
        try:
            torch.set_num_interop_threads(1)
        except RuntimeError:  # only before any parallel work; set once per process
            pass


def band_plot(path: pathlib.Path, series: dict[str, list[list[tuple[float, float]]]], xlabel: str, ylabel: str,
              title: str, logx: bool = False, ylim: tuple[float, float] | None = (0.0, 1.02)) -> None:
    """One line per method (the mean over seeds) and its min-max band. `series` maps a method
    to its seeds' curves, each a list of (x, y); the seeds' points are matched by index (each
    seed has the same budgets) and x is the mean over seeds at that index."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.ticker
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4.2))
    for name, curves in series.items():
        curves = [c for c in curves if c]
        if not curves:
            continue
        n = min(len(c) for c in curves)
        xs = [statistics.fmean(c[i][0] for c in curves) for i in range(n)]
        ys = [[c[i][1] for c in curves] for i in range(n)]
        mean = [statistics.fmean(y) for y in ys]
        published = "TGPO" in name
        label = name if published else f"{name} (n={len(curves)})"
        (line,) = ax.plot(xs, mean, marker="o", ms=3, label=label, linestyle="--" if published else "-")
        ax.fill_between(xs, [min(y) for y in ys], [max(y) for y in ys], color=line.get_color(), alpha=0.2)
    if logx:
        ax.set_xscale("log")
        ax.xaxis.set_major_formatter(matplotlib.ticker.FuncFormatter(lambda v, _: f"{v:g}"))
    if ylim:
        ax.set_ylim(*ylim)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title, fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="best")
    fig.text(0.01, 0.01, "line: mean over seeds; band: min-max over seeds", fontsize=7, color="#555")
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path)
    plt.close(fig)
