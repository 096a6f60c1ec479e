"""Commands that run many configs: ``sweep`` and ``tune``."""

from __future__ import annotations

from collections.abc import Callable
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
    note,
    say_if_compiling,
    stoppable,
)
from cartpole_q.cli.options import Address, Backend, Quiet, Workers, Yes
from cartpole_q.errors import UserError


@app.command("sweep", cls=Command)
def sweep_command(
    sweep_file: Annotated[
        Path | None,
        typer.Argument(
            metavar="SWEEP.yaml",
            help="The sweep file: base config, seeds, grid and zip axes over dotted config keys.",
            show_default=False,
        ),
    ] = None,
    resume: Annotated[
        Path | None,
        typer.Option(metavar="DIR", help="Finish an interrupted sweep directory."),
    ] = None,
    out: Annotated[
        Path | None,
        typer.Option(
            metavar="DIR",
            help="Sweep directory to create; it must not exist or be empty.",
            show_default="sweeps/<name>-<YYYYmmdd-HHMMSS>",
        ),
    ] = None,
    workers: Workers = None,
    backend: Backend = BackendChoice.local,
    address: Address = None,
    max_runs: Annotated[
        int,
        typer.Option(
            metavar="N",
            min=1,
            help="Refuse sweeps of more runs (points x seeds) than this, unless --yes.",
        ),
    ] = 20_000,
    yes: Yes = False,
    quiet: Quiet = False,
) -> None:
    """Train and evaluate every point of a sweep on every seed; the last line printed is its directory."""
    # Connected (or refused) before the sweep directory is created.
    with exit_codes(), backend_connection(backend, workers, address):
        from cartpole_q.experiments import sweep as sweeping
        from cartpole_q.store import sweepdir
        from cartpole_q.store.lock import directory_lock

        if resume is not None:
            if sweep_file is not None or out is not None:
                raise UserError(
                    "--resume finishes a sweep exactly as it was started, so it takes neither "
                    "a SWEEP.yaml nor --out."
                )
            sweepdir.sweep_file(resume)  # a sweep directory, before a lock file goes into it
            hint = _resume_hint("sweep", "finish", lambda: resume)
            with directory_lock(resume, "sweep"), stoppable(hint) as stop:
                spec = sweeping.load_sweep_dir(resume)
                outcome = _run_sweep(spec, resume, workers, backend, address, quiet, stop)
        else:
            if sweep_file is None:
                raise UserError("give a SWEEP.yaml file, or --resume DIR to finish a sweep.")
            spec = sweeping.prepare_sweep(sweep_file)
            if not spec.axes:
                note(
                    f"{sweep_file} has no grid or zip axes: every seed runs the base config "
                    "(one point)."
                )
            _check_size(
                spec.runs, max_runs, yes, str(sweep_file),
                f"{len(spec.points)} points x {len(spec.seeds)} seeds",
            )  # fmt: skip
            # A signal from the moment the directory exists is a request to stop that the
            # sweep answers (saying what it saved), however early it comes.
            started: list[Path] = []
            hint = _resume_hint("sweep", "finish", lambda: started[0] if started else None)
            with stoppable(hint) as stop, sweeping.new_sweep(spec, out) as directory:
                started.append(directory)
                outcome = _run_sweep(spec, directory, workers, backend, address, quiet, stop)
        if not quiet and outcome.complete:
            from cartpole_q.cli.report import print_sweep_summary

            print_sweep_summary(outcome)
        typer.echo(str(outcome.directory))
        saved = sweeping.saved_text(outcome.directory, outcome.done_runs, outcome.total_runs)
        exit_if_stopped(
            not outcome.complete,
            f"{saved}; finish it with `cartpole-q sweep --resume {outcome.directory}`",
        )


def _check_size(runs: int, max_runs: int, yes: bool, where: str, product: str) -> None:
    """Refuse a study of more runs than ``--max-runs`` without ``--yes``."""
    if runs > max_runs and not yes:
        raise UserError(
            f"{where}: {product} = {runs:,} runs, more than --max-runs {max_runs:,}; pass "
            "--yes to run them all (or raise --max-runs)."
        )


def _resume_hint(
    command: str, verb: str, directory: Callable[[], Path | None]
) -> Callable[[], str]:
    """How to go on with the study in ``directory()`` (``None``: not created yet)."""

    def hint() -> str:
        where = directory()
        if where is None:
            return f"no {command} directory was created"
        return f"{verb} it with `cartpole-q {command} --resume {where}`"

    return hint


def _run_sweep(
    spec: Any,
    directory: Path,
    workers: int | None,
    backend: BackendChoice,
    address: str | None,
    quiet: bool,
    stop: Any,
) -> Any:
    """Run a (locked) sweep directory until done or ``stop`` is set."""
    from cartpole_q.experiments import sweep as sweeping
    from cartpole_q.experiments.workers import default_workers
    from cartpole_q.progress import make_sweep_progress

    def say_compiling(loops: int) -> None:
        if not quiet:
            typer.echo(
                f"compiling {loops} training loop{'s' if loops > 1 else ''} first: once per "
                "machine and version, a few seconds each...",
                err=True,
            )

    if not quiet and backend is BackendChoice.ray:
        say_if_compiling(spec.points[0].config)
    progress = make_sweep_progress(quiet)
    kept = f"The sweep directory {directory} keeps every run saved so far"
    how = f"finish it with `cartpole-q sweep --resume {directory}`"
    with kept_on_write_error(kept, how):
        return sweeping.run_sweep(
            spec, directory, workers=workers or default_workers(spec.runs),
            backend=backend.value, address=address, progress=progress, should_stop=stop.is_set,
            on_compile=say_compiling,
        )  # fmt: skip


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
    product = f"{total:,} trials x {len(spec.seeds):,} seeds"
    _check_size(total * len(spec.seeds), max_runs, yes, where, product)


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
