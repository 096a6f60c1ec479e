"""The ``cartpole-q`` command line: parse arguments, call the library, print, map errors.

Exit codes: 0 success; 2 bad usage or bad input (one paragraph on stderr naming the file
or field, never a traceback); 1 unexpected failure; 130 interrupted.

Heavy modules (numpy, numba, gymnasium, matplotlib) are imported inside the commands, so
``cartpole-q --help`` starts in a fraction of a second.
"""

from __future__ import annotations

import json
from collections.abc import Iterator
from contextlib import contextmanager
from enum import StrEnum
from pathlib import Path
from typing import Annotated, Any

import typer

from cartpole_q.errors import UserError

EXIT_BAD_INPUT = 2
EXIT_INTERRUPTED = 130

app = typer.Typer(
    name="cartpole-q",
    help="Tabular Q-learning on Gymnasium's CartPole-v1: train, evaluate, plot.",
    add_completion=False,
    no_args_is_help=True,
    pretty_exceptions_enable=False,
)


class EngineChoice(StrEnum):
    """The ``--engine`` values."""

    auto = "auto"
    numba = "numba"
    gymnasium = "gymnasium"


@contextmanager
def _exit_codes() -> Iterator[None]:
    """Turn bad input into exit code 2 and an interruption into 130, without tracebacks."""
    try:
        yield
    except UserError as error:
        typer.echo(f"error: {error}", err=True)
        raise typer.Exit(EXIT_BAD_INPUT) from None
    except KeyboardInterrupt:
        typer.echo("interrupted", err=True)
        raise typer.Exit(EXIT_INTERRUPTED) from None


@app.command()
def train(
    config: Annotated[
        Path | None,
        typer.Option(
            "--config",
            "-c",
            help="YAML config. Keys it leaves out take the embedded default's values.",
            show_default="the embedded default",
        ),
    ] = None,
    seed: Annotated[int | None, typer.Option(min=0, help="Run seed (overrides `seed`).")] = None,
    seeds: Annotated[
        str | None,
        typer.Option(
            help="Train one run per seed, in parallel, e.g. 0-99 or 0,3,7 (overrides `train.seeds`)."
        ),
    ] = None,
    episodes: Annotated[
        int | None, typer.Option(min=1, help="Training episodes (overrides `train.episodes`).")
    ] = None,
    engine: Annotated[
        EngineChoice | None, typer.Option(help="Training engine (overrides `engine`).")
    ] = None,
    out: Annotated[
        Path | None,
        typer.Option(
            help="Run directory to create; it must not exist or be empty.",
            show_default="runs/<name>-<YYYYmmdd-HHMMSS>",
        ),
    ] = None,
    resume: Annotated[
        Path | None,
        typer.Option(help="Continue an interrupted run directory to its configured episodes."),
    ] = None,
    workers: Annotated[
        int | None,
        typer.Option(
            min=1, help="Worker processes for several seeds.", show_default="one per core"
        ),
    ] = None,
    quiet: Annotated[
        bool, typer.Option("--quiet", "-q", help="Print nothing but the run directory.")
    ] = False,
) -> None:
    """Train a Q-table and write a run directory; the last line printed is its path."""
    with _exit_codes():
        from cartpole_q import runner
        from cartpole_q.config import load_config

        if resume is not None:
            given = {
                "--config": config, "--seed": seed, "--seeds": seeds,
                "--episodes": episodes, "--engine": engine, "--out": out,
            }  # fmt: skip
            clashing = [name for name, value in given.items() if value is not None]
            if clashing:
                raise UserError(
                    f"--resume continues a run exactly as it was configured, so it cannot be "
                    f"combined with {', '.join(clashing)}."
                )
            prepared = runner.prepare_resume(resume)
            run_dir = resume
        else:
            if seed is not None and seeds is not None:
                raise UserError("give either --seed (one run) or --seeds (several), not both.")
            overrides: dict[str, Any] = {}
            if seed is not None:
                overrides.update({"seed": seed, "train.seeds": None})
            if seeds is not None:
                overrides["train.seeds"] = seeds
            if episodes is not None:
                overrides["train.episodes"] = episodes
            if engine is not None:
                overrides["engine"] = engine.value
            loaded = load_config(config, overrides)
            prepared = runner.prepare(loaded, str(config) if config else "default config")
            run_dir = runner.start_run(prepared, out)
        _train_into(run_dir, prepared, resume is not None, workers, quiet)


def _train_into(
    run_dir: Path, prepared: Any, resume: bool, workers: int | None, quiet: bool
) -> None:
    from cartpole_q import runner
    from cartpole_q.progress import make_reporter
    from cartpole_q.report import print_multi_summary, print_single_summary

    seeds = prepared.config.train.seeds
    reporter = make_reporter(quiet)
    with runner.StopRequest(announce=lambda message: typer.echo(message, err=True)) as stop:
        try:
            if seeds is None:
                outcome = runner.execute_run(
                    run_dir, prepared, resume=resume, should_stop=stop.is_set, reporter=reporter
                )
                summary = outcome.summary
            else:
                from cartpole_q.multiseed import default_workers, run_seeds

                summary = run_seeds(
                    prepared, run_dir, workers=workers or default_workers(len(seeds)),
                    reporter=reporter, should_stop=stop.is_set, resume=resume,
                )  # fmt: skip
        finally:
            reporter.close()
    if not quiet:
        if seeds is None:
            print_single_summary(run_dir, summary)
        else:
            print_multi_summary(run_dir, summary)
    typer.echo(str(run_dir))
    if summary.get("interrupted"):
        typer.echo(f"interrupted: resume with `cartpole-q train --resume {run_dir}`", err=True)
        raise typer.Exit(EXIT_INTERRUPTED)


@app.command("eval")
def eval_command(
    run_dir: Annotated[
        Path, typer.Argument(help="A run directory, or the parent of a multi-seed run.")
    ],
    episodes: Annotated[
        int | None,
        typer.Option(min=1, help="Greedy episodes.", show_default="the run's eval.episodes"),
    ] = None,
    seed: Annotated[
        int | None,
        typer.Option(min=0, help="Seed of the first reset.", show_default="the run's eval.seed"),
    ] = None,
    json_output: Annotated[
        bool,
        typer.Option("--json", help="Print one JSON object: mean, std, min, max, episodes, seed."),
    ] = False,
    video: Annotated[
        Path | None,
        typer.Option(help="Record the first episodes as an animated GIF (see --video-episodes)."),
    ] = None,
    video_episodes: Annotated[
        int, typer.Option(min=1, help="How many of the episodes --video records.")
    ] = 1,
    render: Annotated[
        bool,
        typer.Option("--render", help="Show the episodes in Gymnasium's window (needs a display)."),
    ] = False,
    workers: Annotated[
        int | None,
        typer.Option(
            min=1, help="Worker processes for a multi-seed run.", show_default="one per core"
        ),
    ] = None,
) -> None:
    """Play a run's greedy policy in gymnasium.make and report its returns."""
    with _exit_codes():
        from cartpole_q import rundir
        from cartpole_q.report import eval_line

        if rundir.is_multi_seed(run_dir):
            if video is not None or render:
                raise UserError(
                    f"{run_dir}: is a multi-seed run; --video and --render take one seed's "
                    "run directory (one of its seed-* subdirectories)."
                )
            _eval_seeds(run_dir, episodes, seed, json_output, workers)
            return
        run = rundir.load_run(run_dir)
        if render and video is not None:
            raise UserError("--render and --video cannot be combined: choose one.")
        if render:
            from cartpole_q.environment import has_display

            if not has_display():
                raise UserError(
                    "--render needs a display, but neither DISPLAY nor WAYLAND_DISPLAY is set; "
                    "record the episodes with --video FILE.gif instead."
                )
        report = _evaluate_run(run, episodes, seed, video, video_episodes, render)
        if json_output:
            typer.echo(json.dumps(report.to_dict()))
        else:
            typer.echo(eval_line(run_dir, report.to_dict(), run.summary.get("reward_threshold")))
            if video is not None:
                typer.echo(f"video: {video}")


def _evaluate_run(
    run: Any,
    episodes: int | None,
    seed: int | None,
    video: Path | None,
    video_episodes: int,
    render: bool,
) -> Any:
    from cartpole_q.evaluation import evaluate

    if video is None:
        return evaluate(
            run.q_table, run.config, episodes=episodes, seed=seed,
            render_mode="human" if render else None,
        )  # fmt: skip
    from cartpole_q.video import GifRecorder

    recorder = GifRecorder(video, episodes=video_episodes)
    report = evaluate(
        run.q_table, run.config, episodes=episodes, seed=seed,
        render_mode="rgb_array", on_frame=recorder.on_frame,
    )  # fmt: skip
    recorder.save()
    return report


def _eval_seeds(
    parent: Path, episodes: int | None, seed: int | None, json_output: bool, workers: int | None
) -> None:
    from cartpole_q.multiseed import evaluate_seeds
    from cartpole_q.report import eval_seeds_text

    result = evaluate_seeds(parent, episodes=episodes, seed=seed, workers=workers)
    typer.echo(json.dumps(result) if json_output else eval_seeds_text(parent, result))


@app.command()
def plot(
    run_dirs: Annotated[
        list[Path], typer.Argument(help="Run directories (single or multi-seed) to draw together.")
    ],
    out: Annotated[
        Path | None,
        typer.Option(
            help="PNG file to write.",
            show_default="reward_curves.png, or policy_map.png with --policy",
        ),
    ] = None,
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
            help="The two observation dimensions of --policy, e.g. 2,3.",
            show_default="the two with the most bins (pole angle, angular velocity)",
        ),
    ] = None,
) -> None:
    """Draw reward curves (or, with --policy, a policy map) as a PNG; print its path."""
    with _exit_codes():
        from cartpole_q.plotting import plot_policy, plot_rewards

        if policy:
            if len(run_dirs) != 1:
                raise UserError("--policy draws one run: give exactly one run directory.")
            path = plot_policy(run_dirs[0], out or Path("policy_map.png"), dims)
        else:
            if dims is not None:
                raise UserError("--dims only applies to --policy.")
            path = plot_rewards(run_dirs, out or Path("reward_curves.png"))
        typer.echo(str(path))


def main() -> None:
    """Entry point of the ``cartpole-q`` console script."""
    app()


if __name__ == "__main__":  # pragma: no cover
    main()
