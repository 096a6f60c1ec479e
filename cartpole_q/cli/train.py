"""``cartpole-q train``, ``compile`` and ``configs``."""

from __future__ import annotations

from contextlib import nullcontext
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Any

import typer

from cartpole_q.cli.base import (
    BackendChoice,
    Command,
    EngineChoice,
    app,
    backend_connection,
    exit_codes,
    exit_if_stopped,
    kept_on_write_error,
    say_if_compiling,
    stoppable,
)
from cartpole_q.cli.options import (
    MAX_SEED,
    Address,
    Backend,
    ConfigFile,
    LocalWorkers,
    Quiet,
    SetValues,
    Workers,
)
from cartpole_q.errors import UserError


@app.command(cls=Command)
def train(
    config: ConfigFile = None,
    set_values: SetValues = None,
    seed: Annotated[
        int | None,
        typer.Option(metavar="N", min=0, max=MAX_SEED, help="Run seed (overrides `seed`)."),
    ] = None,
    seeds: Annotated[
        str | None,
        typer.Option(
            metavar="LIST",
            help="Train one run per seed, in parallel, e.g. 0-99 or 0,3,7 (overrides `train.seeds`).",
        ),
    ] = None,
    episodes: Annotated[
        int | None,
        typer.Option(
            metavar="N",
            min=1,
            help="Training episodes (overrides `train.episodes`); with --resume, extend the "
            "run to N episodes in all.",
        ),
    ] = None,
    engine: Annotated[
        EngineChoice | None, typer.Option(help="Training engine (overrides `engine`).")
    ] = None,
    out: Annotated[
        Path | None,
        typer.Option(
            metavar="DIR",
            help="Run directory to create; it must not exist or be empty.",
            show_default="runs/<name>-<date>-<time>",
        ),
    ] = None,
    resume: Annotated[
        Path | None,
        typer.Option(
            metavar="DIR",
            help="Continue an interrupted run directory to its configured episodes, or "
            "extend a run that reached them (with --episodes N, or a raised train.episodes).",
        ),
    ] = None,
    workers: Workers = None,
    backend: Backend = BackendChoice.local,
    address: Address = None,
    quiet: Quiet = False,
    watch: Annotated[
        int,
        typer.Option(
            metavar="N",
            min=0,
            help="Every N episodes, play one greedy episode in Gymnasium's window (needs a "
            "display; one run only). 0: never.",
        ),
    ] = 0,
    video_every: Annotated[
        int,
        typer.Option(
            metavar="N",
            min=0,
            help="Every N episodes, record one greedy episode as videos/episode-NNNNNN.gif in "
            "the run directory (one run only). 0: never.",
        ),
    ] = 0,
    seed_plots: Annotated[
        bool,
        typer.Option(
            "--seed-plots",
            help="With several seeds, draw reward_curve.png for each seed and for all of "
            "them together (slower; `cartpole-q plot DIR` draws it later).",
        ),
    ] = False,
    tensorboard: Annotated[
        bool,
        typer.Option(
            "--tensorboard",
            help="Also write TensorBoard event files into RUN/tensorboard/ (sets "
            '`train.tensorboard`; needs `pip install "cartpole-q\\[tensorboard]"`).',
        ),
    ] = False,
) -> None:
    """Train a Q-table and write a run directory; the last line printed is its path."""
    options = TrainOptions(workers, backend, address, quiet, watch, video_every, seed_plots)
    with exit_codes():
        from cartpole_q.experiments import run as runner
        from cartpole_q.store.lock import directory_lock

        if resume is not None:
            given = {
                "--config": config, "--set": set_values, "--seed": seed, "--seeds": seeds,
                "--engine": engine, "--out": out, "--tensorboard": tensorboard or None,
            }  # fmt: skip
            clashing = [name for name, value in given.items() if value is not None]
            if clashing:
                raise UserError(
                    f"--resume continues a run exactly as it was configured, so it cannot be "
                    f"combined with {', '.join(clashing)} (only --episodes, to extend it)."
                )
            # One writer per run directory; a path that is none gets prepare_resume's message.
            with directory_lock(resume, "run") if resume.is_dir() else nullcontext():
                prepared = runner.prepare_resume(resume, episodes)
                _check_options(prepared.config.train.seeds, watch, video_every, backend)
                _check_outputs(prepared.config, tensorboard, video_every, watch)
                with backend_connection(backend, workers, address):
                    _train_into(resume, prepared, True, options)
            return
        if seed is not None and seeds is not None:
            raise UserError("give either --seed (one run) or --seeds (several), not both.")
        assignments = [*(set_values or []), *(["train.tensorboard=true"] if tensorboard else [])]
        prepared = runner.prepare_new(
            config, assignments, seed=seed, seeds=seeds, episodes=episodes,
            engine=None if engine is None else engine.value,
        )  # fmt: skip
        _check_options(prepared.config.train.seeds, watch, video_every, backend)
        _check_outputs(prepared.config, tensorboard, video_every, watch)
        # Connected (or refused) before the run directory is created.
        with (
            backend_connection(backend, workers, address),
            runner.new_run(prepared, out) as run_dir,
        ):
            _train_into(run_dir, prepared, False, options)


def _check_options(seeds: Any, watch: int, video_every: int, backend: BackendChoice) -> None:
    """Refuse options that cannot work for this run, before it starts (or Ray is started)."""
    if seeds is None and backend is BackendChoice.ray:
        raise UserError(
            "--backend ray runs the seeds of a multi-seed run as Ray tasks: give --seeds "
            "(one run trains in this process)."
        )
    if seeds is not None and (watch or video_every):
        raise UserError(
            "--watch and --video-every follow one run; with several seeds, train one of "
            "them with --seed N to watch it."
        )
    if watch:
        from cartpole_q.envs.gym import display_problem

        problem = display_problem()
        if problem is not None:
            raise UserError(f"--watch needs a window, but {problem}; use --video-every N instead.")


def _check_outputs(config: Any, tensorboard: bool, video_every: int, watch: int) -> None:
    """Refuse outputs that cannot be written, before the run directory is created.

    TensorBoard event files need the optional writer; videos need an environment that
    renders itself; watching and videos need a greedy policy (not a prediction run's V).
    """
    if video_every or watch:
        from cartpole_q.rl.algorithms import get as get_algorithm

        if get_algorithm(config.agent.algorithm).predicts:
            raise UserError(
                f"--watch and --video-every play the greedy policy, but agent.algorithm "
                f"{config.agent.algorithm} learns the values V of a given policy: there is "
                "none to watch."
            )
    if config.train.tensorboard:
        from cartpole_q.store.tensorboard import require_writer

        require_writer("--tensorboard" if tensorboard else "train.tensorboard")
    if video_every:
        from cartpole_q.store.video import check_renderer

        check_renderer(config.env.id, "--video-every")


@dataclass(frozen=True)
class TrainOptions:
    """How ``train`` runs and shows a run: none of them changes its results."""

    workers: int | None
    """a multi-seed run's worker processes (``None``: one per core)"""
    backend: BackendChoice
    """local processes or Ray, for the seeds"""
    address: str | None
    """a running Ray cluster"""
    quiet: bool
    """print only the run directory"""
    watch: int
    """show the greedy policy every this many episodes (0: never)"""
    video_every: int
    """record the greedy policy every this many episodes (0: never)"""
    seed_plots: bool
    """draw each seed's curves too"""


def _train_into(run_dir: Path, prepared: Any, resume: bool, options: TrainOptions) -> None:
    workers, backend, address = options.workers, options.backend, options.address
    quiet, watch, video_every = options.quiet, options.watch, options.video_every
    seed_plots = options.seed_plots
    from cartpole_q.cli.report import print_multi_summary, print_single_summary
    from cartpole_q.experiments import run as runner
    from cartpole_q.progress import make_reporter
    from cartpole_q.results import MultiSeedSummary, RunSummary

    seeds = prepared.config.train.seeds
    if not quiet:
        say_if_compiling(prepared.config, prepared)
    reporter = make_reporter(quiet)
    hint = f"resume with `cartpole-q train --resume {run_dir}`"
    kept = f"The run directory {run_dir} is kept as far as it got"
    summary: RunSummary | MultiSeedSummary
    with kept_on_write_error(kept, hint), stoppable(hint) as stop:
        try:
            if seeds is None:
                outcome = runner.execute_run(
                    run_dir, prepared, resume=resume, should_stop=stop.is_set,
                    reporting=runner.Reporting(reporter), watch_every=watch,
                    video_every=video_every,
                )  # fmt: skip
                summary = outcome.summary
            else:
                from cartpole_q.experiments.multiseed import run_seeds
                from cartpole_q.experiments.workers import default_workers

                summary = run_seeds(
                    prepared, run_dir, workers=workers or default_workers(len(seeds)),
                    reporter=reporter, should_stop=stop.is_set, resume=resume,
                    seed_plots=seed_plots, backend=backend.value, address=address,
                )  # fmt: skip
        finally:
            reporter.close()
    if not quiet:
        if isinstance(summary, RunSummary):
            print_single_summary(run_dir, summary)
        else:
            print_multi_summary(run_dir, summary)
    typer.echo(str(run_dir))
    exit_if_stopped(summary.interrupted, hint)


@app.command("compile", cls=Command)
def compile_command(
    config: Annotated[
        Path | None,
        typer.Option(
            "--config",
            "-c",
            metavar="PATH|NAME",
            help="Compile this config's training loops (both engines).",
            show_default="the embedded default",
        ),
    ] = None,
    every: Annotated[
        bool,
        typer.Option(
            "--all",
            help="Compile every algorithm on every environment with a compiled twin, and on "
            "the gymnasium engine (one compilation per algorithm serves every environment "
            "but tile-coded ones), with the shipped configs' settings: tile coding, sample "
            "averages and env.randomize compile their own loops when first run.",
        ),
    ] = False,
    workers: LocalWorkers = None,
    quiet: Quiet = False,
) -> None:
    """Fill numba's cache ahead of time (CI images, classrooms): later runs start at once."""
    with exit_codes():
        from cartpole_q.config import load_config
        from cartpole_q.experiments.compiling import compile_all
        from cartpole_q.numba_cache import cache_dir

        if config is not None and every:
            raise UserError("give either --config (one config) or --all (everything), not both.")
        chosen = load_config(config) if config is not None else None
        with stoppable("run it again to compile the rest") as stop:
            compiled, skipped, seconds = compile_all(
                chosen, every, workers=workers, should_stop=stop.is_set,
                on_done=None if quiet else typer.echo,
            )  # fmt: skip
        typer.echo(
            f"{compiled} compiled or loaded, {skipped} skipped, in {seconds:.1f} s ({cache_dir()})"
        )
        exit_if_stopped(stop.is_set(), "run it again to compile the rest")


@app.command("configs", cls=Command)
def configs_command() -> None:
    """List the shipped example configs: `train -c NAME` takes one by its name."""
    from cartpole_q.config import shipped_configs

    shipped = shipped_configs()
    width = max(map(len, shipped))
    for name, description in shipped.items():
        typer.echo(f"{name:<{width}}  {description}")
