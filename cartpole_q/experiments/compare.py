"""Comparing two runs (or multi-seed runs) by their seeds' figures, with an interval.

The probability of improvement (rliable): how likely a random seed of A beats a random seed
of B on a metric, with a 95% stratified-bootstrap interval (seeds resampled within each
run). A single run counts as one seed; a sweep point (``<sweep>/points/<p>``) has the seeds
of its ``results.csv`` rows.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from cartpole_q.errors import UserError
from cartpole_q.experiments.multiseed import load_seed_runs
from cartpole_q.experiments.statistics import iqm, median, probability_of_improvement
from cartpole_q.store import rundir, sweepdir

METRICS = {
    "eval_mean": ("greedy eval mean", True),
    "solved_episode": ("solved episode (unsolved seeds count as never)", False),
}
"""metric -> (description, whether higher is better)"""


@dataclass(frozen=True)
class Comparison:
    """The probability that A beats B on a metric, and each side's figures."""

    metric: str
    a: list[float]
    b: list[float]
    probability: float
    low: float
    high: float

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready figures."""
        return {
            "metric": self.metric,
            "probability_of_improvement": self.probability,
            "low": self.low,
            "high": self.high,
            "seeds_a": len(self.a),
            "seeds_b": len(self.b),
        }


def seed_values(path: Path, metric: str) -> list[float]:
    """One value per finished seed of a run (a single run is one seed) or sweep point."""
    point_rows = sweepdir.point_results(path)
    if point_rows is not None:
        cells = [row[metric] for row in point_rows]
        return [float(cell) if cell else float("inf") for cell in cells]
    runs = load_seed_runs(path) if rundir.is_multi_seed(path) else [rundir.load_run(path)]
    values = []
    for run in runs:
        if metric == "eval_mean":
            evaluation = run.summary.get("eval") or {}
            if evaluation.get("mean") is None:
                raise UserError(f"{run.path}: its summary.json has no final evaluation to compare.")
            values.append(float(evaluation["mean"]))
        else:
            solved = run.summary.get("solved_episode")
            values.append(float("inf") if solved is None else float(solved))
    return values


def compare(path_a: Path, path_b: Path, metric: str = "eval_mean") -> Comparison:
    """P(A better than B) on ``metric`` over the two runs' seeds.

    Raises:
        UserError: an unknown metric, or a directory that is not a finished run.
    """
    if metric not in METRICS:
        raise UserError(f"--metric {metric!r}: choose one of {', '.join(METRICS)}.")
    a, b = seed_values(path_a, metric), seed_values(path_b, metric)
    higher_is_better = METRICS[metric][1]
    signed_a = a if higher_is_better else [-value for value in a]
    signed_b = b if higher_is_better else [-value for value in b]
    probability, low, high = probability_of_improvement(signed_a, signed_b)
    return Comparison(metric, a, b, probability, low, high)


def summary_text(path_a: Path, path_b: Path, result: Comparison) -> str:
    """The lines ``cartpole-q compare`` prints."""
    description = METRICS[result.metric][0]
    lines = [f"metric: {description}"]
    for label, path, values in (("A", path_a, result.a), ("B", path_b, result.b)):
        finite = [value for value in values if value != float("inf")]
        figures = f"median {median(finite):g}, IQM {iqm(finite):g}" if finite else "no finite value"
        lines.append(f"{label}: {path} ({len(values)} seeds; {figures})")
    lines.append(
        f"P(A better than B) = {result.probability:.3f} "
        f"[{result.low:.3f}, {result.high:.3f}] (95% stratified bootstrap over seeds)"
    )
    return "\n".join(lines)
