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

    finished, runs = summary["finished"], summary["runs"]
    threshold = summary.get("reward_threshold")
    eval_mean = summary.get("eval_mean")
    over = "" if finished == runs else f" (over the {finished} finished seeds)"
    rows = [
        ("run", str(run_dir)),
        ("seeds", f"{summary['seeds']} ({runs} runs, {finished} finished)"),
        ("engine", str(summary.get("engine"))),
        (
            "success",
            f"{summary['successes']}/{finished} greedy eval mean >= {threshold}{over}"
            if finished
            else "- (no seed has finished)",
        ),
        ("solved episode", f"{spread('solved_episode')}, {summary['solved_runs']} solved"),
        ("env steps to solve", spread("env_steps_to_solve")),
        ("greedy first >= threshold", spread("first_greedy_success_env_steps") + " env steps"),
        (
            "eval mean",
            f"mean {eval_mean['mean']:.1f}, min {eval_mean['min']:.1f}" if eval_mean else "-",
        ),
    ]
    if finished < runs:
        rows.append(("unfinished", _unfinished(summary)))
    rows.append(("time", f"{summary['wall_seconds']:.1f} s"))
    if summary.get("interrupted"):
        rows.append(("status", "interrupted"))
    return rows


def _unfinished(summary: dict[str, Any]) -> str:
    """Which seeds have not finished, and how far the interrupted ones got.

    >>> _unfinished({"runs": 4, "finished": 0, "interrupted_seeds": "0-1",
    ...     "no_result_seeds": "2-3", "per_seed": {
    ...         "0": {"interrupted": True, "eval_mean": 500.0},
    ...         "1": {"interrupted": True, "eval_mean": 480.0}}})
    '4 of 4: seeds 0-1 interrupted (greedy eval mean so far 490.0), seeds 2-3 without a result'
    """
    parts = []
    if summary.get("interrupted_seeds"):
        means = [
            run["eval_mean"]
            for run in summary.get("per_seed", {}).values()
            if run.get("interrupted") and run.get("eval_mean") is not None
        ]
        so_far = f" (greedy eval mean so far {sum(means) / len(means):.1f})" if means else ""
        parts.append(f"{_seeds(summary['interrupted_seeds'])} interrupted{so_far}")
    if summary.get("no_result_seeds"):
        parts.append(f"{_seeds(summary['no_result_seeds'])} without a result")
    return f"{summary['runs'] - summary['finished']} of {summary['runs']}: " + ", ".join(parts)


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
    """Lines reporting the greedy evaluation of every seed of a multi-seed run.

    The last line, when some seeds were left out, names them (``result["note"]``).
    """
    lines = [
        f"seed {run['run_seed']}: mean {run['mean']:.2f} +/- {run['std']:.2f} (min {run['min']:g}, max {run['max']:g})"
        for run in result["runs"]
    ]
    note = result.get("note")
    lines.append(
        f"{parent}: {result['successes']}/{len(result['runs'])} {'finished ' if note else ''}"
        "seeds with greedy mean >= "
        f"{result['reward_threshold']:g} over {result['episodes']} episodes each in gymnasium.make; "
        f"mean of means {result['mean']:.2f}, lowest {result['min']:.2f}"
    )
    if note:
        lines.append(note)
    return "\n".join(lines)
