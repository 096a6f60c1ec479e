"""``cartpole-q dp``: dynamic programming on a world's model, drawn as the book draws it."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from cartpole_q.cli.base import Command, app, exit_codes


@app.command("dp", cls=Command)
def dp_command(
    study_file: Annotated[
        Path,
        typer.Argument(
            metavar="STUDY.yaml",
            help="The study file: a world with a model, the algorithm (policy_evaluation, "
            "value_iteration, policy_iteration), gamma, the figure and the book's numbers.",
            show_default=False,
        ),
    ],
    out: Annotated[
        Path | None,
        typer.Option(
            metavar="FILE",
            help="The figure (.png, .svg or .pdf); the numbers it draws go beside it as .csv, "
            "every recorded sweep and policy as _sweeps.csv.",
            show_default="the study's figure.file in the current directory",
        ),
    ] = None,
    force: Annotated[
        bool, typer.Option("--force", help="Replace the figure and its .csv files if they exist.")
    ] = False,
) -> None:
    """Run policy evaluation, value iteration or policy iteration; draw the figure, print the book's numbers beside ours."""
    with exit_codes():
        from cartpole_q.experiments import planning

        study = planning.load_study(study_file)
        path = out or planning.default_out(study)
        planning.check_outputs(path, force)
        outcome = planning.run_study(study)
        typer.echo(planning.summary(study, outcome))
        rows = planning.book_rows(study, outcome)
        if rows:
            typer.echo("the book's numbers and ours (rounded as the book prints them):")
            for row in rows:
                typer.echo(f"  {row.text()}")
        figure, sweeps = planning.write_study(study, outcome, path)
        typer.echo(str(sweeps))
        typer.echo(str(figure))
