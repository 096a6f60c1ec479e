"""Learning curves across seeds: a per-episode metric, against episodes or env steps.

The curves of textbook figures are not all "return per episode": Sutton & Barto draw steps
per episode (Figs. 8.2, 10.2), episodes completed against time steps (Fig. 6.4) and
cumulative reward against time steps (Figs. 8.4, 8.5). Every one of them is a function of
the two per-episode records every run keeps (returns and lengths), so this module turns
those records into one curve per seed on a common x grid, then aggregates the seeds (mean
or interquartile mean) with a 95% percentile-bootstrap band.

Pure functions of arrays; drawing is :mod:`cartpole_q.figures`' job.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

METRICS = ("return", "length", "cumulative-return", "episodes")
"""what ``plot --metric`` draws: per episode, its return or its length; running totals of
returns, or of episodes"""
X_AXES = ("episode", "env-steps")
"""what ``plot --x`` draws against: training episodes, or training env steps"""
AGGREGATES = ("mean", "iqm")
"""how the seeds are combined: the mean, or the interquartile mean (the mean of the middle
50%, robust to a few outlying seeds)"""
STEP_POINTS = 400
"""points of the common env-steps grid"""

METRIC_LABELS = {
    "return": "return per episode",
    "length": "steps per episode",
    "cumulative-return": "cumulative return",
    "episodes": "episodes completed",
}
X_LABELS = {"episode": "training episode", "env-steps": "training env steps"}


@dataclass(frozen=True)
class SeedCurves:
    """Several seeds' curves of one metric on a common x grid."""

    x: np.ndarray
    """the grid: episodes ``1..n`` or env steps"""
    values: np.ndarray
    """``(seeds, len(x))``; NaN where a seed has no value (before its first episode ends
    on an env-steps grid, or after it stopped training)"""


def per_episode(returns: np.ndarray, lengths: np.ndarray, metric: str) -> np.ndarray:
    """One run's ``metric`` after each of its episodes.

    >>> per_episode(np.array([1.0, 2.0]), np.array([3, 4]), "cumulative-return").tolist()
    [1.0, 3.0]
    >>> per_episode(np.array([1.0, 2.0]), np.array([3, 4]), "episodes").tolist()
    [1.0, 2.0]
    """
    if metric == "return":
        return np.asarray(returns, dtype=np.float64)
    if metric == "length":
        return np.asarray(lengths, dtype=np.float64)
    if metric == "cumulative-return":
        return np.cumsum(np.asarray(returns, dtype=np.float64))
    if metric == "episodes":
        return np.arange(1, len(returns) + 1, dtype=np.float64)
    raise ValueError(f"unknown metric {metric!r}; one of {', '.join(METRICS)}")


def smooth(values: np.ndarray, window: int) -> np.ndarray:
    """Trailing mean over the last ``window`` values (fewer at the start); 1 leaves them.

    >>> smooth(np.array([1.0, 3.0, 5.0]), 2).tolist()
    [1.0, 2.0, 4.0]
    """
    values = np.asarray(values, dtype=np.float64)
    if window <= 1 or values.size == 0:
        return values
    cumulative = np.concatenate([[0.0], np.cumsum(values)])
    index = np.arange(1, values.size + 1)
    start = np.maximum(index - window, 0)
    return np.asarray((cumulative[index] - cumulative[start]) / (index - start))


def seed_curves(
    returns: Sequence[np.ndarray],
    lengths: Sequence[np.ndarray],
    metric: str,
    x: str,
    window: int = 1,
    x_max: float | None = None,
) -> SeedCurves:
    """Every seed's ``metric`` on a common grid of episodes or env steps.

    Args:
        returns: Per seed, its episodes' returns.
        lengths: Per seed, its episodes' lengths (same shapes as ``returns``).
        metric: One of :data:`METRICS`.
        x: One of :data:`X_AXES`.
        window: Trailing moving average applied to each seed's per-episode values first
            (``return`` and ``length`` only; running totals are not smoothed).
        x_max: The grid's end (the book's figures stop at a fixed step or episode);
            default: the longest seed's.

    Returns:
        The grid and the ``(seeds, points)`` values. On ``episode``, a seed's value at
        episode ``k`` is its metric after episode ``k``; on ``env-steps``, its metric after
        the last episode finished by that many steps (a step function, as the book's
        figures are drawn from per-episode records).
    """
    if x not in X_AXES:
        raise ValueError(f"unknown x axis {x!r}; one of {', '.join(X_AXES)}")
    per_seed = []
    for seed_returns, seed_lengths in zip(returns, lengths, strict=True):
        values = per_episode(seed_returns, seed_lengths, metric)
        if metric in ("return", "length"):
            values = smooth(values, window)
        per_seed.append(values)
    if x == "episode":
        longest = max((len(values) for values in per_seed), default=0)
        if x_max is not None:
            longest = int(x_max)
        grid = np.arange(1, longest + 1, dtype=np.float64)
        table = np.full((len(per_seed), longest), np.nan)
        for row, values in zip(table, per_seed, strict=True):
            row[: min(len(values), longest)] = values[:longest]
        return SeedCurves(grid, table)
    ends = [np.cumsum(np.asarray(seed_lengths, dtype=np.int64)) for seed_lengths in lengths]
    last = max((int(end[-1]) for end in ends if end.size), default=0)
    if x_max is not None:
        last = int(x_max)
    grid = np.linspace(0.0, float(last), STEP_POINTS) if last else np.zeros(1)
    table = np.full((len(per_seed), grid.size), np.nan)
    for row, values, end in zip(table, per_seed, ends, strict=True):
        if not end.size:
            continue
        done = np.searchsorted(end, grid, side="right")  # episodes finished by each point
        inside = grid <= end[-1]
        has_value = inside & (done > 0)
        row[has_value] = values[done[has_value] - 1]
        if metric in ("cumulative-return", "episodes"):
            row[inside & (done == 0)] = 0.0  # nothing finished yet: a total of 0
    return SeedCurves(grid, table)


def interquartile_mean(values: np.ndarray, axis: int = 0) -> np.ndarray:
    """The mean of the middle 50% of ``values`` along ``axis``, ignoring NaN.

    Of ``n`` values sorted, those from index ``floor(n / 4)`` to ``n - floor(n / 4)`` (the
    interquartile range, whole values; for n < 4 every value) are averaged.

    >>> interquartile_mean(np.array([[0.0], [1.0], [2.0], [100.0]])).tolist()
    [1.5]
    """
    ordered = np.moveaxis(np.sort(values, axis=axis), axis, 0)  # NaN sorts last
    present = np.sum(~np.isnan(ordered), axis=0)
    cut = present // 4
    position = np.arange(ordered.shape[0]).reshape((-1,) + (1,) * (ordered.ndim - 1))
    middle = (position >= cut) & (position < present - cut)
    count = np.sum(middle, axis=0)
    total = np.sum(np.where(middle, ordered, 0.0), axis=0)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.asarray(np.where(count > 0, total / np.maximum(count, 1), np.nan))


def aggregate_band(
    curves: np.ndarray,
    aggregate: str,
    rng: np.random.Generator,
    resamples: int = 1000,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The seeds' aggregate per point and its 95% percentile-bootstrap band.

    Args:
        curves: ``(seeds, points)``; NaN where a seed has no value.
        aggregate: ``mean`` or ``iqm``.
        rng: Draws the resamples (seeds resampled with replacement).
        resamples: Bootstrap resamples (the IQM's are computed in chunks).

    Returns:
        ``(centre, low, high)``, each of length ``points``.
    """
    statistic = _statistic(aggregate)
    n_seeds = curves.shape[0]
    centre = statistic(curves)
    picks = rng.integers(0, n_seeds, size=(resamples, n_seeds))
    if aggregate == "mean":
        # A resample's mean is (how often each seed was picked) @ (the seeds' values).
        counts = np.zeros((resamples, n_seeds))
        np.add.at(counts, (np.arange(resamples)[:, None], picks), 1.0)
        present = ~np.isnan(curves)
        with np.errstate(invalid="ignore", divide="ignore"):
            resampled = (counts @ np.where(present, curves, 0.0)) / (counts @ present)
    else:
        resampled = np.vstack([
            [statistic(curves[pick]) for pick in picks[start : start + 50]]
            for start in range(0, resamples, 50)
        ])  # fmt: skip
    with warnings.catch_warnings():  # a point no seed reaches has no band: NaN, said once
        warnings.simplefilter("ignore", RuntimeWarning)
        low, high = np.nanpercentile(resampled, [2.5, 97.5], axis=0)
    return centre, np.asarray(low), np.asarray(high)


def _statistic(aggregate: str) -> Callable[[np.ndarray], np.ndarray]:
    if aggregate == "mean":
        return lambda curves: np.asarray(_nanmean(curves))
    if aggregate == "iqm":
        return lambda curves: interquartile_mean(curves, axis=0)
    raise ValueError(f"unknown aggregate {aggregate!r}; one of {', '.join(AGGREGATES)}")


def _nanmean(curves: np.ndarray) -> np.ndarray:
    present = np.sum(~np.isnan(curves), axis=0)
    total = np.nansum(curves, axis=0)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(present > 0, total / np.maximum(present, 1), np.nan)
