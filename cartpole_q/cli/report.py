"""What the command line prints about runs: summary tables and evaluation lines."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

from cartpole_q.results import MultiSeedSummary, RunSummary, Spread, is_success


def _rows_single(run_dir: Path, summary: RunSummary) -> list[tuple[str, str]]:
    threshold = summary.reward_threshold
    solved = summary.solved_episode
    evaluation = summary.eval
    greedy = summary.first_greedy_success
    rows = [("run", str(run_dir)), ("engine", summary.engine or "?")]
    if summary.predicts:  # V of a fixed policy: nothing to solve, its error is the figure
        rows.append((
            "RMS error",
            f"{summary.rms_error:.6g} after episode {summary.episodes} (V against the policy's exact values)"
            if summary.rms_error is not None
            else f"- ({summary.episodes} episodes; the world has no model to know the exact values by)",
        ))  # fmt: skip
    else:
        rows.append((
            "solved",
            f"episode {solved} (100-episode average >= {threshold:g})"
            if solved is not None and threshold is not None
            else f"no ({summary.episodes} episodes)",
        ))  # fmt: skip
    if evaluation is not None:
        cut = ", cut short by the stop" if evaluation.interrupted else ""
        rows.append((
            "greedy eval",
            f"mean {evaluation.mean:.1f} +/- {evaluation.std:.1f} over {evaluation.episodes} "
            f"episodes (min {evaluation.min:g}, max {evaluation.max:g}{cut})",
        ))  # fmt: skip
    if greedy is not None:
        rows.append((
            "greedy first >= threshold",
            f"episode {greedy.episode}, {greedy.env_steps:,} env steps",
        ))  # fmt: skip
    rows.append((
        "time",
        f"{summary.wall_seconds:.2f} s, {summary.env_steps:,} env steps "
        f"({summary.steps_per_second:,.0f} train steps/s, evaluations excluded)",
    ))  # fmt: skip
    if summary.interrupted:
        rows.append(("status", f"interrupted after episode {summary.episodes}"))
    return rows


def _rows_multi(run_dir: Path, summary: MultiSeedSummary) -> list[tuple[str, str]]:
    def spread(value: Spread | None) -> str:
        if value is None:
            return "-"
        return f"median {value.median:,.0f} (IQR {value.q25:,.0f}-{value.q75:,.0f})"

    finished, runs = summary.finished, summary.runs
    eval_mean = summary.eval_mean
    over = "" if finished == runs else f" (over the {finished} finished seeds)"
    rows = [
        ("run", str(run_dir)),
        ("seeds", f"{summary.seeds} ({runs} runs, {finished} finished)"),
        ("engine", str(summary.engine)),
        (
            "success",
            f"{summary.successes}/{finished} greedy eval mean >= {summary.reward_threshold}{over}"
            if finished
            else "- (no seed has finished)",
        ),
        ("solved episode", f"{spread(summary.solved_episode)}, {summary.solved_runs} solved"),
        ("env steps to solve", spread(summary.env_steps_to_solve)),
        (
            "greedy first >= threshold",
            spread(summary.first_greedy_success_env_steps) + " env steps",
        ),
        (
            "eval mean",
            f"mean {eval_mean.mean:.1f}, min {eval_mean.min:.1f}" if eval_mean else "-",
        ),
    ]
    if finished < runs:
        rows.append(("unfinished", _unfinished(summary)))
    rows.append(("time", f"{summary.wall_seconds:.1f} s"))
    if summary.interrupted:
        rows.append(("status", "interrupted"))
    return rows


def _unfinished(summary: MultiSeedSummary) -> str:
    """Which seeds have not finished, and how far the interrupted ones got.

    >>> from cartpole_q.results import MultiSeedSummary, SeedEntry
    >>> entry = SeedEntry("seed-000", 50, None, None, 500.0, None, True)
    >>> summary = MultiSeedSummary("0-3", 4, 0, 4, "0-1", "2-3", True, None, None, 0, None,
    ...     0, None, None, None, None, 0.0, {"0": entry, "1": SeedEntry(
    ...         "seed-001", 50, None, None, 480.0, None, True)}, {})
    >>> _unfinished(summary)
    '4 of 4: seeds 0-1 interrupted (greedy eval mean so far 490.0), seeds 2-3 without a result'
    """
    parts = []
    if summary.interrupted_seeds:
        means = summary.interrupted_eval_means()
        so_far = f" (greedy eval mean so far {sum(means) / len(means):.1f})" if means else ""
        parts.append(f"{_seeds(summary.interrupted_seeds)} interrupted{so_far}")
    if summary.no_result_seeds:
        parts.append(f"{_seeds(summary.no_result_seeds)} without a result")
    return f"{summary.runs - summary.finished} of {summary.runs}: " + ", ".join(parts)


def _seeds(seeds: str) -> str:
    """``seed 3`` or ``seeds 0-2,5``, from seeds in ``--seeds`` syntax."""
    return f"seed {seeds}" if seeds.isdigit() else f"seeds {seeds}"


def _print_rows(title: str, rows: list[tuple[str, str]]) -> None:
    if sys.stdout.isatty():
        from rich.console import Console
        from rich.table import Table

        table = Table(title=title, show_header=False, title_justify="left")
        table.add_column(style="bold")
        table.add_column()
        for key, value in rows:
            table.add_row(key, value)
        Console().print(table)
        return
    width = max(len(key) for key, _ in rows)
    print(title)
    for key, value in rows:
        print(f"  {key:<{width}}  {value}")


def print_single_summary(run_dir: Path, summary: RunSummary) -> None:
    """Print the end-of-training table of one run."""
    _print_rows("Training summary", _rows_single(run_dir, summary))


def print_multi_summary(run_dir: Path, summary: MultiSeedSummary) -> None:
    """Print the end-of-training table of a multi-seed run."""
    _print_rows("Multi-seed summary", _rows_multi(run_dir, summary))


def eval_line(
    run_dir: Path,
    report: dict[str, Any],
    threshold: float | None,
    conditions: dict[str, Any] | None = None,
) -> str:
    """One line reporting a greedy evaluation (and the conditions it played under).

    >>> eval_line(Path("runs/a"), {"mean": 500.0, "std": 0.0, "min": 500.0, "max": 500.0,
    ...     "episodes": 100, "seed": 7}, 475.0)
    'runs/a: greedy mean 500.00 +/- 0.00 (min 500, max 500) over 100 episodes from seed 7 [>= 475: yes]'
    >>> eval_line(Path("a"), {"mean": 9.0, "std": 0.0, "min": 9, "max": 9, "episodes": 1,
    ...     "seed": 0, "played_in": "twin"}, None, {"physics": {"length": 0.75}, "max_steps": 1000})
    'a: greedy mean 9.00 +/- 0.00 (min 9, max 9) over 1 episodes from seed 0 on the compiled twin, under physics length=0.75, time limit 1000'
    """
    verdict = ""
    if threshold is not None:
        reached = is_success(report["mean"], threshold)
        verdict = f" [>= {threshold:g}: {'yes' if reached else 'no'}]"
    where = " on the compiled twin" if report.get("played_in") == "twin" else ""
    return (
        f"{run_dir}: greedy mean {report['mean']:.2f} +/- {report['std']:.2f} "
        f"(min {report['min']:g}, max {report['max']:g}) over {report['episodes']} episodes "
        f"from seed {report['seed']}{where}{conditions_text(conditions)}{verdict}"
    )


def conditions_text(conditions: dict[str, Any] | None) -> str:
    """``, under physics length=0.75, time limit 1000`` (empty without changed conditions)."""
    if not conditions:
        return ""
    parts = []
    if conditions.get("physics"):
        shown = ", ".join(f"{key}={value:g}" if isinstance(value, float) else f"{key}={value}"
                          for key, value in conditions["physics"].items())  # fmt: skip
        parts.append(f"physics {shown}")
    if conditions.get("max_steps") is not None:
        parts.append(f"time limit {conditions['max_steps']}")
    return ", under " + ", ".join(parts)


PLACES = {"gymnasium": "in gymnasium.make", "twin": "on the compiled twin"}
"""where greedy episodes were played (``played_in``), in words"""


def eval_seeds_text(parent: Path, result: dict[str, Any]) -> str:
    """Lines reporting the greedy evaluation of every seed of a multi-seed run or sweep point.

    Where the environment's exact optimum is known, the headline counts the seeds within
    0.01 of it instead of a reward threshold no policy may reach.
    """
    lines = [
        f"seed {run['run_seed']}: mean {run['mean']:.2f} +/- {run['std']:.2f} (min {run['min']:g}, max {run['max']:g})"
        for run in result["runs"]
    ]
    where = result.get("played_in") or "gymnasium"
    finished = "finished " if result.get("note") else ""
    count = len(result["runs"])
    threshold = result["reward_threshold"]
    exact = result.get("exact")
    if exact is not None:
        reached = (
            f"{exact['within_0.01']}/{count} {finished}seeds within 0.01 of the optimum "
            f"{exact['optimum']:.4g} (exact)"
        )
    elif threshold is not None:
        reached = f"{result['successes']}/{count} {finished}seeds with greedy mean >= {threshold:g}"
    else:
        reached = f"{count} {finished}seeds (no reward threshold)"
    lines.append(
        f"{parent}: {reached} over {result['episodes']} episodes each {PLACES[where]}"
        f"{conditions_text(result.get('conditions'))}; mean of means {result['mean']:.2f}, "
        f"lowest {result['min']:.2f}"
    )
    return "\n".join(lines)
