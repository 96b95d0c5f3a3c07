"""What the gymnasium benchmarks (gym_bench.py, continuous_bench.py) time with: CPU time,
since the machine is shared and CPU time is what a loaded run can still measure."""

from __future__ import annotations

import resource
import time


def best(fn, repeats: int) -> float:
    """The fastest of `repeats` runs, in seconds of this process's CPU time."""
    times = []
    for _ in range(repeats):
        t0 = time.process_time()
        fn()
        times.append(time.process_time() - t0)
    return min(times)


def children_cpu() -> float:
    """CPU seconds of the finished child processes."""
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def stepper(env, actions, episode: int):
    """Steps `env` through `actions`, resetting every `episode` steps."""

    def run():
        env.reset(seed=0)
        for t, a in enumerate(actions, 1):
            env.step(a)
            if t % episode == 0:
                env.reset()

    return run
