"""Commands that run many configs: ``sweep`` and ``tune``."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Any

import typer

from cartpole_q.cli.base import (
    BackendChoice,
    Command,
    app,
    backend_connection,
    exit_codes,
    exit_if_stopped,
    kept_on_write_error,
    say_if_compiling,
    stoppable,
)
from cartpole_q.cli.options import Address, Backend, Quiet, Workers, Yes
from cartpole_q.errors import UserError

STUDY_FILE_HELP = (
    "The study file; its `kind` says what it is: sweep (a grid of configs on many seeds, "
    "the default), bandit (the k-armed testbed), dp (dynamic programming on a model), "
    "updates (chapter 8's planning studies)."
)
StudyFileArgument = Annotated[
    Path | None,
    typer.Argument(metavar="STUDY.yaml", help=STUDY_FILE_HELP, show_default=False),
]
Resume = Annotated[
    Path | None,
    typer.Option(metavar="DIR", help="Finish an interrupted study directory (a sweep's too)."),
]
StudyOut = Annotated[
    Path | None,
    typer.Option(
        metavar="DIR",
        help="Study directory to create; it must not exist or be empty.",
        show_default="sweeps/<name>-<YYYYmmdd-HHMMSS> (a sweep), else studies/<name>-<...>",
    ),
]
MaxRuns = Annotated[
    int,
    typer.Option(
        metavar="N",
        min=1,
        help="Refuse studies of more runs (a sweep: points x seeds) than this, unless --yes.",
    ),
]
Check = Annotated[
    bool,
    typer.Option(
        "--check",
        help="Read and check the study file, say what it would run, run nothing (exit 0 or 2).",
    ),
]


STOP_POINT = "the runs in flight, saving what has finished"
"""what a study does on a first signal"""


ALIAS_KINDS: dict[str, str | None] = {
    "study": None,
    "sweep": None,
    "dp": "dp",
    "updates": "updates",
}
"""each name :func:`study_command` answers to, and the kind it runs (``None``: any): ``sweep``
is ``study``'s first name; ``dp`` and ``updates`` are aliases for one release (``bandit``,
with its ``--engine``, is a command of its own)"""


@app.command(
    "sweep",
    cls=Command,
    help="Train and evaluate every point of a sweep on every seed (`study` under its first "
    "name); the last line is its directory.",
)
@app.command("study", cls=Command)  # registered first: listed first
def study_command(
    ctx: typer.Context,
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
    """Run any study file (a sweep, bandits, dynamic programming, planning updates); the last line is its directory."""
    # One function under several names: the name it was called by says which kind it runs.
    command = ctx.info_name or "study"
    request = StudyRequest(
        study_file, resume, out, workers, backend, address, max_runs, yes, quiet, check
    )
    run_study_command(command, ALIAS_KINDS[command], request)


@dataclass(frozen=True)
class StudyRequest:
    """What ``study`` (or an alias) was asked: the options every study command has."""

    study_file: Path | None
    """the study file (``None`` with ``resume``)"""
    resume: Path | None
    """the directory to finish"""
    out: Path | None
    """the new directory"""
    workers: int | None
    """worker processes (``None``: one per core)"""
    backend: BackendChoice
    """local processes or Ray"""
    address: str | None
    """a running Ray cluster"""
    max_runs: int
    """the size guard (more runs need ``yes``)"""
    yes: bool
    """go ahead however large"""
    quiet: bool
    """print only the directory"""
    check: bool
    """read and check, run nothing"""


def run_study_command(
    command: str,
    required: str | None,
    request: StudyRequest,
    overrides: dict[str, object] | None = None,
) -> None:
    """``study`` and its aliases: read (or take up) a study, run it, print, exit.

    Args:
        command: the command's name, for messages (``cartpole-q sweep --resume ...``).
        required: the kind an alias runs (``bandit``), or ``None``: any.
        request: the command's options.
        overrides: study file keys an alias's options set (``bandit --engine``).
    """
    study_file, resume, out, check = request.study_file, request.resume, request.out, request.check
    workers, backend, address = request.workers, request.backend, request.address
    quiet = request.quiet
    # Connected (or refused) before the study directory is created.
    with exit_codes(), backend_connection(backend, workers, address):
        from cartpole_q.experiments import study as studies
        from cartpole_q.experiments.study_kinds import registered
        from cartpole_q.store.lock import directory_lock

        kinds = registered()
        started: list[Path] = []
        hint = _resume_hint(command, "finish", lambda: started[0] if started else None)
        if resume is not None:
            if study_file is not None or out is not None or check or overrides:
                raise UserError(
                    "--resume finishes a study exactly as it was started, so it takes neither "
                    "a study file, --out, --check nor options that change the study."
                )
            kind = studies.kind_of_directory(resume)
            _check_kind(kind.name, required, str(resume), command)
            started.append(resume)
            what = "sweep" if kind.name == "sweep" else "study"
            with directory_lock(resume, what), stoppable(hint, STOP_POINT) as stop:
                spec = kind.load(resume)
                outcome = kind.run(spec, resume, _options(workers, backend, address, quiet, stop))
        else:
            if study_file is None:
                raise UserError("give a study file, or --resume DIR to finish a study.")
            label = "sweep file" if command == "sweep" else "study file"
            study = studies.read_study_file(study_file, default=required, label=label)
            if overrides:
                study = studies.study_of({**study.raw, **overrides}, study.where, study.stem,
                                         study.base_dir, study.kind)  # fmt: skip
            _check_kind(study.kind, required, str(study_file), command)
            kind = kinds[study.kind]
            spec = kind.read(study)
            runs, what = kind.describe(spec)
            if check:
                typer.echo(f"{study_file}: {what}; nothing was run (--check).")
                return
            _check_size(runs, request.max_runs, request.yes, str(study_file), what)
            # A signal from the moment the directory exists is a request to stop that the
            # study answers (saying what it saved), however early it comes.
            with stoppable(hint, STOP_POINT) as stop, kind.start(spec, study, out) as directory:
                started.append(directory)
                typer.echo(f"{study_file}: {what}", err=True)  # a note: also when quiet
                outcome = kind.run(
                    spec, directory, _options(workers, backend, address, quiet, stop)
                )
        if not quiet and outcome.complete:
            for line in outcome.lines:
                typer.echo(line)
        typer.echo(str(outcome.directory))
        exit_if_stopped(
            not outcome.complete,
            f"{outcome.saved}; finish it with `cartpole-q {command} --resume {outcome.directory}`",
        )


def _check_kind(kind: str, required: str | None, where: str, command: str) -> None:
    """Refuse a study of another kind than the alias runs, naming the command that runs it."""
    if required is not None and kind != required:
        raise UserError(
            f"{where}: is {_a(kind)} study, not {_a(required)} study; run it with `cartpole-q "
            f"study {where}` (`{command}` runs {required} studies)."
        )


def _a(kind: str) -> str:
    """The kind with its article: ``a dp``, ``an updates``.

    >>> _a("dp"), _a("updates"), _a("average_reward")
    ('a dp', 'an updates', 'an average_reward')
    """
    return f"{'an' if kind[:1] in 'aeiou' else 'a'} {kind}"


def _options(
    workers: int | None, backend: BackendChoice, address: str | None, quiet: bool, stop: Any
) -> Any:
    from cartpole_q.experiments.study import Options
    from cartpole_q.progress import make_sweep_progress

    def say(text: str) -> None:
        typer.echo(text, err=True)

    return Options(
        workers=workers or 0, backend=backend.value, address=address, quiet=quiet,
        should_stop=stop.is_set, progress=lambda units: make_sweep_progress(quiet, units=units),
        say=say,
    )  # fmt: skip


def _check_size(runs: int, max_runs: int, yes: bool, where: str, what: str) -> None:
    """Refuse a study of more runs than ``--max-runs`` without ``--yes``.

    ``what`` says what the runs are (``a sweep: 2 points x 100 seeds = 200 runs``).
    """
    if runs > max_runs and not yes:
        raise UserError(
            f"{where}: {what}, more than --max-runs {max_runs:,}; pass --yes to run them all "
            "(or raise --max-runs)."
        )


def _resume_hint(
    command: str, verb: str, directory: Callable[[], Path | None]
) -> Callable[[], str]:
    """How to go on with the study in ``directory()`` (``None``: not created yet)."""

    def hint() -> str:
        where = directory()
        if where is None or not where.exists():  # never made, or removed again: nothing saved
            return f"no {command} directory was kept"
        return f"{verb} it with `cartpole-q {command} --resume {where}`"

    return hint


@app.command("tune", cls=Command)
def tune_command(
    tune_file: Annotated[
        Path | None,
        typer.Argument(
            metavar="TUNE.yaml",
            help="The tune file: base config, seeds, trials, objective and search space.",
            show_default=False,
        ),
    ] = None,
    resume: Annotated[
        Path | None,
        typer.Option(
            metavar="DIR",
            help="Go on with a tune directory's study: finish it after a kill or a full disk, "
            "or raise its total with --trials.",
        ),
    ] = None,
    out: Annotated[
        Path | None,
        typer.Option(
            metavar="DIR",
            help="Tune directory to create; it must not exist or be empty.",
            show_default="tunes/<name>-<YYYYmmdd-HHMMSS>",
        ),
    ] = None,
    trials: Annotated[
        int | None,
        typer.Option(metavar="N", min=1, help="Trials in all (overrides `trials`)."),
    ] = None,
    storage: Annotated[
        str | None,
        typer.Option(
            metavar="URL",
            help="Where the study lives: an Optuna storage URL (sqlite:///study.db, "
            "postgresql://...) or a journal file's path, to share it between processes.",
            show_default="the journal file DIR/study.journal",
        ),
    ] = None,
    join: Annotated[
        bool,
        typer.Option(
            "--join",
            help="Add trials to the study of this name already in --storage (its search must "
            "be this file's) instead of refusing it.",
        ),
    ] = False,
    workers: Workers = None,
    backend: Backend = BackendChoice.local,
    address: Address = None,
    max_runs: Annotated[
        int,
        typer.Option(
            metavar="N",
            min=1,
            help="Refuse studies of more runs (trials x seeds) than this, unless --yes.",
        ),
    ] = 200_000,
    yes: Yes = False,
    quiet: Quiet = False,
) -> None:
    """Search config values with Optuna, each trial scored on every seed; the last line is its directory."""
    # Connected (or refused) before the tune directory is created, and once for all trials.
    with exit_codes(), backend_connection(backend, workers, address):
        from cartpole_q.experiments import tune as tuning
        from cartpole_q.experiments.tune_spec import load_tune
        from cartpole_q.store import tunedir
        from cartpole_q.store.lock import directory_lock

        if resume is not None:
            if tune_file is not None or out is not None or storage is not None or join:
                raise UserError(
                    "--resume goes on with the study as it was started, so it takes neither a "
                    "TUNE.yaml, --out, --storage nor --join (only --trials, to raise the total)."
                )
            tunedir.tune_file(resume)  # a tune directory, before a lock file goes into it
            with directory_lock(resume, "tune directory"):
                spec, storage_url = tuning.load_tune_dir(resume)
                where = str(resume / tunedir.TUNE_FILE)
                _check_tune_size(spec, trials, max_runs, yes, where)
                with stoppable(_resume_hint("tune", "go on", lambda: resume)) as stop:
                    _tune(spec, resume, storage_url, trials, workers, backend, address, quiet, stop)
            return
        if tune_file is None:
            raise UserError("give a TUNE.yaml file, or --resume DIR to go on with a study.")
        spec = load_tune(tune_file)
        _check_tune_size(spec, trials, max_runs, yes, str(tune_file))
        storage_url = tuning.absolute_url(storage)
        tuning.optuna_module()
        tuning.check_storage(spec, storage_url, join, str(tune_file))
        # A signal from the moment the directory exists is a request to stop that the
        # study answers (with how to go on), however early it comes.
        started: list[Path] = []
        hint = _resume_hint("tune", "go on", lambda: started[0] if started else None)
        with stoppable(hint) as stop, tuning.new_tune(spec, out, storage_url) as directory:
            started.append(directory)
            _tune(spec, directory, storage_url, trials, workers, backend, address, quiet, stop)


def _check_tune_size(spec: Any, trials: int | None, max_runs: int, yes: bool, where: str) -> None:
    total = trials or spec.trials
    runs = total * len(spec.seeds)
    product = f"{total:,} trials x {len(spec.seeds):,} seeds = {runs:,} runs"
    _check_size(runs, max_runs, yes, where, product)


def _tune(
    spec: Any,
    directory: Path,
    storage_url: str | None,
    trials: int | None,
    workers: int | None,
    backend: BackendChoice,
    address: str | None,
    quiet: bool,
    stop: Any,
) -> None:
    """Run a (locked) tune directory's study until done or ``stop`` is set; print each trial."""
    from cartpole_q.experiments import tune as tuning
    from cartpole_q.experiments.workers import default_workers

    def report(trial: dict[str, Any]) -> None:
        if quiet:
            return
        if trial.get("pruned"):
            typer.echo(f"trial {trial['number']}: pruned (it could not beat the best)")
            return
        shown = ", ".join(f"{k}={v}" for k, v in trial["values"].items())
        rate = trial.get("success_rate")
        rate_text = "" if rate is None else f"success {rate:.2f}, "
        iqm = trial.get("iqm_eval_return", float("nan"))
        typer.echo(f"trial {trial['number']}: {rate_text}IQM {iqm:.1f} ({shown})")

    hint = f"go on with `cartpole-q tune --resume {directory}`"
    if not quiet:
        say_if_compiling(spec.config_for({}))
    kept = "The study is kept, less the trial in flight"
    with kept_on_write_error(kept, hint):
        outcome = tuning.run_tune(
            spec, directory, storage_url, trials=trials,
            workers=workers or default_workers(len(spec.seeds)), backend=backend.value,
            address=address, should_stop=stop.is_set, on_trial=report,
        )  # fmt: skip
    if not quiet and outcome.best is not None:
        best = outcome.best
        typer.echo(
            f"best: trial {best['number']} ({outcome.finished_trials} trials complete), "
            f"objective {best['objective']:.6g}: "
            + ", ".join(f"{k}={v}" for k, v in best["values"].items())
        )
        typer.echo(f"trials.csv, best.yaml, history.png and importance.png in {directory}")
    typer.echo(str(directory))
    exit_if_stopped(stop.is_set(), hint)
