"""Commands that read finished runs: ``eval``, ``plot``, ``robustness``, ``compare``; and ``optimum``."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Annotated

import typer

from cartpole_q.cli.base import Command, PlayChoice, app, exit_codes, note
from cartpole_q.cli.options import (
    MAX_SEED,
    JsonOutput,
    MaxSteps,
    Physics,
    Quiet,
    SetValues,
    Workers,
    Yes,
)
from cartpole_q.errors import UserError


@app.command("eval", cls=Command)
def eval_command(
    run_dir: Annotated[
        Path,
        typer.Argument(
            metavar="RUN_DIR",
            help="A run directory, a multi-seed run's parent, or a sweep point "
            "(SWEEP_DIR/points/NNN).",
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
    json_output: JsonOutput = False,
    video: Annotated[
        Path | None,
        typer.Option(
            metavar="FILE",
            help="Record the first episodes (see --video-episodes) as FILE.gif, or FILE.mp4 "
            'with the video extra (`pip install "cartpole-q\\[video]"`); any environment with '
            "a renderer; checked before any episode is played.",
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
    workers: Workers = None,
    physics: Physics = None,
    max_steps: MaxSteps = None,
    engine: Annotated[
        PlayChoice,
        typer.Option(
            help="Where to play: gymnasium.make (the proof), or numba: the environment's "
            "compiled twin, the same returns exactly and some thirty times faster "
            "(environments with a twin; no --video or --render). The output says which.",
        ),
    ] = PlayChoice.gymnasium,
) -> None:
    """Play a run's greedy policy in gymnasium.make (or on its compiled twin) and report its returns."""
    with exit_codes():
        from cartpole_q.cli.exact_text import exact_lines, exact_seeds_line
        from cartpole_q.cli.report import eval_line, eval_seeds_text
        from cartpole_q.config import parse_assignment
        from cartpole_q.experiments.evaluate_runs import Recording, evaluate_run, evaluate_seeds
        from cartpole_q.store.runsets import check_tables, load_run_set

        changed = dict(parse_assignment(text, "--physics") for text in physics or [])
        run_set = load_run_set(run_dir)
        check_tables(run_set)  # each table fits its world, the file named if not
        for text in run_set.notes:
            note(text)
        if run_set.kind != "run":
            if video is not None or render:
                raise UserError(
                    f"{run_dir}: is a {run_set.kind}; --video and --render play one run: give "
                    "one seed's run directory (a multi-seed run's seed-* subdirectory)."
                )
            result = evaluate_seeds(
                run_set, episodes=episodes, seed=seed, workers=workers, physics=changed,
                max_steps=max_steps, engine=engine.value,
            )  # fmt: skip
            if json_output:
                typer.echo(json.dumps(result))
                return
            typer.echo(eval_seeds_text(run_set.path, result))
            if "exact" in result:
                typer.echo(exact_seeds_line(result["exact"]))
            return
        if video is not None:
            from cartpole_q.store.video import check_renderer

            check_renderer(run_set.runs[0].config.env.id, f"{run_dir}: --video")
        recording = None if video is None else Recording(video, video_episodes, force)
        evaluation = evaluate_run(
            run_set.runs[0], episodes=episodes, seed=seed, physics=changed, max_steps=max_steps,
            recording=recording, render=render, engine=engine.value,
        )  # fmt: skip
        if json_output:
            typer.echo(json.dumps(evaluation.to_json()))
            return
        report = evaluation.report.to_dict()
        typer.echo(eval_line(run_dir, report, evaluation.threshold, evaluation.conditions))
        if evaluation.exact is not None:
            for line in exact_lines(evaluation.exact.to_dict()):
                typer.echo(line)
        if video is not None:
            typer.echo(f"video: {video}")


@app.command(cls=Command)
def plot(
    run_dirs: Annotated[
        list[Path],
        typer.Argument(
            metavar="RUN_DIR",
            help="Run directories (single or multi-seed, or sweep points) to draw together.",
            show_default=False,
        ),
    ],
    out: Annotated[
        Path | None,
        typer.Option(
            metavar="FILE",
            help="The figure to write: .png, .svg or .pdf, as its extension says; the "
            "numbers it draws go beside it as .csv.",
            show_default="RUN_DIR/reward_curve.png, or RUN_DIR/policy_map.png with --policy "
            "(both redrawn in place); with several run directories, reward_curves.png in the "
            "current directory",
        ),
    ] = None,
    force: Annotated[
        bool, typer.Option("--force", help="Replace the figure and its .csv if they exist.")
    ] = False,
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
    metric: Annotated[
        str | None,
        typer.Option(
            metavar="METRIC",
            help="Draw learning curves of this per-episode metric instead of the reward "
            "figure: return, length (steps per episode), cumulative-return, episodes "
            "(episodes completed), rms_error (a prediction run's error of V against the true "
            "values) or info:KEY (each episode's sum of the environment's info[KEY], for runs "
            "trained with train.info_metric: KEY), each seed faint, the seeds' aggregate bold "
            "with a 95% bootstrap band.",
            show_default="the reward figure (return, 100-episode average, solve marks)",
        ),
    ] = None,
    x_axis: Annotated[
        str,
        typer.Option("--x", metavar="AXIS", help="With --metric: against episode or env-steps."),
    ] = "episode",
    aggregate: Annotated[
        str,
        typer.Option(
            metavar="AGG",
            help="With --metric: combine seeds by their mean, iqm (interquartile mean) or "
            "mean_square (the mean of their squares: a one-state error's mean square error).",
        ),
    ] = "mean",
    smooth: Annotated[
        int,
        typer.Option(
            metavar="N",
            min=1,
            help="With --metric return or length: a trailing N-episode moving average per seed.",
        ),
    ] = 1,
    log_y: Annotated[
        bool, typer.Option("--log-y", help="With --metric: a logarithmic y axis.")
    ] = False,
    all_points: Annotated[
        bool,
        typer.Option(
            "--all-points",
            help="With --metric: draw, and write in the figure's data, every point of a long "
            "curve (by default at most 1,000 per line, log-spaced on a log axis: what the "
            "figure can show).",
        ),
    ] = False,
) -> None:
    """Draw reward curves (or, with --policy, a policy map) as PNG, SVG or PDF; print its path."""
    with exit_codes():
        from cartpole_q.experiments.plots import (
            CurveStyle,
            MetricView,
            plot_metric,
            plot_policy,
            plot_rewards,
        )
        from cartpole_q.learning_curves import AGGREGATES, X_AXES, check_metric
        from cartpole_q.store.rundir import CURVE_FILE

        curve_options = (
            x_axis != "episode" or aggregate != "mean" or smooth != 1 or log_y or all_points
        )
        if metric is None and curve_options:
            raise UserError(
                "--x, --aggregate, --smooth, --log-y and --all-points apply to --metric only."
            )
        problem = None if metric is None else check_metric(metric)
        if problem is not None:
            raise UserError(f"--metric {metric}: {problem}.")
        for option, value, choices in (
            ("--x", x_axis, X_AXES), ("--aggregate", aggregate, AGGREGATES),
        ):  # fmt: skip
            if value not in choices:
                raise UserError(f"{option} {value}: not one of {', '.join(choices)}.")
        if metric is not None:
            if policy:
                raise UserError(
                    "--metric draws learning curves; --policy a policy map: one of them."
                )
            if dims is not None or seed is not None:
                raise UserError("--dims and --seed only apply to --policy.")
            name = Path(f"{metric.replace(':', '_')}_by_{x_axis}.png")
            default = run_dirs[0] / name if len(run_dirs) == 1 else name
            replace = force or (out is None and len(run_dirs) == 1)
            path = plot_metric(
                run_dirs, out or default, MetricView(metric, x_axis, aggregate, smooth), replace,
                on_note=note, style=CurveStyle(log_y=log_y, all_points=all_points),
            )  # fmt: skip
            typer.echo(str(path))
            return
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


@app.command("robustness", cls=Command)
def robustness_command(
    run_dir: Annotated[
        Path,
        typer.Argument(
            metavar="RUN_DIR",
            help="A CartPole run directory (single or multi-seed, or a sweep point).",
        ),
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
            help="The figure (.png, .svg, .pdf); its data goes beside it as .csv, every "
            "seed's mean at every grid point as _seeds.csv.",
            show_default="RUN_DIR/robustness.png",
        ),
    ] = None,
    force: Annotated[bool, typer.Option("--force", help="Replace existing files.")] = False,
    max_steps: MaxSteps = None,
    yes: Yes = False,
    quiet: Quiet = False,
) -> None:
    """The greedy policy's mean return as CartPole's physics vary: a CSV and a plot."""
    with exit_codes():
        import sys

        from cartpole_q.experiments.robustness import (
            Measurement,
            parse_vary,
            preset_axes,
            robustness,
        )
        from cartpole_q.progress import ROBUSTNESS_UNITS, make_sweep_progress

        if (preset is None) == (not vary):
            raise UserError("give --vary KEY=START:STOP:N (once or twice) or --preset NAME.")
        axes = preset_axes(preset, points) if preset else [parse_vary(text) for text in vary or []]
        figure, table = robustness(
            run_dir, Measurement(axes, episodes, seed, max_steps),
            out or run_dir / "robustness.png", force=force, yes=yes,
            progress=make_sweep_progress(quiet, sys.stderr, ROBUSTNESS_UNITS), on_note=note,
        )  # fmt: skip
        typer.echo(str(table))
        typer.echo(str(figure))


@app.command("compare", cls=Command)
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
            "as FILE (.png, .svg or .pdf), its data beside it as .csv.",
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
    json_output: JsonOutput = False,
) -> None:
    """The probability that a seed of one run beats a seed of another, for every pair, with 95% intervals."""
    with exit_codes():
        from cartpole_q.experiments.compare import compare, summary_text

        if len(runs) < 2:
            raise UserError("compare needs at least two runs.")
        if out is not None:
            from cartpole_q.store.figure_file import check_figure_file

            check_figure_file(out, "--out", force)
        result = compare(runs, metric, force=force)
        for text in result.notes:
            note(text)
        typer.echo(json.dumps(result.to_dict()) if json_output else summary_text(result))
        if out is not None:
            from cartpole_q.experiments.plots import write_compare_figure

            typer.echo(str(write_compare_figure(result, out)))


@app.command("optimum", cls=Command)
def optimum_command(
    env_id: Annotated[
        str,
        typer.Argument(
            metavar="ENV_ID",
            help="A Gymnasium id with a transition table (FrozenLake-v1, FrozenLake8x8-v1, "
            "Taxi-v4, CliffWalking-v1) or Blackjack-v1.",
        ),
    ],
    set_values: SetValues = None,
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
    policy: Annotated[
        str | None,
        typer.Option(
            metavar="POLICY",
            help="Instead, the exact state values of this fixed policy (random: uniform over "
            "the actions; a rule the world declares; greedy or epsilon_greedy of a run, with "
            "--set agent.policy_run=RUN_DIR), which a prediction run's rms_error is measured "
            "against; --gamma then defaults to 1.",
        ),
    ] = None,
    json_output: JsonOutput = False,
) -> None:
    """The best expected return from the start, by value iteration on the environment's model.

    On an average-reward world (access control): the best reward per step, by relative value iteration.
    """
    with exit_codes():
        from cartpole_q.cli.exact_text import exact_lines, policy_grid, state_label
        from cartpole_q.config import parse_assignment
        from cartpole_q.experiments.evaluate_runs import optimum, policy_values
        from cartpole_q.families import profile_for

        assignments = [parse_assignment(text) for text in set_values or []]
        if policy is not None:
            values = policy_values(env_id, assignments, policy, 1.0 if gamma is None else gamma)
            if json_output:
                typer.echo(json.dumps(values.to_json()))
                return
            typer.echo(f"{env_id} {json.dumps(values.kwargs)}")
            typer.echo(f"values of the {policy} policy (gamma {values.gamma:g}), by state:")
            blackjack = profile_for(env_id).model == "blackjack"
            for state, value in values.values.items():
                typer.echo(f"  {state_label(blackjack, state)}: {value:.6g}")
            return
        if gamma is None and profile_for(env_id).average_reward:
            from cartpole_q.experiments.average_reward import gain_optimum

            gain = gain_optimum(env_id, assignments)
            if json_output:
                typer.echo(json.dumps(gain.to_json()))
                return
            typer.echo(f"{env_id} {json.dumps(gain.kwargs)}")
            for line in gain.lines():
                typer.echo(line)
            return
        found = optimum(env_id, assignments, gamma)
        if json_output:
            typer.echo(json.dumps(found.to_json()))
            return
        typer.echo(f"{env_id} {json.dumps(found.kwargs)}")
        for line in exact_lines(found.exact.to_dict()):
            typer.echo(line)
        layout = found.layout
        if layout is not None:
            marks = {state: cell for state, cell in enumerate(layout.cells) if cell in "HCG#E"}
            legend = "S start, H hole, C cliff, G goal"
            legend += ", # wall" if "#" in layout.cells else ""
            legend += ", E end" if "E" in layout.cells else ""
            typer.echo(f"optimal first actions ({legend}):")
            optimal = list(found.exact.optimal_policy)
            typer.echo(policy_grid(optimal, layout.rows, layout.columns, layout.arrows(), marks))
