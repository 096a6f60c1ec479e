"""Comparing runs (single, multi-seed, or sweep points) by their seeds' figures, with intervals.

For every pair, the probability of improvement (rliable): how likely a random seed of one
beats a random seed of the other on a metric, with a 95% stratified-bootstrap interval
(seeds resampled within each run). Each run's IQM comes with its bootstrap interval, and,
for returns, the optimality gap: how far below the target (the reward threshold) the
seeds fall on average, rliable's ``mean(max(target - score, 0))``.

Runs are compared only when their figures mean the same thing: the same environment
(id, arguments, physics) and the same reward threshold. Otherwise the comparison is
refused, naming what differs, unless ``force`` is given.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from cartpole_q.config import shown_value
from cartpole_q.errors import UserError
from cartpole_q.statistics import (
    iqm_interval,
    median,
    probability_of_improvement,
    stratified_bootstrap,
)
from cartpole_q.store.runsets import RunSet, load_run_set

METRICS = {
    "eval_mean": ("greedy eval mean", True),
    "solved_episode": ("solved episode (unsolved seeds count as never)", False),
}
"""metric -> (description, whether higher is better)"""


@dataclass(frozen=True)
class Side:
    """One compared run: its label, path and one value per finished seed."""

    label: str
    path: Path
    values: list[float]
    iqm: float
    iqm_low: float
    iqm_high: float
    optimality_gap: float | None = None
    gap_low: float | None = None
    gap_high: float | None = None


@dataclass(frozen=True)
class Comparison:
    """Every pair's probability of improvement on a metric, and each run's figures."""

    metric: str
    sides: list[Side]
    probabilities: list[list[tuple[float, float, float]]]
    """``[i][j]``: ``(P(i better than j), low, high)``; the diagonal is 0.5"""
    target: float | None = None
    """the reward threshold the optimality gap is measured against"""
    notes: list[str] = field(default_factory=list)
    """what was left out or is unfinished, and incomparabilities passed with ``--force``"""

    @property
    def a(self) -> list[float]:
        """The first run's values."""
        return self.sides[0].values

    @property
    def b(self) -> list[float]:
        """The second run's values."""
        return self.sides[1].values

    @property
    def probability(self) -> float:
        """P(first better than second)."""
        return self.probabilities[0][1][0]

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready figures (two runs: the first pair at the top level, as before)."""
        first = self.probabilities[0][1]
        return {
            "metric": self.metric,
            "probability_of_improvement": first[0],
            "low": first[1],
            "high": first[2],
            "seeds_a": len(self.sides[0].values),
            "seeds_b": len(self.sides[1].values),
            "target": self.target,
            "runs": [
                {
                    "label": side.label,
                    "path": str(side.path),
                    "seeds": len(side.values),
                    "iqm": side.iqm,
                    "iqm_low": side.iqm_low,
                    "iqm_high": side.iqm_high,
                    "optimality_gap": side.optimality_gap,
                    "optimality_gap_low": side.gap_low,
                    "optimality_gap_high": side.gap_high,
                }
                for side in self.sides
            ],
            "pairs": [
                {
                    "a": self.sides[i].label,
                    "b": self.sides[j].label,
                    "probability_of_improvement": estimate,
                    "low": low,
                    "high": high,
                }
                for i, row in enumerate(self.probabilities)
                for j, (estimate, low, high) in enumerate(row)
                if i != j
            ],
            "notes": self.notes,
        }


def seed_values(run_set: RunSet, metric: str) -> list[float]:
    """One value per finished seed (``inf`` for a seed that never solved).

    Raises:
        UserError: a seed has no final evaluation to compare.
    """
    values = []
    for run in run_set.runs:
        if metric == "eval_mean":
            if run.result.eval_mean is None:
                raise UserError(f"{run.path}: has no final evaluation to compare.")
            values.append(run.result.eval_mean)
        else:
            solved = run.result.solved_episode
            values.append(float("inf") if solved is None else float(solved))
    return values


def task_of(run_set: RunSet) -> dict[str, Any]:
    """What the figures of a run are measured on: its environment and threshold."""
    env = run_set.config.env
    return {
        "env.id": env.id,
        "env.kwargs": dict(env.kwargs),
        "env.physics": dict(env.physics),
        "reward threshold": run_set.reward_threshold,
    }


def incomparable(run_sets: Sequence[RunSet], labels: Sequence[str]) -> list[str]:
    """Sentences naming what differs between the first run's task and each other's."""
    first = task_of(run_sets[0])
    found = []
    for label, run_set in zip(labels[1:], run_sets[1:], strict=True):
        task = task_of(run_set)
        for key, value in first.items():
            if task[key] != value:
                found.append(
                    f"{key}: {labels[0]} ({run_sets[0].path}) has {shown_value(value)}, "
                    f"{label} ({run_set.path}) has {shown_value(task[key])}"
                )
    return found


def labels_for(count: int) -> list[str]:
    """``A``, ``B``, ... ``Z``, ``AA``, ``AB``, ...

    >>> labels_for(3), labels_for(28)[-2:]
    (['A', 'B', 'C'], ['AA', 'AB'])
    """
    names = []
    for index in range(count):
        name, number = "", index
        while True:
            name = chr(ord("A") + number % 26) + name
            number = number // 26 - 1
            if number < 0:
                break
        names.append(name)
    return names


def compare(paths: Sequence[Path], metric: str = "eval_mean", *, force: bool = False) -> Comparison:
    """Every pair's P(better) on ``metric`` over the runs' seeds, and each run's IQM.

    Raises:
        UserError: an unknown metric, fewer than two runs, a directory that is not a
            finished run, or runs of different tasks (unless ``force``).
    """
    if metric not in METRICS:
        raise UserError(f"--metric {metric!r}: choose one of {', '.join(METRICS)}.")
    if len(paths) < 2:
        raise UserError("compare needs at least two runs.")
    run_sets = [load_run_set(path) for path in paths]
    for run_set in run_sets:
        if any(run.predicts for run in run_set.runs):
            raise UserError(
                f"{run_set.path}: is a prediction run ({run_set.config.agent.algorithm}): it "
                "has no greedy policy, no evaluation and no solve point to compare; `cartpole-q "
                "plot RUN... --metric rms_error` draws their errors side by side."
            )
    labels = labels_for(len(run_sets))
    notes = [note for run_set in run_sets for note in run_set.notes]
    differences = incomparable(run_sets, labels)
    if differences and not force:
        raise UserError(
            "these runs are not comparable: "
            + "; ".join(differences)
            + ". Their figures are measured on different tasks or scales; pass --force to "
            "compare them anyway."
        )
    notes.extend(f"compared although {difference} (--force)" for difference in differences)
    higher_is_better = METRICS[metric][1]
    target = run_sets[0].reward_threshold if metric == "eval_mean" else None
    sides = [
        _side(label, run_set.path, seed_values(run_set, metric), target)
        for label, run_set in zip(labels, run_sets, strict=True)
    ]
    probabilities = [
        [
            (0.5, 0.5, 0.5)
            if i == j
            else probability_of_improvement(_signed(a.values, higher_is_better),
                                            _signed(b.values, higher_is_better))
            for j, b in enumerate(sides)
        ]
        for i, a in enumerate(sides)
    ]  # fmt: skip
    return Comparison(metric, sides, probabilities, target, notes)


def _signed(values: list[float], higher_is_better: bool) -> list[float]:
    return values if higher_is_better else [-value for value in values]


def _side(label: str, path: Path, values: list[float], target: float | None) -> Side:
    finite = np.array([value for value in values if value != float("inf")], dtype=np.float64)
    nan = float("nan")
    point, low, high = iqm_interval(finite) if finite.size else (nan, nan, nan)
    if target is None or not finite.size:
        return Side(label, path, values, point, low, high)
    gap = optimality_gap_rows(finite[np.newaxis, :], target)[0]
    gap_low, gap_high = stratified_bootstrap(
        [finite], lambda parts: optimality_gap_rows(parts[0], target)
    )
    return Side(label, path, values, point, low, high, float(gap), gap_low, gap_high)


def optimality_gap_rows(samples: np.ndarray, target: float) -> np.ndarray:
    """The optimality gap per row (rliable's): ``mean(max(target - score, 0))``.

    >>> optimality_gap_rows(np.array([[500.0, 400.0, 475.0]]), 475.0).tolist()
    [25.0]
    """
    gaps: np.ndarray = np.maximum(target - samples, 0.0).mean(axis=1)
    return gaps


def summary_text(result: Comparison) -> str:
    """The lines ``cartpole-q compare`` prints."""
    description = METRICS[result.metric][0]
    lines = [f"metric: {description}"]
    for side in result.sides:
        finite = [value for value in side.values if value != float("inf")]
        figures = (
            f"median {median(finite):g}, IQM {side.iqm:g} [{side.iqm_low:g}, {side.iqm_high:g}]"
            if finite
            else "no finite value"
        )
        if side.optimality_gap is not None:
            figures += (
                f", optimality gap {side.optimality_gap:g} [{side.gap_low:g}, "
                f"{side.gap_high:g}] below {result.target:g}"
            )
        lines.append(f"{side.label}: {side.path} ({len(side.values)} seeds; {figures})")
    if len(result.sides) == 2:
        estimate, low, high = result.probabilities[0][1]
        lines.append(
            f"P(A better than B) = {estimate:.3f} [{low:.3f}, {high:.3f}] "
            "(95% stratified bootstrap over seeds)"
        )
        return "\n".join(lines)
    lines.append("P(row better than column), 95% stratified bootstrap over seeds:")
    width = 21
    lines.append(" " * 4 + "".join(f"{side.label:>{width}}" for side in result.sides))
    for i, side in enumerate(result.sides):
        cells = [
            "-" if i == j else f"{estimate:.3f} [{low:.2f}, {high:.2f}]"
            for j, (estimate, low, high) in enumerate(result.probabilities[i])
        ]
        lines.append(f"{side.label:<4}" + "".join(f"{cell:>{width}}" for cell in cells))
    return "\n".join(lines)


def compare_figure_data(result: Comparison) -> dict[str, Any]:
    """What the aggregate figure draws: each run's IQM, gap and seed values."""
    return {
        "labels": [f"{side.label}: {side.path.name}" for side in result.sides],
        "iqm": [(side.iqm, side.iqm_low, side.iqm_high) for side in result.sides],
        "gap": [_gap(side) for side in result.sides],
        "values": [
            np.array([v for v in side.values if v != float("inf")]) for side in result.sides
        ],
        "target": result.target,
        "metric": METRICS[result.metric][0],
        "higher_is_better": METRICS[result.metric][1],
    }


def _gap(side: Side) -> tuple[float, float, float] | None:
    if side.optimality_gap is None or side.gap_low is None or side.gap_high is None:
        return None
    return side.optimality_gap, side.gap_low, side.gap_high
