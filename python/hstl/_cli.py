"""The ``hstlc`` command that ``pip install`` puts on ``PATH`` (``[project.scripts]``).

It is the command line itself, not a copy: ``hstl._hstl.cli`` runs the Rust ``hstlc::run``
that the native ``hstlc`` binary runs, on this process's standard input, output and error,
so the output and the exit status are the binary's. Only the signals need setting here,
since Python changes two of them at startup: Ctrl-C (SIGINT) goes back to the default
action, ending the process at once as it ends the native binary (Python would only raise
``KeyboardInterrupt`` once the Rust code returned), unless the process started with it
ignored (``nohup``, a background job of a script), which the binary keeps too; and SIGPIPE
stays ignored, as Rust programs have it, so that a closed pipe is the write error the
command turns into status 141.
"""

from __future__ import annotations

import signal
import sys
from typing import Optional, Sequence


def main(argv: Optional[Sequence[str]] = None) -> int:
    """Runs ``hstlc`` with ``argv`` (default ``sys.argv``, the program's name first) and
    returns its exit status."""
    from ._hstl import cli

    # Python installs its handler only over the default action: anything else was inherited.
    if signal.getsignal(signal.SIGINT) is signal.default_int_handler:
        signal.signal(signal.SIGINT, signal.SIG_DFL)
    if hasattr(signal, "SIGPIPE"):
        signal.signal(signal.SIGPIPE, signal.SIG_IGN)
    args = list(sys.argv if argv is None else argv)
    if args:
        # The script's path, as the binary's own: clap names the program by its file name.
        args[0] = args[0] or "hstlc"
    else:
        args = ["hstlc"]
    return cli(args)


if __name__ == "__main__":
    sys.exit(main())
