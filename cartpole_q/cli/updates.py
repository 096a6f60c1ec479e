"""``cartpole-q updates``: chapter 8's planning studies (Figures 8.7 and 8.8), one study file each."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from cartpole_q.cli.base import Command, app, exit_codes, exit_interrupted
from cartpole_q.cli.options import ReplaceFigure, StudyFigureOut


@app.command("updates", cls=Command)
def updates_command(
    study_file: Annotated[
        Path,
        typer.Argument(
            metavar="STUDY.yaml",
            help="The study file: the figure kind (expected_vs_sample: Figure 8.7; "
            "trajectory_sampling: Figure 8.8), the seeds (one problem or task each) and the "
            "kind's settings.",
            show_default=False,
        ),
    ],
    out: StudyFigureOut = None,
    force: ReplaceFigure = False,
) -> None:
    """Expected vs sample updates, or uniform vs on-policy updates; draw the figure, print its numbers."""
    with exit_codes():
        from cartpole_q.experiments import updates
        from cartpole_q.experiments.run import StopRequest

        study = updates.load_study(study_file)
        path = out or updates.default_out(study)
        updates.check_outputs(path, force)
        if study.kind == "trajectory_sampling":
            from cartpole_q.engines.trajectory import compile_notice

            notice = compile_notice()
            if notice is not None:
                typer.echo(notice, err=True)

        def announce(message: str) -> None:
            signal = message.partition(":")[0]
            typer.echo(f"{signal}: stopping after the current task (send it again to stop at once)",
                       err=True)  # fmt: skip

        with StopRequest(announce) as stop:
            outcome = updates.run_study(study, stop.is_set)
        if outcome is None:
            exit_interrupted("interrupted: nothing was written; run it again to draw the figure")
        for line in updates.summary(study, outcome):
            typer.echo(line)
        typer.echo(str(updates.write_study(study, outcome, path)))
