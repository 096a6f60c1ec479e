"""The ``cartpole-q`` command line: parse arguments, call the library, print, map errors.

Exit codes: 0 success; 2 bad usage or bad input (one paragraph on stderr naming the file
or field, never a traceback); 1 unexpected failure; 130 interrupted.

Heavy modules (numpy, numba, gymnasium, matplotlib) are imported inside the commands, so
``cartpole-q --help`` starts in a fraction of a second.
"""

from __future__ import annotations

import dataclasses
import json
from collections.abc import Iterator
from contextlib import contextmanager, nullcontext
from enum import StrEnum
from pathlib import Path
from typing import Annotated, Any

import typer
from typer.core import TyperCommand, TyperGroup

from cartpole_q.errors import UserError

EXIT_BAD_INPUT = 2
MAX_SEED = 2**32 - 1
"""the largest seed (as :data:`cartpole_q.config.MAX_SEED`; the CLI imports no config)"""
EXIT_INTERRUPTED = 130


class _App(TyperGroup):
    """The root command: a usage error is one line on stderr and exit code 2, as ours are.

    Typer would draw a box around it; a user reads the same one-paragraph form as every
    other bad input (``error: ...``), with where to find the command's options.
    """

    def main(  # type: ignore[override]
        self,
        args: Any = None,
        prog_name: str | None = None,
        complete_var: str | None = None,
        standalone_mode: bool = True,
        **extra: Any,
    ) -> Any:
        """Run the command line; usage errors become one line and exit code 2."""
        import sys

        if not standalone_mode:
            return super().main(args, prog_name, complete_var, standalone_mode, **extra)
        try:
            code = super().main(args, prog_name, complete_var, False, **extra)
        except typer.Abort:
            typer.echo("interrupted", err=True)
            sys.exit(EXIT_INTERRUPTED)
        except typer.TyperException as error:  # Typer's (click's) usage errors
            exit_code = getattr(error, "exit_code", EXIT_BAD_INPUT)
            context = getattr(error, "ctx", None)
            where = f" (see `{context.command_path} --help`)" if context is not None else ""
            message = error.format_message() if hasattr(error, "format_message") else str(error)
            typer.echo(f"error: {message}{where}", err=True)
            sys.exit(exit_code)
        sys.exit(code if isinstance(code, int) else 0)


app = typer.Typer(
    cls=_App,
    name="cartpole-q",
    help="Tabular Q-learning on Gymnasium's CartPole-v1: train, evaluate, plot.",
    no_args_is_help=True,
    pretty_exceptions_enable=False,
    context_settings={"help_option_names": ["-h", "--help"]},
)


class _Command(TyperCommand):
    """A command whose usage line reads like the README: ``eval [OPTIONS] RUN_DIR``.

    Typer writes required arguments as ``{run_dir}``; this writes each argument's metavar
    as given (``[RUN_DIR]`` when optional, ``RUN_DIR...`` when repeatable).
    """

    def format_help(self, ctx: Any, formatter: Any) -> None:
        """Help without Typer's type column for arguments (``<list[Path]>``): the name says it."""
        for param in self.params:
            if param.param_type_name == "argument":
                param.display_type_rich = lambda ctx: None  # type: ignore[attr-defined]
        super().format_help(ctx, formatter)

    def collect_usage_pieces(self, ctx: Any) -> list[str]:
        """The usage line after the command's name."""
        pieces = [self.options_metavar] if self.options_metavar else []
        for param in self.get_params(ctx):
            if param.param_type_name != "argument":
                continue
            name = param.metavar or (param.name or "").upper()
            name = f"{name}..." if param.nargs != 1 else name
            pieces.append(name if param.required else f"[{name}]")
        return pieces


def _print_version(value: bool) -> None:
    if value:
        from cartpole_q import __version__

        typer.echo(f"cartpole-q {__version__}")
        raise typer.Exit()


@app.callback()
def _main(
    version: Annotated[
        bool,
        typer.Option(
            "--version",
            callback=_print_version,
            is_eager=True,
            help="Print the version and exit.",
        ),
    ] = False,
) -> None:
    """Tabular Q-learning on Gymnasium's CartPole-v1: train, evaluate, plot."""


class EngineChoice(StrEnum):
    """The ``--engine`` values."""

    auto = "auto"
    numba = "numba"
    gymnasium = "gymnasium"


@contextmanager
def _exit_codes() -> Iterator[None]:
    """Turn bad input into exit code 2 and an interruption into 130, without tracebacks.

    SIGTERM interrupts like Ctrl-C (a command may handle both itself inside, as ``train``
    does to stop cleanly); once interrupted, further signals are ignored while it exits.
    """
    import signal
    import threading

    def interrupt(signum: int, frame: object) -> None:
        raise KeyboardInterrupt

    main = threading.current_thread() is threading.main_thread()
    previous = {signum: signal.getsignal(signum) for signum in (signal.SIGINT, signal.SIGTERM)}
    interrupted = False
    if main:
        signal.signal(signal.SIGTERM, interrupt)
    try:
        yield
    except UserError as error:
        typer.echo(f"error: {error}", err=True)
        raise typer.Exit(EXIT_BAD_INPUT) from None
    except KeyboardInterrupt:
        interrupted = True
        if main:
            for signum in previous:
                signal.signal(signum, signal.SIG_IGN)
        typer.echo("interrupted", err=True)
        raise typer.Exit(EXIT_INTERRUPTED) from None
    except typer.Exit as exit_:
        interrupted = exit_.exit_code == EXIT_INTERRUPTED
        raise
    finally:
        # After an interruption, signals stay ignored until the process has exited.
        if main and not interrupted:
            for signum, handler in previous.items():
                if handler is not None:  # None: installed outside Python, cannot be restored
                    signal.signal(signum, handler)


@app.command(cls=_Command)
def train(
    config: Annotated[
        Path | None,
        typer.Option(
            "--config",
            "-c",
            metavar="PATH|NAME",
            help="YAML config file, or a shipped config's name (see `cartpole-q configs`). "
            "Keys it leaves out take the embedded default's values.",
            show_default="the embedded default",
        ),
    ] = None,
    set_values: Annotated[
        list[str] | None,
        typer.Option(
            "--set",
            metavar="KEY=VALUE",
            help="Set any config key by its dotted path, the value read as YAML, e.g. "
            "--set agent.alpha=5e-4 --set discretization.bins=[1,1,6,12]. Repeatable.",
        ),
    ] = None,
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
            show_default="runs/<name>-<YYYYmmdd-HHMMSS>",
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
    workers: Annotated[
        int | None,
        typer.Option(
            metavar="N",
            min=1,
            help="Worker processes for several seeds.",
            show_default="one per core",
        ),
    ] = None,
    quiet: Annotated[
        bool, typer.Option("--quiet", "-q", help="Print nothing but the run directory.")
    ] = False,
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
) -> None:
    """Train a Q-table and write a run directory; the last line printed is its path."""
    with _exit_codes():
        from cartpole_q.config import (
            Provenance,
            load_config,
            parse_assignment,
            resolve_config_path,
        )
        from cartpole_q.experiments import run as runner
        from cartpole_q.store.lock import directory_lock

        if resume is not None:
            given = {
                "--config": config, "--set": set_values, "--seed": seed, "--seeds": seeds,
                "--engine": engine, "--out": out,
            }  # fmt: skip
            clashing = [name for name, value in given.items() if value is not None]
            if clashing:
                raise UserError(
                    f"--resume continues a run exactly as it was configured, so it cannot be "
                    f"combined with {', '.join(clashing)} (only --episodes, to extend it)."
                )
            # One writer per run directory; a path that is none gets prepare_resume's message.
            locked = directory_lock(resume, "run") if resume.is_dir() else nullcontext()
            with locked:
                prepared = runner.prepare_resume(resume, episodes)
                _check_viewing(prepared.config.train.seeds, watch, video_every)
                _train_into(resume, prepared, True, workers, quiet, watch, video_every, seed_plots)
            return
        else:
            if seed is not None and seeds is not None:
                raise UserError("give either --seed (one run) or --seeds (several), not both.")
            overrides: dict[str, Any] = dict(map(parse_assignment, set_values or []))
            if seed is not None:
                overrides.update({"seed": seed, "train.seeds": None})
            if seeds is not None:
                overrides["train.seeds"] = seeds
            if episodes is not None:
                overrides["train.episodes"] = episodes
            if engine is not None:
                overrides["engine"] = engine.value
            loaded = load_config(config, overrides)
            _check_viewing(loaded.train.seeds, watch, video_every)
            file = str(resolve_config_path(config)) if config else "default config"
            prepared = runner.prepare(loaded, Provenance(file, tuple(overrides)))
            run_dir = runner.start_run(prepared, out)
        with directory_lock(run_dir, "run"):
            _train_into(run_dir, prepared, False, workers, quiet, watch, video_every, seed_plots)


def _say_if_compiling(config: Any, prepared: Any = None) -> None:
    """Tell the user when the first run will compile the training loop (seconds, once)."""
    from cartpole_q.engines import compile_notice, resolve_engine
    from cartpole_q.envs.gym import inspect_env

    if prepared is None:
        info = inspect_env(config)
        notice = compile_notice(config, info, resolve_engine(config, info))
    else:
        notice = compile_notice(config, prepared.env_info, prepared.engine)
    if notice is not None:
        typer.echo(notice, err=True)


def _check_viewing(seeds: Any, watch: int, video_every: int) -> None:
    """Refuse --watch and --video-every where they cannot work, before a run starts."""
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


def _train_into(
    run_dir: Path,
    prepared: Any,
    resume: bool,
    workers: int | None,
    quiet: bool,
    watch: int = 0,
    video_every: int = 0,
    seed_plots: bool = False,
) -> None:
    from cartpole_q.cli.report import print_multi_summary, print_single_summary
    from cartpole_q.experiments import run as runner
    from cartpole_q.progress import make_reporter
    from cartpole_q.results import MultiSeedSummary, RunSummary

    seeds = prepared.config.train.seeds
    if not quiet:
        _say_if_compiling(prepared.config, prepared)
    reporter = make_reporter(quiet)
    resume_hint = f"resume with `cartpole-q train --resume {run_dir}`"
    stopped_at_once = False
    with runner.StopRequest(announce=lambda message: typer.echo(message, err=True)) as stop:
        try:
            summary: RunSummary | MultiSeedSummary
            if seeds is None:
                outcome = runner.execute_run(
                    run_dir, prepared, resume=resume, should_stop=stop.is_set, reporter=reporter,
                    watch_every=watch, video_every=video_every,
                )  # fmt: skip
                summary = outcome.summary
            else:
                from cartpole_q.experiments.multiseed import run_seeds
                from cartpole_q.experiments.workers import default_workers

                summary = run_seeds(
                    prepared, run_dir, workers=workers or default_workers(len(seeds)),
                    reporter=reporter, should_stop=stop.is_set, resume=resume,
                    seed_plots=seed_plots,
                )  # fmt: skip
        except KeyboardInterrupt:
            stopped_at_once = True  # a second signal: workers killed, checkpoints kept
        finally:
            reporter.close()
    if stopped_at_once:
        typer.echo(f"interrupted at once: {resume_hint}", err=True)
        raise typer.Exit(EXIT_INTERRUPTED)
    if not quiet:
        if isinstance(summary, RunSummary):
            print_single_summary(run_dir, summary)
        else:
            print_multi_summary(run_dir, summary)
    typer.echo(str(run_dir))
    if summary.interrupted:
        typer.echo(f"interrupted: {resume_hint}", err=True)
        raise typer.Exit(EXIT_INTERRUPTED)


@app.command("compile", cls=_Command)
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
            "the gymnasium engine for each observation kind.",
        ),
    ] = False,
    workers: Annotated[
        int | None,
        typer.Option(metavar="N", min=1, help="Worker processes.", show_default="one per core"),
    ] = None,
    quiet: Annotated[
        bool, typer.Option("--quiet", "-q", help="Print nothing but the summary line.")
    ] = False,
) -> None:
    """Fill numba's cache ahead of time (CI images, classrooms): later runs start at once."""
    with _exit_codes():
        from cartpole_q.config import load_config
        from cartpole_q.experiments.compiling import compile_all
        from cartpole_q.experiments.run import StopRequest
        from cartpole_q.numba_cache import cache_dir

        if config is not None and every:
            raise UserError("give either --config (one config) or --all (everything), not both.")
        chosen = load_config(config) if config is not None else None
        with StopRequest(announce=lambda message: typer.echo(message, err=True)) as stop:
            count, seconds = compile_all(
                chosen, every, workers=workers, should_stop=stop.is_set,
                on_done=None if quiet else lambda line: typer.echo(f"compiled {line}"),
            )  # fmt: skip
        typer.echo(f"{count} training loops compiled or loaded in {seconds:.1f} s ({cache_dir()})")
        if stop.is_set():
            typer.echo("interrupted: run it again to compile the rest", err=True)
            raise typer.Exit(EXIT_INTERRUPTED)


@app.command("configs", cls=_Command)
def configs_command() -> None:
    """List the shipped example configs: `train -c NAME` takes one by its name."""
    from cartpole_q.config import shipped_configs

    shipped = shipped_configs()
    width = max(map(len, shipped))
    for name, description in shipped.items():
        typer.echo(f"{name:<{width}}  {description}")


@app.command("eval", cls=_Command)
def eval_command(
    run_dir: Annotated[
        Path,
        typer.Argument(
            metavar="RUN_DIR", help="A run directory, or the parent of a multi-seed run."
        ),
    ],
    episodes: Annotated[
        int | None,
        typer.Option(
            metavar="N", min=1, help="Greedy episodes.", show_default="the run's eval.episodes"
        ),
    ] = None,
    seed: Annotated[
        int | None,
        typer.Option(
            metavar="N",
            min=0,
            max=MAX_SEED,
            help="Seed of the first reset.",
            show_default="the run's eval.seed",
        ),
    ] = None,
    json_output: Annotated[
        bool,
        typer.Option("--json", help="Print one JSON object: mean, std, min, max, episodes, seed."),
    ] = False,
    video: Annotated[
        Path | None,
        typer.Option(
            metavar="FILE",
            help="Record the first episodes (see --video-episodes) as FILE.gif, or FILE.mp4 "
            "with imageio-ffmpeg installed; checked before any episode is played.",
        ),
    ] = None,
    video_episodes: Annotated[
        int, typer.Option(metavar="N", min=1, help="How many of the episodes --video records.")
    ] = 1,
    force: Annotated[
        bool, typer.Option("--force", help="Let --video replace an existing file.")
    ] = False,
    render: Annotated[
        bool,
        typer.Option("--render", help="Show the episodes in Gymnasium's window (needs a display)."),
    ] = False,
    workers: Annotated[
        int | None,
        typer.Option(
            metavar="N",
            min=1,
            help="Worker processes for a multi-seed run.",
            show_default="one per core",
        ),
    ] = None,
    physics: Annotated[
        list[str] | None,
        typer.Option(
            "--physics",
            metavar="KEY=VALUE",
            help="Play under other CartPole physics, e.g. --physics length=0.75 (repeatable; "
            "keys of env.physics).",
        ),
    ] = None,
    max_steps: Annotated[
        int | None,
        typer.Option(
            metavar="N", min=1, help="Play with another time limit (env max_episode_steps)."
        ),
    ] = None,
) -> None:
    """Play a run's greedy policy in gymnasium.make and report its returns."""
    with _exit_codes():
        from cartpole_q.cli.report import eval_line
        from cartpole_q.config import parse_assignment
        from cartpole_q.experiments.multiseed import conditions_of
        from cartpole_q.store.runsets import load_run_set

        changed = dict(parse_assignment(text, "--physics") for text in physics or [])
        run_set = load_run_set(run_dir)
        for note in run_set.notes:
            typer.echo(f"note: {note}", err=True)
        if run_set.kind != "run":
            if video is not None or render:
                raise UserError(
                    f"{run_dir}: is a {run_set.kind}; --video and --render play one run: give "
                    "one seed's run directory (a multi-seed run's seed-* subdirectory)."
                )
            _eval_seeds(run_set, episodes, seed, json_output, workers, changed, max_steps)
            return
        run = run_set.runs[0]
        threshold = run.result.reward_threshold
        if changed or max_steps is not None:
            from cartpole_q.envs.gym import inspect_env
            from cartpole_q.evaluation import under_conditions

            run = dataclasses.replace(run, config=under_conditions(run.config, changed, max_steps))
            threshold = inspect_env(run.config).reward_threshold
        if render and video is not None:
            raise UserError("--render and --video cannot be combined: choose one.")
        if render:
            from cartpole_q.envs.gym import display_problem

            problem = display_problem()
            if problem is not None:
                raise UserError(
                    f"--render needs a display, but {problem}; "
                    "record the episodes with --video FILE.gif instead."
                )
        report = _evaluate_run(run, episodes, seed, video, video_episodes, render, force)
        from cartpole_q.cli.exact_text import exact_lines
        from cartpole_q.evaluation import exact_report

        exact = exact_report(run.config, run.q_table)  # a sentence when there is no model
        extra = {} if isinstance(exact, str) else {"exact": exact.to_dict()}
        conditions = conditions_of(changed, max_steps)
        if conditions:
            extra["conditions"] = conditions
        if json_output:
            typer.echo(json.dumps({**report.to_dict(), **extra}))
        else:
            typer.echo(eval_line(run_dir, report.to_dict(), threshold, conditions))
            for line in exact_lines(extra["exact"]) if "exact" in extra else []:
                typer.echo(line)
            if video is not None:
                typer.echo(f"video: {video}")


def _evaluate_run(
    run: Any,
    episodes: int | None,
    seed: int | None,
    video: Path | None,
    video_episodes: int,
    render: bool,
    force: bool = False,
) -> Any:
    from cartpole_q.evaluation import evaluate

    if video is None:
        return evaluate(
            run.q_table, run.config, episodes=episodes, seed=seed,
            render_mode="human" if render else None,
        )  # fmt: skip
    from cartpole_q.store.video import VideoRecorder, offscreen_rendering

    # The recorder checks the file (extension, directory, an existing file) before playing.
    with VideoRecorder(video, episodes=video_episodes, force=force) as recorder:
        with offscreen_rendering():
            report = evaluate(
                run.q_table, run.config, episodes=episodes, seed=seed,
                render_mode="rgb_array", on_frame=recorder.on_frame,
            )  # fmt: skip
        recorder.save()
    return report


def _eval_seeds(
    run_set: Any,
    episodes: int | None,
    seed: int | None,
    json_output: bool,
    workers: int | None,
    physics: dict[str, Any] | None = None,
    max_steps: int | None = None,
) -> None:
    from cartpole_q.cli.report import eval_seeds_text
    from cartpole_q.experiments.multiseed import evaluate_seeds

    result = evaluate_seeds(
        run_set, episodes=episodes, seed=seed, workers=workers, physics=physics,
        max_steps=max_steps,
    )  # fmt: skip
    if json_output:
        typer.echo(json.dumps(result))
    else:
        typer.echo(eval_seeds_text(run_set.path, result))
        if "exact" in result:
            from cartpole_q.cli.exact_text import exact_seeds_line

            typer.echo(exact_seeds_line(result["exact"]))


@app.command(cls=_Command)
def plot(
    run_dirs: Annotated[
        list[Path],
        typer.Argument(
            metavar="RUN_DIR",
            help="Run directories (single or multi-seed) to draw together.",
            show_default=False,
        ),
    ],
    out: Annotated[
        Path | None,
        typer.Option(
            metavar="FILE",
            help="The figure to write: .png, .svg or .pdf, as its extension says.",
            show_default="RUN_DIR/reward_curve.png, or RUN_DIR/policy_map.png with --policy "
            "(both redrawn in place); with several run directories, reward_curves.png in the "
            "current directory",
        ),
    ] = None,
    force: Annotated[bool, typer.Option("--force", help="Replace the file if it exists.")] = False,
    policy: Annotated[
        bool,
        typer.Option(
            "--policy",
            help="Draw the greedy action, state value and visit counts of one run over two binned dimensions.",
        ),
    ] = False,
    dims: Annotated[
        str | None,
        typer.Option(
            metavar="D1,D2",
            help="The two observation dimensions of --policy, e.g. 2,3.",
            show_default="the two with the most bins (pole angle, angular velocity)",
        ),
    ] = None,
    seed: Annotated[
        int | None,
        typer.Option(
            metavar="N",
            min=0,
            max=MAX_SEED,
            help="With --policy on several seeds: draw this seed's policy.",
            show_default="the seeds' majority action and their agreement",
        ),
    ] = None,
) -> None:
    """Draw reward curves (or, with --policy, a policy map) as PNG, SVG or PDF; print its path."""
    with _exit_codes():
        from cartpole_q.experiments.plots import plot_policy, plot_rewards
        from cartpole_q.store.rundir import CURVE_FILE

        def note(text: str) -> None:
            typer.echo(f"note: {text}", err=True)

        if policy:
            if len(run_dirs) != 1:
                raise UserError("--policy draws one run: give exactly one run directory.")
            default = run_dirs[0] / "policy_map.png"
            path = plot_policy(
                run_dirs[0], out or default, dims, force or out is None, seed, on_note=note
            )
        else:
            if dims is not None or seed is not None:
                raise UserError("--dims and --seed only apply to --policy.")
            # One directory: its own reward_curve.png (the figure training draws, from the
            # same files); several: one figure of them all here.
            default = run_dirs[0] / CURVE_FILE if len(run_dirs) == 1 else Path("reward_curves.png")
            replace = force or (out is None and len(run_dirs) == 1)
            path = plot_rewards(run_dirs, out or default, replace, on_note=note)
        typer.echo(str(path))


@app.command("robustness", cls=_Command)
def robustness_command(
    run_dir: Annotated[
        Path,
        typer.Argument(metavar="RUN_DIR", help="A CartPole run directory (single or multi-seed)."),
    ],
    vary: Annotated[
        list[str] | None,
        typer.Option(
            "--vary",
            metavar="KEY=START:STOP:N",
            help="A physics key and N values from START to STOP, e.g. length=0.25:0.75:11; "
            "once for a curve, twice for a heatmap.",
        ),
    ] = None,
    preset: Annotated[
        str | None,
        typer.Option(
            metavar="NAME",
            help="Instead of --vary: rl-generalization (force_mag 5-15 x length 0.25-0.75) "
            "or rl-generalization-extreme (1-20 x 0.05-1.0).",
        ),
    ] = None,
    points: Annotated[
        int, typer.Option(metavar="N", min=1, max=100, help="Values per key of a --preset.")
    ] = 11,
    episodes: Annotated[
        int, typer.Option(metavar="N", min=1, help="Greedy episodes per grid point.")
    ] = 20,
    seed: Annotated[
        int,
        typer.Option(
            metavar="N", min=0, max=MAX_SEED, help="Seed of each grid point's first reset."
        ),
    ] = 1000000,
    out: Annotated[
        Path | None,
        typer.Option(
            metavar="FILE",
            help="The figure (.png, .svg, .pdf); the table goes beside it as .csv.",
            show_default="RUN_DIR/robustness.png",
        ),
    ] = None,
    force: Annotated[bool, typer.Option("--force", help="Replace existing files.")] = False,
    max_steps: Annotated[
        int | None,
        typer.Option(
            metavar="N", min=1, help="Play with this time limit instead of the run's own."
        ),
    ] = None,
    yes: Annotated[
        bool,
        typer.Option(
            "--yes", "-y", help="Play however many greedy episodes it takes (above 5,000,000)."
        ),
    ] = False,
    quiet: Annotated[
        bool, typer.Option("--quiet", "-q", help="Print nothing but the two files' paths.")
    ] = False,
) -> None:
    """The greedy policy's mean return as CartPole's physics vary: a CSV and a plot."""
    with _exit_codes():
        import sys

        from cartpole_q.experiments.robustness import parse_vary, preset_axes, robustness
        from cartpole_q.progress import ROBUSTNESS_UNITS, make_sweep_progress

        if (preset is None) == (not vary):
            raise UserError("give --vary KEY=START:STOP:N (once or twice) or --preset NAME.")
        axes = preset_axes(preset, points) if preset else [parse_vary(text) for text in vary or []]
        figure, table = robustness(
            run_dir, axes, episodes, seed, out or run_dir / "robustness.png", force, max_steps,
            yes=yes, progress=make_sweep_progress(quiet, sys.stderr, ROBUSTNESS_UNITS),
            on_note=lambda note: typer.echo(f"note: {note}", err=True),
        )  # fmt: skip
        typer.echo(str(table))
        typer.echo(str(figure))


@app.command("compare", cls=_Command)
def compare_command(
    runs: Annotated[
        list[Path],
        typer.Argument(
            metavar="RUN",
            help="Two or more runs to compare: run directories, multi-seed runs or sweep "
            "points (SWEEP_DIR/points/NNN).",
            show_default=False,
        ),
    ],
    metric: Annotated[
        str,
        typer.Option(
            metavar="NAME",
            help="eval_mean (higher is better) or solved_episode (lower is better).",
        ),
    ] = "eval_mean",
    out: Annotated[
        Path | None,
        typer.Option(
            metavar="FILE",
            help="Also draw IQM and optimality gap with intervals, and performance profiles, "
            "as FILE (.png, .svg or .pdf).",
        ),
    ] = None,
    force: Annotated[
        bool,
        typer.Option(
            "--force",
            help="Compare runs of different environments or thresholds anyway; with --out, "
            "replace the file.",
        ),
    ] = False,
    json_output: Annotated[bool, typer.Option("--json", help="Print one JSON object.")] = False,
) -> None:
    """The probability that a seed of one run beats a seed of another, for every pair, with 95% intervals."""
    with _exit_codes():
        from cartpole_q.experiments.compare import compare, summary_text

        if len(runs) < 2:
            raise UserError("compare needs at least two runs.")
        if out is not None:
            from cartpole_q.figures import FIGURE_FORMATS
            from cartpole_q.store.atomic import check_output_file

            check_output_file(out, "--out", tuple(FIGURE_FORMATS), force)
        result = compare(runs, metric, force=force)
        for note in result.notes:
            typer.echo(f"note: {note}", err=True)
        typer.echo(json.dumps(result.to_dict()) if json_output else summary_text(result))
        if out is not None:
            from cartpole_q.experiments.plots import write_compare_figure

            typer.echo(str(write_compare_figure(result, out)))


class BackendChoice(StrEnum):
    """The ``sweep --backend`` values."""

    local = "local"
    ray = "ray"


@contextmanager
def _backend_connection(
    backend: BackendChoice, workers: int | None, address: str | None
) -> Iterator[None]:
    """With ``--backend ray``, stay connected to Ray (a local cluster without ``--address``)."""
    if address is not None and backend is not BackendChoice.ray:
        raise UserError("--address is for --backend ray.")
    if backend is not BackendChoice.ray:
        yield
        return
    import os

    from cartpole_q.experiments.workers import ray_connection

    with ray_connection(workers or os.cpu_count() or 1, address):
        yield


@app.command("sweep", cls=_Command)
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
    workers: Annotated[
        int | None,
        typer.Option(
            metavar="N",
            min=1,
            help="Worker processes (with Ray: a local cluster's CPUs).",
            show_default="one per core",
        ),
    ] = None,
    backend: Annotated[
        BackendChoice,
        typer.Option(
            help="Run on local processes, or as Ray tasks (`pip install 'cartpole-q\\[ray]'`)."
        ),
    ] = BackendChoice.local,
    address: Annotated[
        str | None,
        typer.Option(
            metavar="ADDR",
            help="With --backend ray: a running cluster (`auto`, or HOST:PORT of its head).",
            show_default="start a local cluster",
        ),
    ] = None,
    max_runs: Annotated[
        int,
        typer.Option(
            metavar="N",
            min=1,
            help="Refuse sweeps of more runs (points x seeds) than this, unless --yes.",
        ),
    ] = 20_000,
    yes: Annotated[
        bool, typer.Option("--yes", "-y", help="Run however many runs the sweep has.")
    ] = False,
    quiet: Annotated[
        bool, typer.Option("--quiet", "-q", help="Print nothing but the sweep directory.")
    ] = False,
) -> None:
    """Train and evaluate every point of a sweep on every seed; the last line printed is its directory."""
    # Connected (or refused) before the sweep directory is created.
    with _exit_codes(), _backend_connection(backend, workers, address):
        _sweep(sweep_file, resume, out, workers, backend, address, max_runs, yes, quiet)


def _sweep(
    sweep_file: Path | None,
    resume: Path | None,
    out: Path | None,
    workers: int | None,
    backend: BackendChoice,
    address: str | None,
    max_runs: int,
    yes: bool,
    quiet: bool,
) -> None:
    """The sweep command, once connected to its backend (see :func:`sweep_command`)."""
    from cartpole_q.experiments import sweep as sweeping
    from cartpole_q.experiments.sweep import saved_text
    from cartpole_q.store import sweepdir
    from cartpole_q.store.lock import directory_lock

    if resume is not None:
        if sweep_file is not None or out is not None:
            raise UserError(
                "--resume finishes a sweep exactly as it was started, so it takes neither "
                "a SWEEP.yaml nor --out."
            )
        sweepdir.sweep_file(resume)  # a sweep directory, before a lock file goes into it
        with directory_lock(resume, "sweep"):
            spec = sweeping.load_sweep_dir(resume)
            outcome = _run_sweep(spec, resume, workers, backend, address, quiet)
    else:
        if sweep_file is None:
            raise UserError("give a SWEEP.yaml file, or --resume DIR to finish a sweep.")
        spec = sweeping.prepare_sweep(sweep_file)
        if not spec.axes:
            typer.echo(
                f"note: {sweep_file} has no grid or zip axes: every seed runs the base config "
                "(one point).",
                err=True,
            )
        if spec.runs > max_runs and not yes:
            raise UserError(
                f"{sweep_file}: {len(spec.points)} points x {len(spec.seeds)} seeds = "
                f"{spec.runs:,} runs, more than --max-runs {max_runs:,}; pass --yes to run "
                "them all (or raise --max-runs)."
            )
        directory = sweeping.start_sweep(spec, out)
        with directory_lock(directory, "sweep"):
            outcome = _run_sweep(spec, directory, workers, backend, address, quiet)
    if not quiet and outcome.complete:
        from cartpole_q.cli.report import print_sweep_summary

        print_sweep_summary(outcome)
    typer.echo(str(outcome.directory))
    if not outcome.complete:
        saved = saved_text(outcome.directory, outcome.done_runs, outcome.total_runs)
        typer.echo(
            f"interrupted: {saved}; finish it with `cartpole-q sweep --resume {outcome.directory}`",
            err=True,
        )
        raise typer.Exit(EXIT_INTERRUPTED)


def _run_sweep(
    spec: Any,
    directory: Path,
    workers: int | None,
    backend: BackendChoice,
    address: str | None,
    quiet: bool,
) -> Any:
    """Run a (locked) sweep directory until done or stopped; exit 130 on a second signal."""
    from cartpole_q.experiments import sweep as sweeping
    from cartpole_q.experiments.run import StopRequest
    from cartpole_q.experiments.workers import default_workers
    from cartpole_q.progress import make_sweep_progress

    if not quiet:
        _say_if_compiling(spec.points[0].config)
    progress = make_sweep_progress(quiet)
    hint = f"finish it with `cartpole-q sweep --resume {directory}`"
    with StopRequest(announce=lambda message: typer.echo(message, err=True)) as stop:
        try:
            return sweeping.run_sweep(
                spec, directory, workers=workers or default_workers(spec.runs),
                backend=backend.value, address=address, progress=progress,
                should_stop=stop.is_set,
            )  # fmt: skip
        except sweeping.SweepInterrupted as interrupted:
            typer.echo(f"interrupted at once: {interrupted.text}; {hint}", err=True)
            raise typer.Exit(EXIT_INTERRUPTED) from None


@app.command("optimum", cls=_Command)
def optimum_command(
    env_id: Annotated[
        str,
        typer.Argument(
            metavar="ENV_ID",
            help="A Gymnasium id with a transition table (FrozenLake-v1, FrozenLake8x8-v1, "
            "Taxi-v4, CliffWalking-v1) or Blackjack-v1.",
        ),
    ],
    set_values: Annotated[
        list[str] | None,
        typer.Option(
            "--set",
            metavar="KEY=VALUE",
            help="Set an env key, e.g. --set env.kwargs.is_slippery=false or "
            "--set env.kwargs.map_name=8x8. Repeatable.",
        ),
    ] = None,
    gamma: Annotated[
        float | None,
        typer.Option(
            metavar="G",
            min=0.0,
            max=1.0,
            help="Also give the optimal discounted return with this discount in [0, 1) (no time "
            "limit, so it must be below 1).",
        ),
    ] = None,
    json_output: Annotated[bool, typer.Option("--json", help="Print one JSON object.")] = False,
) -> None:
    """The best expected return from the start, by value iteration on the environment's model."""
    with _exit_codes():
        from cartpole_q.cli.exact_text import exact_lines, policy_grid
        from cartpole_q.config import load_config, parse_assignment
        from cartpole_q.envs.gym import inspect_env
        from cartpole_q.envs.models import grid_layout
        from cartpole_q.evaluation import exact_report

        if gamma is not None and gamma >= 1.0:
            raise UserError(
                "--gamma 1: the discounted optimum needs a discount below 1 (with no time limit, "
                "undiscounted returns may not converge); the undiscounted optimum within the "
                "time limit is printed without --gamma."
            )
        overrides: dict[str, Any] = {"env.id": env_id}
        for key, value in map(parse_assignment, set_values or []):
            if key != "env" and not key.startswith("env."):
                raise UserError(f"--set {key}: optimum takes env keys only (env.kwargs.KEY=VALUE).")
            overrides[key] = value
        config = load_config(overrides=overrides)
        inspect_env(config)  # an unknown id or argument: a config error naming it
        exact = exact_report(config, gamma=1.0 if gamma is None else gamma)
        if isinstance(exact, str):
            raise UserError(
                f"{env_id}: no exact optimum: {exact}. It needs a transition table "
                "(env.unwrapped.P: FrozenLake, Taxi, CliffWalking) or Blackjack's rules."
            )
        result = {"env_id": env_id, "kwargs": dict(config.env.kwargs), **exact.to_dict()}
        layout = grid_layout(config.env)
        if json_output:
            typer.echo(json.dumps({**result, "policy": list(exact.optimal_policy)}))
            return
        typer.echo(f"{env_id} {json.dumps(result['kwargs'])}")
        for line in exact_lines(result):
            typer.echo(line)
        if layout is not None:
            marks = {state: cell for state, cell in enumerate(layout.cells) if cell in "HCG"}
            typer.echo("optimal first actions (S start, H hole, C cliff, G goal):")
            policy = list(exact.optimal_policy)
            typer.echo(policy_grid(policy, layout.rows, layout.columns, layout.arrows(), marks))


@app.command("tune", cls=_Command)
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
    workers: Annotated[
        int | None,
        typer.Option(
            metavar="N",
            min=1,
            help="Worker processes for each trial's seeds.",
            show_default="one per core",
        ),
    ] = None,
    backend: Annotated[
        BackendChoice,
        typer.Option(help="Run each trial's seeds on local processes, or as Ray tasks."),
    ] = BackendChoice.local,
    address: Annotated[
        str | None,
        typer.Option(metavar="ADDR", help="With --backend ray: a running cluster's address."),
    ] = None,
    max_runs: Annotated[
        int,
        typer.Option(
            metavar="N",
            min=1,
            help="Refuse studies of more runs (trials x seeds) than this, unless --yes.",
        ),
    ] = 200_000,
    yes: Annotated[
        bool, typer.Option("--yes", "-y", help="Run however many runs the study has.")
    ] = False,
    quiet: Annotated[
        bool, typer.Option("--quiet", "-q", help="Print nothing but the tune directory.")
    ] = False,
) -> None:
    """Search config values with Optuna, each trial scored on every seed; the last line is its directory."""
    # Connected (or refused) before the tune directory is created, and once for all trials.
    with _exit_codes(), _backend_connection(backend, workers, address):
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
                _check_tune_size(spec, trials, max_runs, yes, str(resume / tunedir.TUNE_FILE))
                _tune(spec, resume, storage_url, trials, workers, backend, address, quiet)
            return
        if tune_file is None:
            raise UserError("give a TUNE.yaml file, or --resume DIR to go on with a study.")
        spec = load_tune(tune_file)
        _check_tune_size(spec, trials, max_runs, yes, str(tune_file))
        storage_url = tuning.absolute_url(storage)
        tuning.optuna_module()
        tuning.check_storage(spec, storage_url, join, str(tune_file))
        directory = tuning.start_tune(spec, out, storage_url)
        with directory_lock(directory, "tune directory"):
            _tune(spec, directory, storage_url, trials, workers, backend, address, quiet)


def _check_tune_size(spec: Any, trials: int | None, max_runs: int, yes: bool, where: str) -> None:
    """Refuse a study of more runs than ``--max-runs`` without ``--yes``."""
    total = trials or spec.trials
    runs = total * len(spec.seeds)
    if runs > max_runs and not yes:
        raise UserError(
            f"{where}: {total:,} trials x {len(spec.seeds):,} seeds = {runs:,} runs, more than "
            f"--max-runs {max_runs:,}; pass --yes to run them all (or raise --max-runs)."
        )


def _tune(
    spec: Any,
    directory: Path,
    storage_url: str | None,
    trials: int | None,
    workers: int | None,
    backend: BackendChoice,
    address: str | None,
    quiet: bool,
) -> None:
    """Run a (locked) tune directory's study; print each trial and the best."""
    from cartpole_q.experiments import tune as tuning
    from cartpole_q.experiments.run import StopRequest
    from cartpole_q.experiments.workers import default_workers

    def report(trial: dict[str, Any]) -> None:
        if not quiet and trial.get("pruned"):
            typer.echo(f"trial {trial['number']}: pruned (it could not beat the best)")
        elif not quiet:
            shown = ", ".join(f"{k}={v}" for k, v in trial["values"].items())
            rate = trial.get("success_rate")
            rate_text = "" if rate is None else f"success {rate:.2f}, "
            iqm = trial.get("iqm_eval_return", float("nan"))
            typer.echo(f"trial {trial['number']}: {rate_text}IQM {iqm:.1f} ({shown})")

    hint = f"go on with `cartpole-q tune --resume {directory}`"
    if not quiet:
        _say_if_compiling(spec.config_for({}))
    with StopRequest(announce=lambda message: typer.echo(message, err=True)) as stop:
        try:
            outcome = tuning.run_tune(
                spec, directory, storage_url, trials=trials,
                workers=workers or default_workers(len(spec.seeds)), backend=backend.value,
                address=address, should_stop=stop.is_set, on_trial=report,
            )  # fmt: skip
        except KeyboardInterrupt:
            typer.echo(f"interrupted at once; {hint}", err=True)
            raise typer.Exit(EXIT_INTERRUPTED) from None
    if not quiet and outcome.best is not None:
        best = outcome.best
        typer.echo(
            f"best: trial {best['number']} ({outcome.finished_trials} trials complete), "
            f"objective {best['objective']:.6g}: "
            + ", ".join(f"{k}={v}" for k, v in best["values"].items())
        )
        typer.echo(f"trials.csv, best.yaml, history.png and importance.png in {directory}")
    typer.echo(str(directory))
    if stop.is_set():
        typer.echo(f"interrupted: {hint}", err=True)
        raise typer.Exit(EXIT_INTERRUPTED)


def main() -> None:
    """Entry point of the ``cartpole-q`` console script."""
    app()


if __name__ == "__main__":  # pragma: no cover
    main()
