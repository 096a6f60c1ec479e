"""What the command line prints about runs: summary tables and evaluation lines."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any


def _rows_single(run_dir: Path, summary: dict[str, Any]) -> list[tuple[str, str]]:
    threshold = summary.get("reward_threshold")
    solved = summary.get("solved_episode")
    evaluation = summary.get("eval") or {}
    greedy = summary.get("first_greedy_success")
    rows = [
        ("run", str(run_dir)),
        ("engine", summary.get("engine", "?")),
        (
            "solved",
            f"episode {solved} (100-episode average >= {threshold:g})"
            if solved is not None
            else f"no ({summary.get('episodes')} episodes)",
        ),
    ]
    if evaluation:
        rows.append((
            "greedy eval",
            f"mean {evaluation['mean']:.1f} +/- {evaluation['std']:.1f} over {evaluation['episodes']} "
            f"episodes (min {evaluation['min']:g}, max {evaluation['max']:g})",
        ))  # fmt: skip
    if greedy:
        rows.append((
            "greedy first >= threshold",
            f"episode {greedy['episode']}, {greedy['env_steps']:,} env steps",
        ))  # fmt: skip
    rows.append((
        "time",
        f"{summary.get('wall_seconds', 0):.2f} s, {summary.get('env_steps', 0):,} env steps "
        f"({summary.get('steps_per_second', 0):,.0f} train steps/s, evaluations excluded)",
    ))  # fmt: skip
    if summary.get("interrupted"):
        rows.append(("status", f"interrupted after episode {summary.get('episodes')}"))
    return rows


def _rows_multi(run_dir: Path, summary: dict[str, Any]) -> list[tuple[str, str]]:
    def spread(key: str) -> str:
        value = summary.get(key)
        if not value:
            return "-"
        return f"median {value['median']:,.0f} (IQR {value['q25']:,.0f}-{value['q75']:,.0f})"

    eval_mean = summary.get("eval_mean") or {}
    rows = [
        ("run", str(run_dir)),
        ("seeds", f"{summary['seeds']} ({summary['runs']} runs, {summary['finished']} finished)"),
        ("engine", str(summary.get("engine"))),
        (
            "success",
            f"{summary['successes']}/{summary['runs']} greedy eval mean >= {summary.get('reward_threshold')}",
        ),
        ("solved episode", f"{spread('solved_episode')}, {summary['solved_runs']} solved"),
        ("env steps to solve", spread("env_steps_to_solve")),
        ("greedy first >= threshold", spread("first_greedy_success_env_steps") + " env steps"),
        (
            "eval mean",
            f"mean {eval_mean.get('mean', float('nan')):.1f}, min {eval_mean.get('min', float('nan')):.1f}",
        ),
        ("time", f"{summary['wall_seconds']:.1f} s"),
    ]
    if summary.get("interrupted"):
        rows.append(("status", "interrupted"))
    return rows


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


def print_single_summary(run_dir: Path, summary: dict[str, Any]) -> None:
    """Print the end-of-training table of one run."""
    _print_rows("Training summary", _rows_single(run_dir, summary))


def print_multi_summary(run_dir: Path, summary: dict[str, Any]) -> None:
    """Print the end-of-training table of a multi-seed run."""
    _print_rows("Multi-seed summary", _rows_multi(run_dir, summary))


def eval_line(run_dir: Path, report: dict[str, Any], threshold: float | None) -> str:
    """One line reporting a greedy evaluation.

    >>> eval_line(Path("runs/a"), {"mean": 500.0, "std": 0.0, "min": 500.0, "max": 500.0,
    ...     "episodes": 100, "seed": 7}, 475.0)
    'runs/a: greedy mean 500.00 +/- 0.00 (min 500, max 500) over 100 episodes from seed 7 [>= 475: yes]'
    """
    verdict = ""
    if threshold is not None:
        verdict = f" [>= {threshold:g}: {'yes' if report['mean'] >= threshold else 'no'}]"
    return (
        f"{run_dir}: greedy mean {report['mean']:.2f} +/- {report['std']:.2f} "
        f"(min {report['min']:g}, max {report['max']:g}) over {report['episodes']} episodes "
        f"from seed {report['seed']}{verdict}"
    )


def eval_seeds_text(parent: Path, result: dict[str, Any]) -> str:
    """Lines reporting the greedy evaluation of every seed of a multi-seed run."""
    lines = [
        f"seed {run['run_seed']}: mean {run['mean']:.2f} +/- {run['std']:.2f} (min {run['min']:g}, max {run['max']:g})"
        for run in result["runs"]
    ]
    lines.append(
        f"{parent}: {result['successes']}/{len(result['runs'])} seeds with greedy mean >= "
        f"{result['reward_threshold']:g} over {result['episodes']} episodes each in gymnasium.make; "
        f"mean of means {result['mean']:.2f}, lowest {result['min']:.2f}"
    )
    return "\n".join(lines)
