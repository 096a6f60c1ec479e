"""The options several commands share, declared once (``Annotated`` types Typer reads).

A command writes ``workers: Workers = None`` and gets the same flag, metavar, bounds and
help as every other command with worker processes.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from cartpole_q.cli.base import BackendChoice

MAX_SEED = 2**32 - 1
"""the largest seed (as :data:`cartpole_q.config.MAX_SEED`; the CLI imports no config)"""

ConfigFile = Annotated[
    Path | None,
    typer.Option(
        "--config",
        "-c",
        metavar="PATH|NAME",
        help="YAML config file, or a shipped config's name (see `cartpole-q configs`). "
        "Keys it leaves out take the embedded default's values.",
        show_default="the embedded default",
    ),
]
SetValues = Annotated[
    list[str] | None,
    typer.Option(
        "--set",
        metavar="KEY=VALUE",
        help="Set any config key by its dotted path, the value read as YAML, e.g. "
        "--set agent.alpha=5e-4 --set 'discretization.bins=[1, 1, 6, 12]'. Repeatable.",
    ),
]
Workers = Annotated[
    int | None,
    typer.Option(
        metavar="N",
        min=1,
        help="Worker processes (with --backend ray and no --address: a local cluster's CPUs).",
        show_default="one per core",
    ),
]
LocalWorkers = Annotated[
    int | None,
    typer.Option(metavar="N", min=1, help="Worker processes.", show_default="one per core"),
]
"""``--workers`` of a command that runs on local processes only (``compile``)"""
Backend = Annotated[
    BackendChoice,
    typer.Option(
        help="Run on local processes, or as Ray tasks (`pip install 'cartpole-q\\[ray]'`)."
    ),
]
Address = Annotated[
    str | None,
    typer.Option(
        metavar="ADDR",
        help="With --backend ray: a running cluster (`auto`, or HOST:PORT of its head).",
        show_default="start a local cluster",
    ),
]
Quiet = Annotated[
    bool,
    typer.Option(
        "--quiet",
        "-q",
        help="Print only the last line (what was written); notes and errors still go to stderr.",
    ),
]
Yes = Annotated[
    bool, typer.Option("--yes", "-y", help="Go ahead however large the job (no size guard).")
]
JsonOutput = Annotated[bool, typer.Option("--json", help="Print one JSON object.")]
Physics = Annotated[
    list[str] | None,
    typer.Option(
        "--physics",
        metavar="KEY=VALUE",
        help="Play under other physics, e.g. --physics length=0.75 (repeatable; keys of "
        "env.physics).",
    ),
]
MaxSteps = Annotated[
    int | None,
    typer.Option(metavar="N", min=1, help="Play with another time limit (env max_episode_steps)."),
]

StudyFigureOut = Annotated[
    Path | None,
    typer.Option(
        metavar="FILE",
        help="The figure (.png, .svg or .pdf); the numbers it draws go beside it as .csv.",
        show_default="the study's figure.file in the current directory",
    ),
]
"""``--out`` of a study command that draws one figure (``bandit``, ``updates``)"""

ReplaceFigure = Annotated[
    bool, typer.Option("--force", help="Replace the figure and its .csv if they exist.")
]
"""``--force`` of a study command that draws one figure"""
