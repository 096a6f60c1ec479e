"""``cartpole-q bandit``: the k-armed testbed of chapter 2, a figure per study file."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from cartpole_q.cli.base import Command, app, exit_codes, exit_interrupted
from cartpole_q.cli.options import ReplaceFigure, StudyFigureOut


@app.command("bandit", cls=Command)
def bandit_command(
    study_file: Annotated[
        Path,
        typer.Argument(
            metavar="STUDY.yaml",
            help="The study file: the testbed, the seeds (one run each) and steps, the curves "
            "(method: epsilon_greedy, ucb, gradient, and their parameters), the figure and the "
            "book's numbers.",
            show_default=False,
        ),
    ],
    out: StudyFigureOut = None,
    force: ReplaceFigure = False,
    engine: Annotated[
        str,
        typer.Option(
            metavar="ENGINE",
            help="numba (the compiled testbed) or gymnasium (gymnasium.make, slower); the "
            "same numbers either way.",
        ),
    ] = "numba",
) -> None:
    """Play the k-armed testbed; draw the figure, print the book's numbers beside ours."""
    with exit_codes():
        from cartpole_q.config import ConfigError
        from cartpole_q.engines.bandit import compile_notice
        from cartpole_q.experiments import bandits
        from cartpole_q.experiments.run import StopRequest

        if engine not in bandits.ENGINES:
            raise ConfigError(
                f"--engine: must be one of {', '.join(bandits.ENGINES)}, got {engine!r}."
            )
        study = bandits.load_study(study_file)
        path = out or bandits.default_out(study)
        bandits.check_outputs(path, force)
        notice = compile_notice(engine)
        if notice is not None:
            typer.echo(notice, err=True)

        def announce(message: str) -> None:
            signal = message.partition(":")[0]
            typer.echo(f"{signal}: stopping after the current run (send it again to stop at once)",
                       err=True)  # fmt: skip

        with StopRequest(announce) as stop:
            outcome = bandits.run_study(study, engine, stop.is_set)
        if outcome is None:
            exit_interrupted("interrupted: nothing was written; run it again to draw the figure")
        for line in bandits.summary(study, outcome):
            typer.echo(line)
        rows = bandits.book_rows(study, outcome)
        if rows:
            typer.echo("the book's numbers (read off its figure) and ours:")
            for row in rows:
                typer.echo(f"  {row.text()}")
        typer.echo(str(bandits.write_study(study, outcome, path)))
