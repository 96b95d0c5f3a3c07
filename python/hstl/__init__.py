"""hstl: exact Signal Temporal Logic monitors for hstl task specs on numpy arrays, grid
worlds for gymnasium, and the hierarchical learner.

>>> import hstl
>>> spec = hstl.Spec.parse('''
...     spec Reach {
...         state { x: float, y: float }
...         let Goal = x > 3 && y < 2;
...         task eventually[0..=5] Goal;
...     }''')
>>> spec.robustness({"x": [0, 2, 4], "y": [1, 1, 1]})
1.0

``hstl.formula("always[0..=10] x > 0.5")`` is a spec of one formula (its state variables
inferred as floats). ``Spec.load(path)`` reads a spec file; ``spec.signal(trace)`` gives the robustness at every
step as a numpy array, ``spec.signal_batch(traces)`` many traces' on every core, and
``spec.online()`` a monitor fed one state at a time. The values are those of
``hstlc monitor``, bit for bit. See ``help(hstl.Spec)``.

``hstl.train(spec, world="paper", seed=0)`` learns a ``hstl.Policy`` as ``hstlc train``
does (the same ``policy.json``, byte for byte); ``policy.evaluate()`` measures it as
``hstlc eval`` does. With gymnasium installed, ``hstl.GridWorldEnv`` is a grid world as a
``gymnasium.Env`` (``gymnasium.make("hstl/GridWorld-v0")``, ``"hstl/FourRooms-v0"``) and
``hstl.STLReward`` rewards any environment by robustness; ``import hstl`` does not import
gymnasium (the two classes load on first use, and the ids are registered once gymnasium is
imported).

``pip install`` also installs the ``hstlc`` command: the command line itself
(``hstl._hstl.cli``), with the native binary's output and exit status.

``hstl.check(path_or_text)`` lists a spec's diagnostics (warnings included; loading issues
the warnings as ``hstl.SpecWarning``), and ``hstl.explain(code)`` explains a code.

``hstl.study(specs, seeds=20)`` trains specs over many seeds and compares them as
``hstlc study`` does, on this machine's cores or on a Ray cluster (``backend="ray"``);
``hstl.tune.trainable`` tunes a spec's ``learn`` values with Ray Tune.
"""

from importlib.util import find_spec as _find_spec
from typing import TYPE_CHECKING as _TYPE_CHECKING
from typing import Any as _Any

from . import _registration
from ._errors import MissingVariableError, PolicyError, SpecError, SpecWarning, WorldError
from ._hstl import (
    EVAL_SEED,
    MAX_EPISODES,
    MAX_ONLINE_VALUES,
    ContinuousWorld,
    Diagnostic,
    OnlineMonitor,
    Policy,
    Spec,
    World,
    __version__,
    check,
    explain,
    formula,
)
from ._registration import MAX_EPISODE_STEPS
from ._study import StudyResult, study
from ._train import train

__all__ = [
    "EVAL_SEED",
    "MAX_EPISODES",
    "MAX_ONLINE_VALUES",
    "MAX_EPISODE_STEPS",
    "ContinuousWorld",
    "Diagnostic",
    "MissingVariableError",
    "OnlineMonitor",
    "Policy",
    "PolicyError",
    "Spec",
    "SpecError",
    "SpecWarning",
    "StudyResult",
    "World",
    "WorldError",
    "__version__",
    "check",
    "explain",
    "formula",
    "study",
    "train",
]

# gymnasium is optional and costs about 150 ms to import: the gymnasium classes load on
# first use (`__getattr__` below), and the ids are registered with gymnasium once it is
# imported (`_registration`).
_GYM = ("GridWorldEnv", "MountainCarEnv", "PlaneEnv", "STLReward", "STLVectorReward")

if _find_spec("gymnasium") is not None:
    __all__ += _GYM
    _registration.install()


if _TYPE_CHECKING:
    # Type checkers see the classes (and no `__getattr__`, which would make every unknown
    # name `Any`).
    from ._gym import GridWorldEnv as GridWorldEnv
    from ._gym import MountainCarEnv as MountainCarEnv
    from ._gym import PlaneEnv as PlaneEnv
    from ._gym import STLReward as STLReward
    from ._gym import STLVectorReward as STLVectorReward
else:

    def __getattr__(name: str) -> _Any:
        if name in _GYM:
            try:
                from . import _gym
            except ImportError as e:
                raise AttributeError(
                    f"hstl.{name} needs gymnasium, which cannot be imported ({e})\n"
                    '  help: install it with `pip install gymnasium` (or `pip install "./python[gymnasium]"`)'
                ) from e
            value = getattr(_gym, name)
            globals()[name] = value
            return value
        raise AttributeError(f"module 'hstl' has no attribute '{name}'")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_GYM))
