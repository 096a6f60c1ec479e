"""The ``cartpole-q`` command line: every command registered on one Typer app.

Each command (``cli/train.py``, ``cli/runs.py``, ``cli/studies.py``; the study aliases in
``cli/bandits.py``, ``cli/planning.py`` and ``cli/updates.py``) parses its options, calls
one library function and prints what it returns; what they share (exit codes, the stop
routine, the options declared once) is in ``cli/base.py`` and ``cli/options.py``.
"""

from __future__ import annotations

import importlib

from cartpole_q.cli.base import app

__all__ = ["app", "main"]

COMMAND_MODULES = tuple(
    importlib.import_module(f"cartpole_q.cli.{name}")
    for name in ("train", "runs", "studies", "schema", "bandits", "planning", "updates")
)
"""the modules whose commands are registered on :data:`app`, in the order ``--help`` lists
them: training and its runs first, then the studies, then the studies' older aliases"""


def main() -> None:
    """Entry point of the ``cartpole-q`` console script.

    ``kill -USR1 PID`` makes a running command print every thread's Python stack to stderr
    (Python's ``faulthandler``) and go on: where a command that seems stuck is.
    """
    import faulthandler
    import signal

    if hasattr(signal, "SIGUSR1"):
        faulthandler.register(signal.SIGUSR1, all_threads=True)
    app()
