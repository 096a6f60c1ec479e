"""Statistics of sweeps and multi-seed runs, in numpy only, as pure functions.

The estimators follow rliable (Agarwal et al., 2021, "Deep RL at the Edge of the
Statistical Precipice"): report intervals, not points.

## Estimators

- **Success rate**: ``successes / n`` with a 95% Wilson score interval (no continuity
  correction), the same as ``scipy.stats.binomtest(k, n).proportion_ci(method="wilson")``.
- **IQM** (interquartile mean): the 25% trimmed mean of ``scipy.stats.trim_mean(x, 0.25)``:
  sort, drop ``int(0.25 * n)`` values from each end, average the rest.
- **Percentile bootstrap** over seeds, stratified when there are several points: the runs
  of each point (stratum) are resampled with replacement within that point only.
- **Probability of improvement** ``P(X > Y)``: the chance that a random run of X scores
  more than a random run of Y, ties counting one half (Mann-Whitney ``U / (n m)``).
- **Performance profile**: the fraction of runs scoring more than each threshold
  (rliable's run-score distribution).

## Reproducing an interval exactly

Every bootstrap here draws, for each stratum in the order given (one stratum for a
single point; ``x`` then ``y`` for the probability of improvement), one index matrix
``rng.integers(0, n, size=(resamples, n))`` from the same ``rng``, where ``n`` is that
stratum's number of runs; row ``r`` of ``values[indices]`` is resample ``r``. The
statistic is computed for each row, and the interval is
``np.percentile(distribution, [(100 - 100 * level) / 2, (100 + 100 * level) / 2])``
with numpy's default (linear) method, i.e. ``[2.5, 97.5]`` for ``level = 0.95``. The
default ``rng`` is a fresh ``np.random.Generator(np.random.PCG64(0))`` per call, with
2000 resamples (the sweep directory contract). A generator passed in is advanced.

## Missing values

A sweep point may have no rows, or no solved seeds. Functions returning floats then
return ``nan`` (an interval ``(nan, nan)``); they never raise for empty input.
:class:`PointStatistics` turns every ``nan`` into ``None``, which the sweep writes as an
empty cell. ``nan`` *inside* the values is refused (``ValueError``): a missing value is
left out by the caller, it is not a score.
"""

from __future__ import annotations

import dataclasses
import math
import operator
from collections.abc import Callable, Sequence
from typing import Final, SupportsIndex

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "DEFAULT_LEVEL",
    "DEFAULT_RESAMPLES",
    "WILSON_Z_95",
    "PointStatistics",
    "aggregate_iqm",
    "bootstrap_interval",
    "default_rng",
    "improvement_rows",
    "iqm",
    "iqm_interval",
    "iqm_rows",
    "median",
    "median_interval",
    "median_rows",
    "performance_profile",
    "probability_of_improvement",
    "stratified_bootstrap",
    "summarize_point",
    "wilson_interval",
]

FloatArray = NDArray[np.float64]
RowStatistic = Callable[[FloatArray], ArrayLike]
"""Maps a ``(resamples, n)`` array to one value per row, shape ``(resamples,)``."""
StrataStatistic = Callable[[list[FloatArray]], ArrayLike]
"""Maps one ``(resamples, n_k)`` array per stratum to one value per row, ``(resamples,)``."""

WILSON_Z_95: Final = 1.959963984540054
"""The two-sided 95% normal quantile, ``scipy.special.ndtri(0.975)``."""
DEFAULT_RESAMPLES: Final = 2000
"""Bootstrap resamples per interval (the sweep directory contract)."""
DEFAULT_LEVEL: Final = 0.95
"""Coverage of every interval."""

_NAN: Final = float("nan")
# Rows of the mid-rank computation processed at once: bounds its memory to a few
# arrays of about this many elements, whatever the number of runs.
_RANK_BLOCK_ELEMENTS: Final = 1 << 20


def default_rng() -> np.random.Generator:
    """A fresh ``Generator(PCG64(0))``: the generator of every bootstrap by default.

    Returns:
        A new generator, in the same state at every call.

    >>> int(default_rng().integers(0, 10)) == int(default_rng().integers(0, 10))
    True
    """
    return np.random.Generator(np.random.PCG64(0))


# ----------------------------------------------------------------------------- proportions


def wilson_interval(
    successes: SupportsIndex, n: SupportsIndex, z: float = WILSON_Z_95
) -> tuple[float, float]:
    """The Wilson score interval of a proportion (95% by default), without continuity correction.

    With ``p = k / n`` and ``q = 1 - p`` (Newcombe 1998, as scipy computes it)::

        center = (2 n p + z²) / (2 (n + z²))
        delta  = z / (2 (n + z²)) · sqrt(4 n p q + z²)
        (low, high) = (center - delta, center + delta)

    with ``low = 0`` exactly when ``k = 0`` and ``high = 1`` exactly when ``k = n`` (where
    the closed form gives those values up to rounding).

    Args:
        successes: The number of successes ``k``, ``0 <= k <= n``.
        n: The number of trials; ``0`` gives ``(nan, nan)`` (a point without seeds).
        z: The normal quantile; the default is two-sided 95%.

    Returns:
        ``(low, high)``, with ``0 <= low <= k / n <= high <= 1``.

    Raises:
        TypeError: ``successes`` or ``n`` is not an integer.
        ValueError: ``n < 0``, ``k`` outside ``[0, n]``, or ``z`` not positive and finite.

    >>> low, high = wilson_interval(5, 10)
    >>> round(low, 4), round(high, 4)
    (0.2366, 0.7634)
    >>> wilson_interval(0, 10)[0], round(wilson_interval(0, 10)[1], 4)
    (0.0, 0.2775)
    >>> wilson_interval(0, 0)
    (nan, nan)
    """
    k = operator.index(successes)
    trials = operator.index(n)
    if trials < 0:
        raise ValueError(f"n must be >= 0, got {trials}")
    if not 0 <= k <= trials:
        raise ValueError(f"successes must be between 0 and n = {trials}, got {k}")
    if not (math.isfinite(z) and z > 0):
        raise ValueError(f"z must be positive and finite, got {z}")
    if trials == 0:
        return _NAN, _NAN
    p = k / trials
    q = 1.0 - p
    denom = 2.0 * (trials + z**2)
    center = (2.0 * trials * p + z**2) / denom
    delta = z / denom * math.sqrt(4.0 * trials * p * q + z**2)
    low = 0.0 if k == 0 else max(0.0, center - delta)
    high = 1.0 if k == trials else min(1.0, center + delta)
    return low, high


# ----------------------------------------------------------------------- point estimators


def iqm_rows(samples: ArrayLike) -> FloatArray:
    """The interquartile mean of each row of a 2-D array (vectorised :func:`iqm`).

    Args:
        samples: Shape ``(rows, n)``.

    Returns:
        Shape ``(rows,)``; ``nan`` everywhere when ``n = 0``.

    >>> iqm_rows([[1, 2, 3, 4], [10, 0, 0, 10]]).tolist()
    [2.5, 5.0]
    """
    ordered = np.sort(_as_matrix(samples), axis=1)
    n = ordered.shape[1]
    if n == 0:
        return np.full(ordered.shape[0], _NAN)
    cut = int(0.25 * n)
    trimmed: np.ndarray = ordered[:, cut : n - cut].mean(axis=1)
    return trimmed


def iqm(values: ArrayLike) -> float:
    """The interquartile mean: the 25% trimmed mean, as ``scipy.stats.trim_mean(x, 0.25)``.

    Sort, drop ``int(0.25 * n)`` values from each end, average the rest. Robust to a few
    failed seeds, less noisy than the median.

    Args:
        values: One score per run (1-D, no ``nan``).

    Returns:
        The IQM; ``nan`` for no values.

    >>> iqm([1, 2, 3, 4, 5, 6, 7, 8])  # drops 1, 2 and 7, 8
    4.5
    >>> iqm([9, 1, 500, 2])  # drops 1 and 500
    5.5
    >>> iqm([])
    nan
    """
    array = _as_values(values)
    if array.size == 0:
        return _NAN
    # One implementation for the point and its bootstrap, so they agree to the last bit.
    return float(iqm_rows(array[np.newaxis, :])[0])


def median_rows(samples: ArrayLike) -> FloatArray:
    """The median of each row of a 2-D array (vectorised :func:`median`).

    Args:
        samples: Shape ``(rows, n)``.

    Returns:
        Shape ``(rows,)``; ``nan`` everywhere when ``n = 0``.

    >>> median_rows([[3, 1, 2, 4], [9, 1, 2, 8]]).tolist()
    [2.5, 5.0]
    """
    ordered = np.sort(_as_matrix(samples), axis=1)
    n = ordered.shape[1]
    if n == 0:
        return np.full(ordered.shape[0], _NAN)
    # Sorting the rows is ~10x faster than np.median(axis=1) on bootstrap matrices, and
    # gives the same values: the middle one, or the mean (a + b) / 2 of the middle two.
    if n % 2:
        return ordered[:, n // 2].copy()
    return (ordered[:, n // 2 - 1] + ordered[:, n // 2]) / 2.0


def median(values: ArrayLike) -> float:
    """The median (``np.median``), ``nan`` for no values.

    Args:
        values: 1-D, no ``nan``.

    Returns:
        The median.

    >>> median([120, 80, 300, 95])
    107.5
    """
    array = _as_values(values)
    if array.size == 0:
        return _NAN
    return float(median_rows(array[np.newaxis, :])[0])


def improvement_rows(x_samples: ArrayLike, y_samples: ArrayLike) -> FloatArray:
    """``P(X > Y)`` for each pair of rows (vectorised :func:`probability_of_improvement`).

    Row ``r``'s value is ``mean over i, j of [x_ri > y_rj] + 0.5 [x_ri == y_rj]``,
    computed as the Mann-Whitney ``U / (n m)`` from mid-ranks, in ``O((n + m) log(n + m))``
    per row. ``U`` is a sum of halves, exact in float64, so the value equals the pairwise
    definition exactly.

    Args:
        x_samples: Shape ``(rows, n)``.
        y_samples: Shape ``(rows, m)``, the same number of rows.

    Returns:
        Shape ``(rows,)``; ``nan`` everywhere when ``n = 0`` or ``m = 0``.

    Raises:
        ValueError: The row counts differ.

    >>> improvement_rows([[3, 1], [1, 1]], [[2, 1], [1, 1]]).tolist()
    [0.625, 0.5]
    """
    x = _as_matrix(x_samples)
    y = _as_matrix(y_samples)
    if x.shape[0] != y.shape[0]:
        raise ValueError(f"x and y need the same number of rows, got {x.shape[0]} and {y.shape[0]}")
    rows, n = x.shape
    m = y.shape[1]
    if n == 0 or m == 0:
        return np.full(rows, _NAN)
    if rows == 0:
        return np.zeros(0)
    block = max(1, _RANK_BLOCK_ELEMENTS // (n + m))
    rank_sums = np.concatenate(
        [
            _x_rank_sums(x[start : start + block], y[start : start + block])
            for start in range(0, rows, block)
        ]
    )
    improvement: np.ndarray = (rank_sums - n * (n + 1) / 2.0) / (n * m)
    return improvement


def _x_rank_sums(x: FloatArray, y: FloatArray) -> FloatArray:
    """Per row, the sum of x's 1-based mid-ranks in the pooled row ``x ++ y``."""
    rows, n = x.shape
    pooled = np.concatenate([x, y], axis=1)
    total = pooled.shape[1]
    order = np.argsort(pooled, axis=1, kind="stable")
    ordered = np.take_along_axis(pooled, order, axis=1)
    positions = np.broadcast_to(np.arange(total), (rows, total))
    # A tie group runs from its first to its last position in the sorted row; every
    # member gets the group's mean rank.
    starts = np.ones((rows, total), dtype=bool)
    starts[:, 1:] = ordered[:, 1:] != ordered[:, :-1]
    ends = np.ones((rows, total), dtype=bool)
    ends[:, :-1] = starts[:, 1:]
    first = np.maximum.accumulate(np.where(starts, positions, 0), axis=1)
    last = np.minimum.accumulate(np.where(ends, positions, total - 1)[:, ::-1], axis=1)[:, ::-1]
    mid_ranks = (first + last) / 2.0 + 1.0
    sums: np.ndarray = np.where(order < n, mid_ranks, 0.0).sum(axis=1)
    return sums


# ------------------------------------------------------------------------------ bootstrap


def stratified_bootstrap(
    strata: Sequence[ArrayLike],
    statistic: StrataStatistic,
    *,
    resamples: int = DEFAULT_RESAMPLES,
    rng: np.random.Generator | None = None,
    level: float = DEFAULT_LEVEL,
) -> tuple[float, float]:
    """Percentile bootstrap interval, resampling runs within each stratum independently.

    rliable's stratified bootstrap: a stratum is a sweep point (or one of the two sides
    of a comparison); its runs are resampled with replacement among themselves only, so
    every resample keeps each stratum's size. For each stratum in order, one index matrix
    ``rng.integers(0, n_k, size=(resamples, n_k))`` is drawn from ``rng``; the statistic
    gets the list of ``values_k[indices_k]`` and returns one value per row; the interval is
    the ``(100 ∓ 100 level) / 2`` percentiles of those values (numpy's linear method).

    Args:
        strata: One 1-D array of run scores per stratum (sizes may differ), no ``nan``.
        statistic: ``[(resamples, n_1), (resamples, n_2), ...] -> (resamples,)``, e.g.
            ``lambda parts: iqm_rows(np.concatenate(parts, axis=1))``.
        resamples: The number of bootstrap resamples.
        rng: The generator to draw from (advanced); default a fresh ``Generator(PCG64(0))``.
        level: The interval's coverage, in ``(0, 1)``.

    Returns:
        ``(low, high)``; ``(nan, nan)`` when there is no stratum or a stratum is empty.

    Raises:
        ValueError: Bad ``resamples`` or ``level``, a stratum not 1-D or with ``nan``, or a
            statistic that does not return one value per resample.

    >>> parts = [[1.0, 2.0, 3.0], [10.0, 20.0]]
    >>> low, high = stratified_bootstrap(parts, lambda s: np.concatenate(s, axis=1).mean(axis=1))
    >>> bool(low <= 7.2 <= high)
    True
    >>> stratified_bootstrap([[1.0], []], lambda s: s[0][:, 0])
    (nan, nan)
    """
    _check_bootstrap_arguments(resamples, level)
    arrays = [_as_values(stratum, f"stratum {index}") for index, stratum in enumerate(strata)]
    if not arrays or any(array.size == 0 for array in arrays):
        return _NAN, _NAN
    generator = default_rng() if rng is None else rng
    samples = [
        array[generator.integers(0, array.size, size=(resamples, array.size))] for array in arrays
    ]
    distribution = np.asarray(statistic(samples), dtype=np.float64)
    if distribution.shape != (resamples,):
        raise ValueError(
            f"the statistic must return one value per resample, shape ({resamples},); "
            f"got shape {distribution.shape} (vectorise it along axis 1)"
        )
    return _percentile_interval(distribution, level)


def bootstrap_interval(
    values: ArrayLike,
    statistic: RowStatistic,
    *,
    resamples: int = DEFAULT_RESAMPLES,
    rng: np.random.Generator | None = None,
    level: float = DEFAULT_LEVEL,
) -> tuple[float, float]:
    """Percentile bootstrap interval of a statistic over seeds (one stratum).

    Exactly: ``indices = rng.integers(0, n, size=(resamples, n))``, then
    ``np.percentile(statistic(values[indices]), [2.5, 97.5])`` for ``level = 0.95`` (see
    the module docstring). The same draw as :func:`stratified_bootstrap` with one stratum.

    Args:
        values: One score per run (1-D, no ``nan``).
        statistic: ``(resamples, n) -> (resamples,)``, e.g. :func:`iqm_rows`,
            :func:`median_rows` or ``lambda s: s.mean(axis=1)``.
        resamples: The number of bootstrap resamples.
        rng: The generator to draw from (advanced); default a fresh ``Generator(PCG64(0))``.
        level: The interval's coverage, in ``(0, 1)``.

    Returns:
        ``(low, high)``; ``(nan, nan)`` for no values.

    Raises:
        ValueError: See :func:`stratified_bootstrap`.

    >>> bootstrap_interval([7.0, 7.0, 7.0], median_rows)
    (7.0, 7.0)
    >>> low, high = bootstrap_interval([1.0, 2.0, 3.0, 4.0, 100.0], iqm_rows)
    >>> bool(1.0 <= low <= iqm([1.0, 2.0, 3.0, 4.0, 100.0]) <= high <= 100.0)
    True
    """
    return stratified_bootstrap(
        [values], lambda parts: statistic(parts[0]), resamples=resamples, rng=rng, level=level
    )


def iqm_interval(
    values: ArrayLike,
    *,
    resamples: int = DEFAULT_RESAMPLES,
    rng: np.random.Generator | None = None,
    level: float = DEFAULT_LEVEL,
) -> tuple[float, float, float]:
    """The IQM with its percentile bootstrap interval over seeds.

    Args:
        values: One score per run (1-D, no ``nan``).
        resamples: The number of bootstrap resamples.
        rng: The generator to draw from (advanced); default a fresh ``Generator(PCG64(0))``.
        level: The interval's coverage.

    Returns:
        ``(iqm, low, high)``; all ``nan`` for no values.

    >>> iqm_interval([500.0] * 4)
    (500.0, 500.0, 500.0)
    """
    low, high = bootstrap_interval(values, iqm_rows, resamples=resamples, rng=rng, level=level)
    return iqm(values), low, high


def median_interval(
    values: ArrayLike,
    *,
    resamples: int = DEFAULT_RESAMPLES,
    rng: np.random.Generator | None = None,
    level: float = DEFAULT_LEVEL,
) -> tuple[float, float, float]:
    """The median with its percentile bootstrap interval over seeds.

    Args:
        values: One value per run (1-D, no ``nan``); e.g. the solve episodes of the solved
            seeds only.
        resamples: The number of bootstrap resamples.
        rng: The generator to draw from (advanced); default a fresh ``Generator(PCG64(0))``.
        level: The interval's coverage.

    Returns:
        ``(median, low, high)``; all ``nan`` for no values (no solved seed).

    >>> median_interval([])
    (nan, nan, nan)
    >>> estimate, low, high = median_interval([250, 260, 240, 900, 255])
    >>> estimate, bool(240 <= low <= estimate <= high <= 900)
    (255.0, True)
    """
    low, high = bootstrap_interval(values, median_rows, resamples=resamples, rng=rng, level=level)
    return median(values), low, high


def mean_rows(samples: ArrayLike) -> FloatArray:
    """The mean of each row (resample): ``samples.mean(axis=1)``."""
    means: FloatArray = _as_matrix(samples).mean(axis=1)
    return means


def mean_interval(
    values: ArrayLike,
    *,
    resamples: int = DEFAULT_RESAMPLES,
    rng: np.random.Generator | None = None,
    level: float = DEFAULT_LEVEL,
) -> tuple[float, float, float]:
    """The mean (``np.mean``) with its percentile bootstrap interval over seeds.

    Returns:
        ``(mean, low, high)``; all ``nan`` for no values; the interval ``nan`` when a value
        is not finite (a diverged run's error).

    >>> mean_interval([0.1, float("inf")])
    (inf, nan, nan)
    >>> mean_interval([])
    (nan, nan, nan)
    >>> mean_interval([0.25, 0.25])
    (0.25, 0.25, 0.25)
    """
    array = np.asarray(values, dtype=np.float64)
    if not array.size:
        return _NAN, _NAN, _NAN
    if not np.all(np.isfinite(array)):  # a diverged run: the mean is not finite, no interval
        return float(np.mean(array)), _NAN, _NAN
    low, high = bootstrap_interval(array, mean_rows, resamples=resamples, rng=rng, level=level)
    return float(np.mean(array)), low, high


def aggregate_iqm(
    values_by_point: Sequence[ArrayLike],
    *,
    resamples: int = DEFAULT_RESAMPLES,
    rng: np.random.Generator | None = None,
    level: float = DEFAULT_LEVEL,
) -> tuple[float, float, float]:
    """The IQM over all runs of several points, with a stratified bootstrap interval.

    As rliable's ``aggregate_iqm``: the trimmed mean of all runs pooled, while the bootstrap
    resamples runs within each point. Points without runs are left out.

    Args:
        values_by_point: One 1-D array of run scores per point.
        resamples: The number of bootstrap resamples.
        rng: The generator to draw from (advanced); default a fresh ``Generator(PCG64(0))``.
        level: The interval's coverage.

    Returns:
        ``(iqm, low, high)``; all ``nan`` when no point has a run.

    >>> aggregate_iqm([[1.0, 1.0], [3.0, 3.0]])  # no spread within a point: no uncertainty
    (2.0, 2.0, 2.0)
    """
    arrays = [_as_values(values, f"point {i}") for i, values in enumerate(values_by_point)]
    arrays = [array for array in arrays if array.size]
    if not arrays:
        return _NAN, _NAN, _NAN
    low, high = stratified_bootstrap(
        arrays,
        lambda parts: iqm_rows(np.concatenate(parts, axis=1)),
        resamples=resamples,
        rng=rng,
        level=level,
    )
    return iqm(np.concatenate(arrays)), low, high


def probability_of_improvement(
    x: ArrayLike,
    y: ArrayLike,
    *,
    resamples: int = DEFAULT_RESAMPLES,
    rng: np.random.Generator | None = None,
    level: float = DEFAULT_LEVEL,
) -> tuple[float, float, float]:
    """``P(X > Y)``: how likely a random run of X beats a random run of Y, with an interval.

    rliable's probability of improvement for one task: ``mean over i, j of
    [x_i > y_j] + 0.5 [x_i == y_j]``, the Mann-Whitney ``U`` of ``x`` divided by ``n m``.
    ``P(X > Y) + P(Y > X) = 1``; 0.5 means neither is better. The interval is a stratified
    bootstrap with ``x`` and ``y`` resampled independently (rliable's
    ``StratifiedIndependentBootstrap``): the ``x`` index matrix is drawn first, then ``y``'s.

    Args:
        x: Run scores of X (1-D, no ``nan``).
        y: Run scores of Y (1-D, no ``nan``); the sizes may differ.
        resamples: The number of bootstrap resamples.
        rng: The generator to draw from (advanced); default a fresh ``Generator(PCG64(0))``.
        level: The interval's coverage.

    Returns:
        ``(estimate, low, high)``; all ``nan`` when ``x`` or ``y`` is empty.

    >>> probability_of_improvement([3, 4], [1, 2])
    (1.0, 1.0, 1.0)
    >>> probability_of_improvement([1, 2], [2, 3])[0]  # 1 pair tied, 3 lost of 4
    0.125
    """
    x_values = _as_values(x, "x")
    y_values = _as_values(y, "y")
    if x_values.size == 0 or y_values.size == 0:
        return _NAN, _NAN, _NAN
    estimate = float(improvement_rows(x_values[np.newaxis, :], y_values[np.newaxis, :])[0])
    low, high = stratified_bootstrap(
        [x_values, y_values],
        lambda parts: improvement_rows(parts[0], parts[1]),
        resamples=resamples,
        rng=rng,
        level=level,
    )
    return estimate, low, high


# ------------------------------------------------------------------- performance profiles


def performance_profile(scores_by_point: Sequence[ArrayLike], thresholds: ArrayLike) -> FloatArray:
    """The fraction of runs scoring more than each threshold, per point (for a plot).

    rliable's run-score distribution: ``profile[p, t] = mean over runs r of point p of
    [score_r > thresholds[t]]``; non-increasing in the threshold.

    Args:
        scores_by_point: One 1-D array of run scores per point (sizes may differ).
        thresholds: 1-D thresholds ``tau``.

    Returns:
        Shape ``(points, thresholds)``; a point without runs is a row of ``nan``.

    Raises:
        ValueError: Thresholds not 1-D or with ``nan``; scores not 1-D or with ``nan``.

    >>> performance_profile([[100, 300, 500, 500], []], [0, 300, 500]).tolist()
    [[1.0, 0.5, 0.0], [nan, nan, nan]]
    """
    taus = _as_values(thresholds, "thresholds")
    profile = np.full((len(scores_by_point), taus.size), _NAN)
    for row, scores in enumerate(scores_by_point):
        values = np.sort(_as_values(scores, f"point {row}"))
        if values.size:
            at_or_below = np.searchsorted(values, taus, side="right")
            profile[row] = (values.size - at_or_below) / values.size
    return profile


# ----------------------------------------------------------------------- a sweep point


@dataclasses.dataclass(frozen=True)
class PointStatistics:
    """The statistics of one sweep point: the ``points.csv`` columns after the axes.

    ``None`` is a missing value (an empty cell): no seeds, or no solved seed for the
    solve medians. Every interval is 95%; each bootstrap interval comes from its own
    fresh ``Generator(PCG64(0))`` with 2000 resamples, so a column does not depend on
    which other columns were computed, or in what order.
    """

    seeds: int
    """seeds with a row in ``results.csv``"""
    success_rate: float | None
    """fraction of seeds whose summary eval mean reached the threshold"""
    success_rate_low: float | None
    """95% Wilson interval, lower end"""
    success_rate_high: float | None
    """95% Wilson interval, upper end"""
    iqm_eval_return: float | None
    """interquartile mean of the seeds' eval means"""
    iqm_eval_return_low: float | None
    """95% percentile bootstrap interval over seeds, lower end"""
    iqm_eval_return_high: float | None
    """95% percentile bootstrap interval over seeds, upper end"""
    median_solved_episode: float | None
    """median solve episode over the solved seeds only"""
    median_solved_episode_low: float | None
    """95% percentile bootstrap interval over the solved seeds, lower end"""
    median_solved_episode_high: float | None
    """95% percentile bootstrap interval over the solved seeds, upper end"""
    median_env_steps_to_solve: float | None
    """median env steps through the solve episode, over the solved seeds only"""
    median_env_steps_to_solve_low: float | None
    """95% percentile bootstrap interval over the solved seeds, lower end"""
    median_env_steps_to_solve_high: float | None
    """95% percentile bootstrap interval over the solved seeds, upper end"""
    mean_rms_error: float | None = None
    """a prediction point's mean over seeds of the RMS error after the last episode"""
    mean_rms_error_low: float | None = None
    """95% percentile bootstrap interval over the seeds, lower end"""
    mean_rms_error_high: float | None = None
    """95% percentile bootstrap interval over the seeds, upper end"""

    @classmethod
    def columns(cls) -> tuple[str, ...]:
        """The ``points.csv`` column names, in order.

        Returns:
            The field names.

        >>> PointStatistics.columns()[:4]
        ('seeds', 'success_rate', 'success_rate_low', 'success_rate_high')
        """
        return tuple(field.name for field in dataclasses.fields(cls))

    def as_row(self) -> dict[str, int | float | None]:
        """The values by column name, in :meth:`columns` order (``None`` = empty cell).

        Returns:
            A new dictionary.
        """
        return {name: getattr(self, name) for name in self.columns()}


def summarize_point(
    eval_means: Sequence[float],
    successes: Sequence[bool] | None,
    solved_episodes: Sequence[float | None],
    env_steps_to_solve: Sequence[float | None],
    threshold: float | None = None,
    *,
    resamples: int = DEFAULT_RESAMPLES,
    rms_errors: Sequence[float] = (),
) -> PointStatistics:
    """The ``points.csv`` statistics of one point, from its seeds' ``results.csv`` rows.

    Each bootstrap (IQM, the two medians) uses its own fresh ``Generator(PCG64(0))``, so
    the columns are independent of each other and of the order they are computed in.

    Args:
        eval_means: Each seed's summary eval mean, one per seed with a row.
        successes: Each seed's ``success``; when ``None``, ``eval_mean >= threshold``.
            When given, it is used as is and ``threshold`` is not consulted.
        solved_episodes: Each seed's solve episode; ``None`` (or ``nan``) = not solved.
        env_steps_to_solve: Each seed's env steps through its solve episode; ``None`` (or
            ``nan``) = not solved.
        threshold: The eval-mean success threshold, needed only without ``successes``.
        resamples: Bootstrap resamples per interval (the contract's 2000 by default).
        rms_errors: A prediction point's seeds' final RMS errors (none for control).

    Returns:
        The point's statistics; ``None`` where a value is missing.

    Raises:
        ValueError: Sequences of different lengths, ``nan`` in ``eval_means``, or neither
            ``successes`` nor ``threshold``.

    >>> stats = summarize_point([500.0, 480.0, 20.0], None, [250, 300, None], [5e4, 6e4, None], 475.0)
    >>> stats.seeds, round(stats.success_rate, 3), stats.median_solved_episode
    (3, 0.667, 275.0)
    >>> summarize_point([], [], [], []).as_row()["iqm_eval_return"] is None
    True
    """
    means = _as_values(eval_means, "eval_means")
    seeds = means.size
    lengths = {
        "successes": seeds if successes is None else len(successes),
        "solved_episodes": len(solved_episodes),
        "env_steps_to_solve": len(env_steps_to_solve),
    }
    for name, length in lengths.items():
        if length != seeds:
            raise ValueError(f"{name} has {length} values for {seeds} eval_means")
    if successes is None:
        if threshold is None:
            raise ValueError("summarize_point needs successes or a threshold")
        success_count = int(np.count_nonzero(means >= threshold))
    else:
        success_count = sum(bool(success) for success in successes)

    rate = success_count / seeds if seeds else _NAN
    rate_low, rate_high = wilson_interval(success_count, seeds)
    iqm_estimate, iqm_low, iqm_high = iqm_interval(means, resamples=resamples)
    episode, episode_low, episode_high = median_interval(
        _solved_only(solved_episodes), resamples=resamples
    )
    steps, steps_low, steps_high = median_interval(
        _solved_only(env_steps_to_solve), resamples=resamples
    )
    error, error_low, error_high = mean_interval(rms_errors, resamples=resamples)
    return PointStatistics(
        seeds=seeds,
        success_rate=_missing(rate),
        success_rate_low=_missing(rate_low),
        success_rate_high=_missing(rate_high),
        iqm_eval_return=_missing(iqm_estimate),
        iqm_eval_return_low=_missing(iqm_low),
        iqm_eval_return_high=_missing(iqm_high),
        median_solved_episode=_missing(episode),
        median_solved_episode_low=_missing(episode_low),
        median_solved_episode_high=_missing(episode_high),
        median_env_steps_to_solve=_missing(steps),
        median_env_steps_to_solve_low=_missing(steps_low),
        median_env_steps_to_solve_high=_missing(steps_high),
        mean_rms_error=_missing(error),
        mean_rms_error_low=_missing(error_low),
        mean_rms_error_high=_missing(error_high),
    )


# -------------------------------------------------------------------------------- helpers


def _as_values(values: ArrayLike, name: str = "values") -> FloatArray:
    """``values`` as a 1-D float64 array, refusing ``nan`` (a missing value is left out)."""
    array = np.asarray(values, dtype=np.float64)
    if array.ndim != 1:
        raise ValueError(f"{name} must be 1-D, got shape {array.shape}")
    if np.isnan(array).any():
        raise ValueError(f"{name} contains nan: leave missing values out instead")
    return array


def _as_matrix(samples: ArrayLike) -> FloatArray:
    """``samples`` as a 2-D float64 array (rows = resamples)."""
    matrix = np.asarray(samples, dtype=np.float64)
    if matrix.ndim != 2:
        raise ValueError(f"samples must be 2-D (resamples, runs), got shape {matrix.shape}")
    return matrix


def _check_bootstrap_arguments(resamples: int, level: float) -> None:
    if operator.index(resamples) < 1:
        raise ValueError(f"resamples must be >= 1, got {resamples}")
    if not 0.0 < level < 1.0:
        raise ValueError(f"level must be in (0, 1), got {level}")


def _percentile_interval(distribution: FloatArray, level: float) -> tuple[float, float]:
    # (100 - 100 * level) / 2 rather than 50 * (1 - level): for level = 0.95 the former is
    # exactly 2.5 (and 97.5), the latter 2.500000000000002.
    low, high = np.percentile(
        distribution, [(100.0 - 100.0 * level) / 2, (100.0 + 100.0 * level) / 2]
    )
    return float(low), float(high)


def _solved_only(values: Sequence[float | None]) -> FloatArray:
    """The values of solved seeds: ``None`` and ``nan`` (not solved) left out."""
    present = np.array([value for value in values if value is not None], dtype=np.float64)
    return present[~np.isnan(present)]


def _missing(value: float) -> float | None:
    """``nan`` becomes ``None`` (an empty cell)."""
    return None if math.isnan(value) else value
