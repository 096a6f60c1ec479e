"""Learning curves across seeds: a per-episode metric, against episodes or env steps.

The curves of textbook figures are not all "return per episode": Sutton & Barto draw steps
per episode (Figs. 8.2, 10.2), episodes completed against time steps (Example 6.5) and
cumulative reward against time steps (Figs. 8.4, 8.5). Every one of them is a function of
the two per-episode records every run keeps (returns and lengths), so this module turns
those records into one curve per seed on a common x grid, then aggregates the seeds (mean
or interquartile mean) with a 95% percentile-bootstrap band. A run trained with
``train.info_metric: KEY`` keeps a third record, each episode's sum of the environment's
``info[KEY]``, drawn as the metric ``info:KEY`` (Fig. 6.5's left actions from A).

Pure functions of arrays; drawing is :mod:`cartpole_q.figures`' job.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

METRICS = ("return", "length", "cumulative-return", "episodes", "rms_error")
"""what ``plot --metric`` draws: per episode, its return or its length; running totals of
returns, or of episodes; a prediction run's RMS error of ``V`` after each episode"""
ERROR_METRIC = "rms_error"
"""a prediction run's RMS error against the true values (``metrics.csv``'s ``rms_error``)"""
INFO_METRIC_PREFIX = "info:"
"""``info:KEY``: each episode's sum of ``info[KEY]`` (runs with ``train.info_metric: KEY``)"""
INFO_KEY_PATTERN = re.compile(r"^[A-Za-z_][A-Za-z0-9_]{0,63}$")
"""an info key (``train.info_metric``, ``info:KEY``): a letter or ``_``, then letters,
digits or ``_``; at most 64 (it names a ``metrics.csv`` column and an array)"""
X_AXES = ("episode", "env-steps")
"""what ``plot --x`` draws against: training episodes, or training env steps"""
AGGREGATES = ("mean", "iqm", "mean_square")
"""how the seeds are combined: the mean, the interquartile mean (the mean of the middle
50%, robust to a few outlying seeds), or the mean of the squares (of a one-state error:
the mean square error, S&B Figure 5.3)"""
AGGREGATE_NAMES = {"mean": "mean", "iqm": "IQM", "mean_square": "mean square"}
"""each aggregate as a legend says it"""
STEP_POINTS = 400
"""points of the common env-steps grid"""

METRIC_LABELS = {
    "return": "return per episode",
    "length": "steps per episode",
    "cumulative-return": "cumulative return",
    "episodes": "episodes completed",
    "rms_error": "RMS error of V, averaged over states",
}
X_LABELS = {"episode": "training episode", "env-steps": "training env steps"}


def info_key_of(metric: str) -> str | None:
    """The info key of an ``info:KEY`` metric (``None`` for the others).

    >>> info_key_of("info:left_from_a"), info_key_of("length")
    ('left_from_a', None)
    """
    if metric.startswith(INFO_METRIC_PREFIX):
        return metric.removeprefix(INFO_METRIC_PREFIX)
    return None


def record_column(metric: str) -> str | None:
    """The ``metrics.csv`` column a metric draws beyond returns and lengths, if it needs one.

    ``info:KEY`` draws ``info_KEY`` (runs with ``train.info_metric: KEY``), ``rms_error`` the
    column of the same name (prediction runs); the others are functions of returns and
    lengths.

    >>> record_column("info:left_from_a"), record_column("rms_error"), record_column("length")
    ('info_left_from_a', 'rms_error', None)
    """
    key = info_key_of(metric)
    if key is not None:
        return f"info_{key}"
    return ERROR_METRIC if metric == ERROR_METRIC else None


def check_metric(metric: str) -> str | None:
    """What is wrong with ``metric`` (a phrase after its name), or ``None`` when it draws.

    >>> check_metric("info:left_from_a") is None, check_metric("return") is None
    (True, True)
    >>> print(check_metric("info:left from a"))
    not info:KEY with a key of letters, digits and _ (as train.info_metric)
    """
    key = info_key_of(metric)
    if key is not None:
        if INFO_KEY_PATTERN.match(key):
            return None
        return "not info:KEY with a key of letters, digits and _ (as train.info_metric)"
    if metric in METRICS:
        return None
    return f"not one of {', '.join(METRICS)}, or info:KEY"


def metric_label(metric: str) -> str:
    """A metric's axis label.

    >>> metric_label("length"), metric_label("info:left_from_a")
    ('steps per episode', 'left_from_a per episode (sum of info)')
    """
    key = info_key_of(metric)
    if key is not None:
        return f"{key} per episode (sum of info)"
    return METRIC_LABELS[metric]


def smoothed(metric: str) -> bool:
    """Whether ``--smooth`` applies to ``metric`` (per-episode values, not running totals)."""
    return metric in ("return", "length", ERROR_METRIC) or info_key_of(metric) is not None


@dataclass(frozen=True)
class SeedCurves:
    """Several seeds' curves of one metric on a common x grid."""

    x: np.ndarray
    """the grid: episodes ``1..n`` or env steps"""
    values: np.ndarray
    """``(seeds, len(x))``; NaN where a seed has no value (before its first episode ends
    on an env-steps grid, or after it stopped training)"""


def per_episode(
    returns: np.ndarray, lengths: np.ndarray, metric: str, record: np.ndarray | None = None
) -> np.ndarray:
    """One run's ``metric`` after each of its episodes.

    ``record`` is the run's column that the metric draws (:func:`record_column`): its
    per-episode sums of ``info[KEY]`` for ``info:KEY``, its errors for ``rms_error``.

    >>> per_episode(np.array([1.0, 2.0]), np.array([3, 4]), "cumulative-return").tolist()
    [1.0, 3.0]
    >>> per_episode(np.array([1.0, 2.0]), np.array([3, 4]), "episodes").tolist()
    [1.0, 2.0]
    >>> per_episode(np.array([1.0]), np.array([2]), "info:left_from_a", np.array([1.0])).tolist()
    [1.0]
    """
    column = record_column(metric)
    if column is not None:
        if record is None:
            raise ValueError(f"{metric}: the run kept no column {column}")
        return np.asarray(record, dtype=np.float64)
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
    records: Sequence[np.ndarray | None] | None = None,
) -> SeedCurves:
    """Every seed's ``metric`` on a common grid of episodes or env steps.

    Args:
        returns: Per seed, its episodes' returns.
        lengths: Per seed, its episodes' lengths (same shapes as ``returns``).
        metric: One of :data:`METRICS`.
        x: One of :data:`X_AXES`.
        window: Trailing moving average applied to each seed's per-episode values first
            (``return``, ``length`` and ``info:KEY``; running totals are not smoothed).
        x_max: The grid's end (the book's figures stop at a fixed step or episode);
            default: the longest seed's.
        records: Per seed, the column the metric draws (:func:`record_column`).

    Returns:
        The grid and the ``(seeds, points)`` values. On ``episode``, a seed's value at
        episode ``k`` is its metric after episode ``k``; on ``env-steps``, its metric after
        the last episode finished by that many steps (a step function, as the book's
        figures are drawn from per-episode records).
    """
    if x not in X_AXES:
        raise ValueError(f"unknown x axis {x!r}; one of {', '.join(X_AXES)}")
    per_seed = []
    seed_records = [None] * len(returns) if records is None else records
    for seed_returns, seed_lengths, record in zip(returns, lengths, seed_records, strict=True):
        values = per_episode(seed_returns, seed_lengths, metric, record)
        if smoothed(metric):
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


BAND_BLOCK_VALUES = 2**22
"""resampled values a band computes at once (32 MiB of float64): a longer curve's band is
computed block of points by block, so that memory stays bounded however long the runs"""


def aggregate_band(
    curves: np.ndarray,
    aggregate: str,
    rng: np.random.Generator,
    resamples: int = 1000,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The seeds' aggregate per point and its 95% percentile-bootstrap band.

    The resamples are drawn once, for every point. A curve of more than
    ``BAND_BLOCK_VALUES / resamples`` points is resampled in blocks of at most that many
    points (a 100,000-episode curve would need 800 MB at once).

    Args:
        curves: ``(seeds, points)``; NaN where a seed has no value.
        aggregate: ``mean``, ``iqm`` or ``mean_square``.
        rng: Draws the resamples (seeds resampled with replacement).
        resamples: Bootstrap resamples (the IQM's are computed in chunks).

    Returns:
        ``(centre, low, high)``, each of length ``points``.
    """
    statistic = _statistic(aggregate)
    n_seeds, points = curves.shape
    centre = statistic(curves)
    picks = rng.integers(0, n_seeds, size=(resamples, n_seeds))
    if aggregate == "mean_square":  # the mean of the squares, resampled as a mean
        return aggregate_band(curves * curves, "mean", rng, resamples)
    counts = np.zeros((resamples, n_seeds))  # how often each resample picked each seed
    np.add.at(counts, (np.arange(resamples)[:, None], picks), 1.0)
    bands = np.full((2, points), np.nan)
    blocks = max(1, -(-points * resamples // BAND_BLOCK_VALUES))  # (rounded up)
    start = 0
    for block in range(blocks):
        stop = start + points // blocks + (block < points % blocks)
        part = curves[:, start:stop]
        if aggregate == "mean":
            # A resample's mean is (how often each seed was picked) @ (the seeds' values).
            present = ~np.isnan(part)
            with np.errstate(invalid="ignore", divide="ignore"):
                resampled = (counts @ np.where(present, part, 0.0)) / (counts @ present)
        else:
            resampled = np.vstack([
                [statistic(part[pick]) for pick in picks[first : first + 50]]
                for first in range(0, resamples, 50)
            ])  # fmt: skip
        bands[:, start:stop] = nan_percentiles(resampled, [2.5, 97.5])
        start = stop
    return centre, bands[0], bands[1]


def nan_percentiles(values: np.ndarray, percents: Sequence[float]) -> np.ndarray:
    """``np.nanpercentile(values, percents, axis=0)``, the same numbers, without its slow path.

    Once any value is NaN, numpy computes each column on its own, a Python call per column
    (seven seconds for a 100,000-episode curve). Here the columns with the same number
    ``n`` of values are computed together, as ``np.percentile`` of their ``n`` smallest
    values (NaN sorts last), each column a contiguous row: numpy's own arithmetic, so
    every number is the same. A column of NaN alone is NaN. ``values`` is 2-D (rows,
    columns) with at least one row, ``percents`` a sequence; the result is float64.

    >>> values = np.array([[1.0, np.nan, np.nan], [3.0, 2.0, np.nan], [2.0, 4.0, np.nan]])
    >>> nan_percentiles(values, [50.0]).tolist()
    [[2.0, 3.0, nan]]
    """
    present = np.sum(~np.isnan(values), axis=0)
    result = np.full((len(percents), values.shape[1]), np.nan)
    full = present == values.shape[0]
    partial = np.flatnonzero(~full & (present > 0))
    with np.errstate(invalid="ignore"):  # (inf - inf between two infinite values: NaN)
        if full.any():  # (most curves: no NaN, no sorting)
            rows = np.ascontiguousarray(values[:, full].T)
            result[:, full] = np.percentile(rows, percents, axis=1, overwrite_input=True)
        if partial.size:
            ordered = np.sort(values[:, partial].T, axis=1)
            for count in np.unique(present[partial]):
                chosen = present[partial] == count
                rows = np.ascontiguousarray(ordered[chosen, :count])
                result[:, partial[chosen]] = np.percentile(
                    rows, percents, axis=1, overwrite_input=True
                )
    return result


def _statistic(aggregate: str) -> Callable[[np.ndarray], np.ndarray]:
    if aggregate == "mean":
        return lambda curves: np.asarray(_nanmean(curves))
    if aggregate == "iqm":
        return lambda curves: interquartile_mean(curves, axis=0)
    if aggregate == "mean_square":
        return lambda curves: np.asarray(_nanmean(curves * curves))
    raise ValueError(f"unknown aggregate {aggregate!r}; one of {', '.join(AGGREGATES)}")


def _nanmean(curves: np.ndarray) -> np.ndarray:
    present = np.sum(~np.isnan(curves), axis=0)
    total = np.nansum(curves, axis=0)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(present > 0, total / np.maximum(present, 1), np.nan)
