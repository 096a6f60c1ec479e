"""``cartpole-q schema``: the JSON Schema of config, study or tune files, for editors."""

from __future__ import annotations

from enum import StrEnum
from pathlib import Path
from typing import Annotated

import typer

from cartpole_q.cli.base import Command, app, exit_codes


class SchemaChoice(StrEnum):
    """The files ``cartpole-q schema`` describes."""

    config = "config"
    study = "study"
    tune = "tune"


@app.command("schema", cls=Command)
def schema_command(
    files: Annotated[
        SchemaChoice,
        typer.Argument(
            metavar="config|study|tune",
            help="Which files: configs (`train -c`), study files (`study`; tune files too, "
            "told apart by their keys), or tune files alone.",
        ),
    ] = SchemaChoice.config,
    out: Annotated[
        Path | None,
        typer.Option(
            "--out",
            metavar="FILE",
            help="Write the schema to FILE (replaced whole, never half written) and print its "
            "path.",
            show_default="print it",
        ),
    ] = None,
) -> None:
    """Print the JSON Schema (draft 2020-12) of config, study or tune files, for editors and validators."""
    with exit_codes():
        import json

        from cartpole_q import __version__
        from cartpole_q.experiments.schemas import schema_named
        from cartpole_q.store.atomic import atomic_write_text

        # Which version wrote it: the schema follows the package's keys, release by release.
        made = {"$comment": f"written by `cartpole-q schema {files}`, cartpole-q {__version__}"}
        schema = {**made, **schema_named(files.value)}
        text = json.dumps(schema, indent=2, ensure_ascii=False) + "\n"
        if out is None:
            typer.echo(text, nl=False)
            return
        atomic_write_text(out, text)
        typer.echo(str(out))
