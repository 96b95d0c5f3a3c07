"""hstl: exact Signal Temporal Logic monitors for hstl task specs, on numpy arrays.

>>> import hstl
>>> spec = hstl.Spec.parse('''
...     spec Reach {
...         state { x: float, y: float }
...         let Goal = x > 3 && y < 2;
...         task eventually[0..=5] Goal;
...     }''')
>>> spec.robustness({"x": [0, 2, 4], "y": [1, 1, 1]})
1.0

``Spec.load(path)`` reads a spec file; ``spec.signal(trace)`` gives the robustness at every
step as a numpy array, ``spec.signal_batch(traces)`` many traces' on every core, and
``spec.online()`` a monitor fed one state at a time. The values are those of
``hstlc monitor``, bit for bit. See ``help(hstl.Spec)``.
"""

from ._errors import MissingVariableError, SpecError
from ._hstl import Diagnostic, OnlineMonitor, Spec, __version__

__all__ = [
    "Diagnostic",
    "MissingVariableError",
    "OnlineMonitor",
    "Spec",
    "SpecError",
    "__version__",
]
