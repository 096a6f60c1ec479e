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
    ...     "seed": 0}, None, {"physics": {"length": 0.75}, "max_steps": 1000})
    'a: greedy mean 9.00 +/- 0.00 (min 9, max 9) over 1 episodes from seed 0, under physics length=0.75, time limit 1000'
    """
    verdict = ""
    if threshold is not None:
        verdict = f" [>= {threshold:g}: {'yes' if report['mean'] >= threshold else 'no'}]"
    return (
        f"{run_dir}: greedy mean {report['mean']:.2f} +/- {report['std']:.2f} "
        f"(min {report['min']:g}, max {report['max']:g}) over {report['episodes']} episodes "
        f"from seed {report['seed']}{conditions_text(conditions)}{verdict}"
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


def eval_seeds_text(parent: Path, result: dict[str, Any]) -> str:
    """Lines reporting the greedy evaluation of every seed of a multi-seed run or sweep point.

    Where the environment's exact optimum is known, the headline counts the seeds within
    0.01 of it instead of a reward threshold no policy may reach.
    """
    lines = [
        f"seed {run['run_seed']}: mean {run['mean']:.2f} +/- {run['std']:.2f} (min {run['min']:g}, max {run['max']:g})"
        for run in result["runs"]
    ]
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
        f"{parent}: {reached} over {result['episodes']} episodes each in gymnasium.make"
        f"{conditions_text(result.get('conditions'))}; mean of means {result['mean']:.2f}, "
        f"lowest {result['min']:.2f}"
    )
    return "\n".join(lines)


SWEEP_TABLE_ROWS = 15
"""``sweep`` prints at most this many points, the best first"""


def _interval(row: dict[str, str], column: str, digits: int) -> str:
    value = row[column]
    if not value:
        return "-"
    low, high = row[f"{column}_low"], row[f"{column}_high"]
    return f"{float(value):.{digits}f} [{float(low):.{digits}f}, {float(high):.{digits}f}]"


def sweep_table(
    axes: list[str], point_rows: list[dict[str, str]], limit: int = SWEEP_TABLE_ROWS
) -> list[str]:
    """The points as text lines, best first (success rate, then IQM eval return).

    >>> row = {"point": "000", "agent.alpha": "0.1", "seeds": "2", "success_rate": "1.0",
    ...        "success_rate_low": "0.34", "success_rate_high": "1.0", "iqm_eval_return": "500.0",
    ...        "iqm_eval_return_low": "500.0", "iqm_eval_return_high": "500.0",
    ...        "median_solved_episode": "175.0", "median_solved_episode_low": "170.0",
    ...        "median_solved_episode_high": "180.0"}
    >>> for line in sweep_table(["agent.alpha"], [row]): print(line)
    point  agent.alpha  seeds  success rate [95%]  IQM eval return [95%]  median solve episode [95%]
    000    0.1          2      1.00 [0.34, 1.00]   500.0 [500.0, 500.0]   175 [170, 180]
    """

    def rank(row: dict[str, str]) -> tuple[float, float]:
        return (-float(row["success_rate"] or -1), -float(row["iqm_eval_return"] or "-inf"))

    ordered = sorted(point_rows, key=rank)[:limit]
    header = ["point", *axes, "seeds", "success rate [95%]", "IQM eval return [95%]",
              "median solve episode [95%]"]  # fmt: skip
    table = [header]
    for row in ordered:
        table.append([
            row["point"], *(row[axis] for axis in axes), row["seeds"],
            _interval(row, "success_rate", 2), _interval(row, "iqm_eval_return", 1),
            _interval(row, "median_solved_episode", 0),
        ])  # fmt: skip
    widths = [max(len(line[i]) for line in table) for i in range(len(header))]
    return ["  ".join(text.ljust(width) for text, width in zip(line, widths, strict=True)).rstrip()
            for line in table]  # fmt: skip


def print_sweep_summary(outcome: Any) -> None:
    """Print a finished sweep's points (the best first) and where its files are."""
    spec, directory = outcome.spec, outcome.directory
    rows = outcome.points
    shown = min(len(rows), SWEEP_TABLE_ROWS)
    title = f"{len(rows)} points x {len(spec.seeds)} seeds"
    if shown < len(rows):
        title += f" (the best {shown} shown; all in points.csv)"
    print(title)
    for line in sweep_table(spec.axes, rows):
        print(line)
    print(f"points.csv, results.csv and sweep.png in {directory}")
