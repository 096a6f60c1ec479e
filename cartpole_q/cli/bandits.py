"""``cartpole-q bandit``: ``study`` for the k-armed testbed's studies (an alias for one release)."""

from __future__ import annotations

from typing import Annotated

import typer

from cartpole_q.cli.base import BackendChoice, Command, app
from cartpole_q.cli.options import Address, Backend, Quiet, Workers, Yes
from cartpole_q.cli.studies import (
    Check,
    MaxRuns,
    Resume,
    StudyFileArgument,
    StudyOut,
    StudyRequest,
    run_study_command,
)


@app.command("bandit", cls=Command)
def bandit_command(
    study_file: StudyFileArgument = None,
    resume: Resume = None,
    out: StudyOut = None,
    engine: Annotated[
        str | None,
        typer.Option(
            metavar="ENGINE",
            help="numba (the compiled testbed) or gymnasium (gymnasium.make, slower): the same "
            "numbers either way (overrides the study file's `engine`).",
            show_default="the study file's engine, else numba",
        ),
    ] = None,
    workers: Workers = None,
    backend: Backend = BackendChoice.local,
    address: Address = None,
    max_runs: MaxRuns = 20_000,
    yes: Yes = False,
    quiet: Quiet = False,
    check: Check = False,
) -> None:
    """`study` for bandit studies (the k-armed testbed, chapter 2); the last line is its directory."""
    overrides: dict[str, object] | None = None if engine is None else {"engine": engine}
    request = StudyRequest(
        study_file, resume, out, workers, backend, address, max_runs, yes, quiet, check
    )
    run_study_command("bandit", "bandit", request, overrides)
