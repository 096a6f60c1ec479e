"""``cartpole-q updates``: ``study`` for chapter 8's planning studies (an alias for one release)."""

from __future__ import annotations

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


@app.command("updates", cls=Command)
def updates_command(
    study_file: StudyFileArgument = None,
    resume: Resume = None,
    out: StudyOut = None,
    workers: Workers = None,
    backend: Backend = BackendChoice.local,
    address: Address = None,
    max_runs: MaxRuns = 20_000,
    yes: Yes = False,
    quiet: Quiet = False,
    check: Check = False,
) -> None:
    """`study` for planning-update studies (chapter 8: figure kinds expected_vs_sample, trajectory_sampling, until_optimal); the last line is its directory."""
    request = StudyRequest(
        study_file, resume, out, workers, backend, address, max_runs, yes, quiet, check
    )
    run_study_command("updates", "updates", request)
