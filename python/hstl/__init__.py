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
``hstl.STLReward`` rewards any environment by robustness.

``hstl.check(path_or_text)`` lists a spec's diagnostics (warnings included; loading issues
the warnings as ``hstl.SpecWarning``), and ``hstl.explain(code)`` explains a code.

``hstl.study(specs, seeds=20)`` trains specs over many seeds and compares them as
``hstlc study`` does, on this machine's cores or on a Ray cluster (``backend="ray"``);
``hstl.tune.trainable`` tunes a spec's ``learn`` values with Ray Tune.
"""

from ._errors import MissingVariableError, PolicyError, SpecError, SpecWarning, WorldError
from ._hstl import EVAL_SEED, MAX_EPISODES, MAX_ONLINE_VALUES, Diagnostic, OnlineMonitor, Policy, Spec, World, __version__, check, explain, formula
from ._study import StudyResult, study
from ._train import train

__all__ = [
    "EVAL_SEED",
    "MAX_EPISODES",
    "MAX_ONLINE_VALUES",
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

try:
    import gymnasium as _gymnasium  # noqa: F401
except ImportError:  # gymnasium is optional: the monitors and training do not need it
    pass
else:
    from ._gym import MAX_EPISODE_STEPS, GridWorldEnv, STLReward, register as _register

    _register()
    __all__ += ["GridWorldEnv", "MAX_EPISODE_STEPS", "STLReward"]
