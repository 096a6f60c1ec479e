"""The ``cartpole-q`` command line: every command registered on one Typer app.

Each command (``cli/train.py``, ``cli/runs.py``, ``cli/studies.py``, ``cli/planning.py``, ``cli/bandits.py``,
``cli/updates.py``)
parses its options, calls one library function and prints what it returns; what they share
(exit codes, the stop routine, the options declared once) is in ``cli/base.py`` and
``cli/options.py``.
"""

from __future__ import annotations

from cartpole_q.cli import bandits, planning, runs, studies, train, updates
from cartpole_q.cli.base import app

__all__ = ["app", "main"]

COMMAND_MODULES = (train, runs, studies, planning, bandits, updates)
"""the modules whose commands are registered on :data:`app` (imported for that)"""


def main() -> None:
    """Entry point of the ``cartpole-q`` console script."""
    app()
