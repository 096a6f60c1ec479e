"""Sweep statistics: hand-computed values, scipy where it has the same estimator, properties.

scipy is a test-only dependency: the package computes everything with numpy.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.stats
from hypothesis import given, settings
from hypothesis import strategies as st

from cartpole_q import statistics
from cartpole_q.statistics import (
    PointStatistics,
    aggregate_iqm,
    bootstrap_interval,
    default_rng,
    improvement_rows,
    iqm,
    iqm_interval,
    iqm_rows,
    median_interval,
    median_rows,
    performance_profile,
    probability_of_improvement,
    stratified_bootstrap,
    summarize_point,
    wilson_interval,
)

Z = 1.959963984540054
Z2 = Z * Z  # 3.8414588206941254

scores = st.floats(min_value=-1e6, max_value=1e6, allow_nan=False, allow_infinity=False)
score_lists = st.lists(scores, min_size=1, max_size=40)
# Few distinct values: many ties, where P(X > Y) and the medians are easiest to get wrong.
tied_lists = st.lists(st.integers(min_value=0, max_value=4), min_size=1, max_size=25)


def pairwise_improvement(x: np.ndarray, y: np.ndarray) -> float:
    """The definition of P(X > Y), pair by pair."""
    x = np.asarray(x, dtype=np.float64)[:, None]
    y = np.asarray(y, dtype=np.float64)[None, :]
    return float(((x > y).sum() + 0.5 * (x == y).sum()) / (x.size * y.size))


# --------------------------------------------------------------------------------- Wilson


@pytest.mark.parametrize(
    ("successes", "n", "expected"),
    [
        # k = 0: center = (z²/2) / (n + z²) and delta = z/(2(n + z²)) · sqrt(z²) is the same,
        # so low = 0 and high = z² / (n + z²) = 3.8414588 / 13.8414588 = 0.2775327998628892.
        (0, 10, (0.0, Z2 / (10 + Z2))),
        # k = n: the mirror image, low = n / (n + z²) = 10 / 13.8414588 = 0.7224672001371107.
        (10, 10, (10 / (10 + Z2), 1.0)),
        # k = n/2: center = 1/2, delta = z/(2(n + z²)) · sqrt(n + z²) = z / (2 sqrt(n + z²))
        # = 1.9599640 / (2 · 3.7204111) = 0.2634069094874361.
        (5, 10, (0.5 - Z / (2 * math.sqrt(10 + Z2)), 0.5 + Z / (2 * math.sqrt(10 + Z2)))),
        # n = 1, k = 1: low = 1 / (1 + z²) = 1 / 4.8414588 = 0.2065493143772374.
        (1, 1, (1 / (1 + Z2), 1.0)),
    ],
)
def test_wilson_hand_computed(successes: int, n: int, expected: tuple[float, float]) -> None:
    low, high = wilson_interval(successes, n)
    assert low == pytest.approx(expected[0], abs=1e-15)
    assert high == pytest.approx(expected[1], abs=1e-15)


def test_wilson_hand_computed_figures() -> None:
    # The closed forms above, evaluated by hand to 7 digits.
    assert wilson_interval(0, 10)[1] == pytest.approx(0.2775328, abs=1e-7)
    assert wilson_interval(10, 10)[0] == pytest.approx(0.7224672, abs=1e-7)
    assert wilson_interval(5, 10) == pytest.approx((0.2365931, 0.7634069), abs=1e-7)
    assert wilson_interval(1, 1)[0] == pytest.approx(0.2065493, abs=1e-7)


def test_wilson_extremes_are_exact() -> None:
    # The closed form gives 0 and 1 only up to rounding; the interval must contain k / n.
    assert wilson_interval(0, 37)[0] == 0.0
    assert wilson_interval(37, 37)[1] == 1.0


def test_wilson_without_seeds_is_nan() -> None:
    low, high = wilson_interval(0, 0)
    assert math.isnan(low) and math.isnan(high)


@pytest.mark.parametrize(
    ("successes", "n", "error"),
    [
        (-1, 10, ValueError),
        (11, 10, ValueError),
        (0, -1, ValueError),
        (0.5, 10, TypeError),
    ],
)
def test_wilson_refuses_bad_counts(successes: int, n: int, error: type[Exception]) -> None:
    with pytest.raises(error):
        wilson_interval(successes, n)


@pytest.mark.parametrize("z", [0.0, -1.0, math.inf, math.nan])
def test_wilson_refuses_bad_z(z: float) -> None:
    with pytest.raises(ValueError, match="z"):
        wilson_interval(3, 10, z)


def test_wilson_accepts_numpy_integers() -> None:
    assert wilson_interval(np.int64(5), np.int64(10)) == wilson_interval(5, 10)


@pytest.mark.parametrize(("successes", "n"), [(0, 1), (1, 2), (3, 7), (97, 100), (5, 10), (0, 100)])
def test_wilson_equals_scipy(successes: int, n: int) -> None:
    scipy_interval = scipy.stats.binomtest(successes, n).proportion_ci(method="wilson")
    assert wilson_interval(successes, n) == pytest.approx(
        (scipy_interval.low, scipy_interval.high), abs=1e-15
    )


def test_scipy_wilson_is_the_formula_without_continuity_correction() -> None:
    # Wilson (1927) as usually printed: (p + z²/2n ± z sqrt(p q / n + z²/4n²)) / (1 + z²/n).
    successes, n = 7, 20
    p = successes / n
    half = Z * math.sqrt(p * (1 - p) / n + Z2 / (4 * n * n))
    textbook = ((p + Z2 / (2 * n) - half) / (1 + Z2 / n), (p + Z2 / (2 * n) + half) / (1 + Z2 / n))
    plain = scipy.stats.binomtest(successes, n).proportion_ci(method="wilson")
    corrected = scipy.stats.binomtest(successes, n).proportion_ci(method="wilsoncc")
    assert (plain.low, plain.high) == pytest.approx(textbook, abs=1e-15)
    assert corrected.low < plain.low and corrected.high > plain.high
    assert wilson_interval(successes, n) == pytest.approx(textbook, abs=1e-15)


@given(
    st.integers(min_value=1, max_value=100_000).flatmap(
        lambda n: st.tuples(st.integers(min_value=0, max_value=n), st.just(n))
    )
)
def test_wilson_contains_the_proportion(counts: tuple[int, int]) -> None:
    successes, n = counts
    low, high = wilson_interval(successes, n)
    assert 0.0 <= low <= successes / n <= high <= 1.0
    scipy_interval = scipy.stats.binomtest(successes, n).proportion_ci(method="wilson")
    assert (low, high) == pytest.approx((scipy_interval.low, scipy_interval.high), abs=1e-12)


# ------------------------------------------------------------------------------------ IQM


@pytest.mark.parametrize(
    ("values", "expected"),
    [
        (list(range(1, 9)), 4.5),  # n = 8: cut 2 each end, mean(3, 4, 5, 6)
        ([1, 2, 3, 4, 100], 3.0),  # n = 5: cut int(1.25) = 1, mean(2, 3, 4)
        ([4, 1, 100, 2], 3.0),  # n = 4: cut 1, mean(2, 4): the order does not matter
        ([1, 2, 30], 11.0),  # n = 3: cut int(0.75) = 0, the plain mean
        ([7.5], 7.5),
        (list(range(1, 13)), 6.5),  # n = 12: cut 3, mean(4..9)
        ([0, 0, 500, 500, 500, 500, 500, 500], 500.0),  # two failed seeds are cut
    ],
)
def test_iqm_hand_computed(values: list[float], expected: float) -> None:
    assert iqm(values) == expected
    assert iqm(values) == pytest.approx(scipy.stats.trim_mean(values, 0.25), abs=0)


def test_iqm_empty_is_nan() -> None:
    assert math.isnan(iqm([]))
    assert np.isnan(iqm_rows(np.zeros((3, 0)))).all()


@pytest.mark.parametrize("bad", [[1.0, math.nan], [[1.0, 2.0]]])
def test_iqm_refuses_nan_and_matrices(bad: list[float] | list[list[float]]) -> None:
    with pytest.raises(ValueError):
        iqm(bad)


@given(score_lists)
def test_iqm_equals_scipy_trim_mean(values: list[float]) -> None:
    assert iqm(values) == pytest.approx(scipy.stats.trim_mean(values, 0.25), rel=1e-12, abs=1e-9)


@given(st.lists(st.integers(min_value=-1000, max_value=1000), min_size=1, max_size=40))
def test_iqm_of_integers_equals_scipy_exactly(values: list[int]) -> None:
    # Sums of small integers are exact, so sort-then-mean and scipy's partition agree bitwise.
    assert iqm(values) == scipy.stats.trim_mean(values, 0.25)


@given(score_lists)
def test_iqm_lies_between_min_and_max(values: list[float]) -> None:
    # Up to the rounding of a mean: np.mean([0.1] * 3) is 0.10000000000000002.
    slack = 1e-12 * max(1.0, max(abs(v) for v in values))
    assert min(values) - slack <= iqm(values) <= max(values) + slack


@given(
    st.lists(score_lists, min_size=1, max_size=5).filter(
        lambda rows: len({len(r) for r in rows}) == 1
    )
)
def test_row_statistics_equal_the_scalar_ones(rows: list[list[float]]) -> None:
    matrix = np.array(rows)
    assert iqm_rows(matrix).tolist() == [iqm(row) for row in rows]
    assert median_rows(matrix).tolist() == [float(np.median(row)) for row in rows]


# ------------------------------------------------------------------------------ bootstrap


VALUES = np.array([12.0, 480.0, 500.0, 500.0, 131.0, 500.0, 475.5, 9.0, 500.0, 322.0, 488.0])


def test_bootstrap_reproduced_independently() -> None:
    # The documented draw, written out: one index matrix, statistic per row, percentiles.
    rng = np.random.Generator(np.random.PCG64(0))
    indices = rng.integers(0, VALUES.size, size=(2000, VALUES.size))
    medians = [np.median(VALUES[row]) for row in indices]
    expected = tuple(np.percentile(medians, [2.5, 97.5]))
    assert bootstrap_interval(VALUES, median_rows) == expected

    trimmed = [scipy.stats.trim_mean(VALUES[row], 0.25) for row in indices]
    low, high = bootstrap_interval(VALUES, iqm_rows)
    assert (low, high) == pytest.approx(tuple(np.percentile(trimmed, [2.5, 97.5])), rel=1e-12)


def test_bootstrap_default_generator_is_pcg64_zero() -> None:
    explicit = bootstrap_interval(VALUES, iqm_rows, rng=np.random.Generator(np.random.PCG64(0)))
    assert bootstrap_interval(VALUES, iqm_rows) == explicit
    assert bootstrap_interval(VALUES, iqm_rows, rng=default_rng()) == explicit


def test_bootstrap_advances_a_given_generator() -> None:
    rng = default_rng()
    first = bootstrap_interval(VALUES, iqm_rows, rng=rng)
    second = bootstrap_interval(VALUES, iqm_rows, rng=rng)
    assert first == bootstrap_interval(VALUES, iqm_rows)
    assert second != first


@settings(max_examples=50)
@given(score_lists, st.integers(min_value=0, max_value=2**32))
def test_bootstrap_is_deterministic(values: list[float], seed: int) -> None:
    def interval() -> tuple[float, float]:
        rng = np.random.Generator(np.random.PCG64(seed))
        return bootstrap_interval(values, iqm_rows, resamples=200, rng=rng)

    assert interval() == interval()


@settings(max_examples=50)
@given(score_lists)
def test_bootstrap_interval_is_ordered_and_within_the_data(values: list[float]) -> None:
    for statistic in (iqm_rows, median_rows):
        low, high = bootstrap_interval(values, statistic, resamples=200)
        slack = 1e-12 * max(1.0, max(abs(v) for v in values))
        assert min(values) - slack <= low <= high <= max(values) + slack


def test_bootstrap_of_constant_values_is_a_point() -> None:
    assert bootstrap_interval([3.0] * 5, iqm_rows) == (3.0, 3.0)
    assert bootstrap_interval([3.0], median_rows) == (3.0, 3.0)


def test_bootstrap_empty_is_nan() -> None:
    low, high = bootstrap_interval([], iqm_rows)
    assert math.isnan(low) and math.isnan(high)


def test_bootstrap_level() -> None:
    narrow = bootstrap_interval(VALUES, median_rows, level=0.5)
    wide = bootstrap_interval(VALUES, median_rows, level=0.99)
    default = bootstrap_interval(VALUES, median_rows)
    assert wide[0] <= default[0] <= narrow[0] <= narrow[1] <= default[1] <= wide[1]


@pytest.mark.parametrize(
    ("keywords", "match"),
    [({"resamples": 0}, "resamples"), ({"level": 1.0}, "level"), ({"level": 0.0}, "level")],
)
def test_bootstrap_refuses_bad_arguments(keywords: dict[str, float], match: str) -> None:
    with pytest.raises(ValueError, match=match):
        bootstrap_interval(VALUES, iqm_rows, **keywords)  # type: ignore[arg-type]


def test_bootstrap_refuses_a_statistic_that_is_not_vectorised() -> None:
    with pytest.raises(ValueError, match="one value per resample"):
        bootstrap_interval(VALUES, np.median)


def test_bootstrap_loosely_agrees_with_scipy() -> None:
    # scipy.stats.bootstrap draws differently: only the intervals' scale can agree.
    values = np.random.Generator(np.random.PCG64(1)).normal(100.0, 10.0, size=60)
    ours = bootstrap_interval(values, lambda s: s.mean(axis=1))
    theirs = scipy.stats.bootstrap(
        (values,),
        np.mean,
        method="percentile",
        n_resamples=2000,
        random_state=np.random.default_rng(2),
    ).confidence_interval
    width = theirs.high - theirs.low
    assert ours[0] == pytest.approx(theirs.low, abs=0.15 * width)
    assert ours[1] == pytest.approx(theirs.high, abs=0.15 * width)


# ----------------------------------------------------------------- stratified bootstrap


def test_one_stratum_is_the_plain_bootstrap() -> None:
    plain = bootstrap_interval(VALUES, iqm_rows)
    assert stratified_bootstrap([VALUES], lambda parts: iqm_rows(parts[0])) == plain


def test_stratified_bootstrap_reproduced_independently() -> None:
    first, second = VALUES[:4], VALUES[4:]
    rng = np.random.Generator(np.random.PCG64(0))
    first_indices = rng.integers(0, first.size, size=(2000, first.size))
    second_indices = rng.integers(0, second.size, size=(2000, second.size))
    pooled = [
        np.mean(np.sort(np.concatenate([first[a], second[b]]))[2:-2])  # n = 11: cut 2
        for a, b in zip(first_indices, second_indices, strict=True)
    ]
    expected = np.percentile(pooled, [2.5, 97.5])
    interval = stratified_bootstrap(
        [first, second], lambda parts: iqm_rows(np.concatenate(parts, axis=1))
    )
    assert interval == pytest.approx(tuple(expected), rel=1e-12)


def test_stratified_bootstrap_resamples_within_each_stratum() -> None:
    # Every resample keeps three 0s-from-the-first-point and two 1s: the pooled mean never
    # moves. A bootstrap over the pooled runs would give an interval around 0.4.
    interval = stratified_bootstrap(
        [[0.0, 0.0, 0.0], [1.0, 1.0]], lambda parts: np.concatenate(parts, axis=1).mean(axis=1)
    )
    assert interval == pytest.approx((0.4, 0.4), abs=1e-15)


def test_stratified_bootstrap_with_an_empty_stratum_is_nan() -> None:
    for strata in ([], [[1.0, 2.0], []]):
        low, high = stratified_bootstrap(strata, lambda parts: parts[0][:, 0])
        assert math.isnan(low) and math.isnan(high)


def test_aggregate_iqm() -> None:
    points = [[0.0, 500.0, 480.0, 20.0], [500.0, 500.0, 9.0], [], [300.0, 320.0]]
    estimate, low, high = aggregate_iqm(points)
    pooled = np.concatenate([np.asarray(p, dtype=float) for p in points])
    assert estimate == pytest.approx(scipy.stats.trim_mean(pooled, 0.25), abs=0)
    assert low <= estimate <= high
    # The empty point is left out: the same draw as without it.
    assert aggregate_iqm([p for p in points if p]) == (estimate, low, high)
    assert all(math.isnan(v) for v in aggregate_iqm([[], []]))


# -------------------------------------------------------------- probability of improvement


@given(tied_lists, tied_lists)
def test_improvement_equals_the_pairwise_definition(x: list[int], y: list[int]) -> None:
    estimate = improvement_rows([x], [y])[0]
    assert estimate == pairwise_improvement(np.array(x), np.array(y))


@given(score_lists, score_lists)
def test_improvement_equals_scipy_mann_whitney(x: list[float], y: list[float]) -> None:
    u = scipy.stats.mannwhitneyu(x, y).statistic  # U of the first sample, ties count 1/2
    estimate = probability_of_improvement(x, y, resamples=1)[0]
    assert estimate == pytest.approx(u / (len(x) * len(y)), abs=1e-15)


@given(tied_lists, tied_lists)
def test_improvement_is_complementary(x: list[int], y: list[int]) -> None:
    forward = probability_of_improvement(x, y, resamples=1)[0]
    backward = probability_of_improvement(y, x, resamples=1)[0]
    assert forward + backward == pytest.approx(1.0, abs=1e-15)
    assert 0.0 <= forward <= 1.0


@pytest.mark.parametrize(
    ("x", "y", "expected"),
    [
        ([3, 4], [1, 2], 1.0),
        ([1, 2], [3, 4], 0.0),
        ([1, 2, 3], [1, 2, 3], 0.5),  # identical runs: neither is better
        ([1, 2], [2, 3], 0.125),  # of 4 pairs: one tie (2, 2), three lost
        ([500, 500, 0], [480], 2 / 3),
    ],
)
def test_improvement_hand_computed(x: list[float], y: list[float], expected: float) -> None:
    assert probability_of_improvement(x, y)[0] == pytest.approx(expected, abs=1e-15)


def test_improvement_interval_reproduced_independently() -> None:
    x, y = VALUES[:6], VALUES[6:]
    rng = np.random.Generator(np.random.PCG64(0))
    x_indices = rng.integers(0, x.size, size=(2000, x.size))  # x first, then y
    y_indices = rng.integers(0, y.size, size=(2000, y.size))
    distribution = [
        pairwise_improvement(x[a], y[b]) for a, b in zip(x_indices, y_indices, strict=True)
    ]
    estimate, low, high = probability_of_improvement(x, y)
    assert estimate == pairwise_improvement(x, y)
    assert (low, high) == tuple(np.percentile(distribution, [2.5, 97.5]))
    assert low <= estimate <= high


def test_improvement_blocks_do_not_change_the_result(monkeypatch: pytest.MonkeyPatch) -> None:
    rng = np.random.Generator(np.random.PCG64(3))
    x = rng.integers(0, 5, size=(50, 7)).astype(float)
    y = rng.integers(0, 5, size=(50, 4)).astype(float)
    whole = improvement_rows(x, y)
    monkeypatch.setattr(statistics, "_RANK_BLOCK_ELEMENTS", 30)  # 2 rows at a time
    assert improvement_rows(x, y).tolist() == whole.tolist()
    assert whole.tolist() == [pairwise_improvement(a, b) for a, b in zip(x, y, strict=True)]


def test_improvement_with_no_runs_is_nan() -> None:
    assert all(math.isnan(v) for v in probability_of_improvement([], [1.0]))
    assert all(math.isnan(v) for v in probability_of_improvement([1.0], []))
    assert improvement_rows(np.zeros((0, 2)), np.zeros((0, 3))).shape == (0,)
    with pytest.raises(ValueError, match="rows"):
        improvement_rows(np.zeros((2, 2)), np.zeros((3, 2)))


# ---------------------------------------------------------------------- performance profile


def test_performance_profile_hand_computed() -> None:
    profile = performance_profile([[100, 300, 500, 500], [500], []], [0, 100, 300, 499.9, 500])
    expected = [
        [1.0, 0.75, 0.5, 0.5, 0.0],  # strictly above: a score equal to tau does not count
        [1.0, 1.0, 1.0, 1.0, 0.0],
    ]
    assert profile[:2].tolist() == expected
    assert np.isnan(profile[2]).all()


@given(st.lists(tied_lists, min_size=1, max_size=4), st.lists(st.floats(-1, 6), max_size=8))
def test_performance_profile_is_the_run_score_distribution(
    points: list[list[int]], thresholds: list[float]
) -> None:
    profile = performance_profile(points, thresholds)
    assert profile.shape == (len(points), len(thresholds))
    for row, runs in zip(profile, points, strict=True):
        brute = [np.mean(np.array(runs) > tau) for tau in thresholds]
        assert row.tolist() == brute
    ascending = np.sort(np.asarray(thresholds))
    assert (np.diff(performance_profile(points, ascending), axis=1) <= 0).all()


# ------------------------------------------------------------------------------- medians


def test_median_interval_hand_computed() -> None:
    estimate, low, high = median_interval([250, 260, 240, 900, 255])
    assert estimate == 255.0
    assert 240.0 <= low <= 255.0 <= high <= 900.0
    assert median_interval([4, 4, 4]) == (4.0, 4.0, 4.0)
    assert all(math.isnan(v) for v in median_interval([]))


# -------------------------------------------------------------------------- summarize_point


DESIGN_COLUMNS = (
    "seeds",
    "success_rate",
    "success_rate_low",
    "success_rate_high",
    "iqm_eval_return",
    "iqm_eval_return_low",
    "iqm_eval_return_high",
    "median_solved_episode",
    "median_solved_episode_low",
    "median_solved_episode_high",
    "median_env_steps_to_solve",
    "median_env_steps_to_solve_low",
    "median_env_steps_to_solve_high",
)


def test_point_columns_are_the_contract() -> None:
    # design.md's columns, then the ones added since (a prediction point's error)
    assert PointStatistics.columns() == (*DESIGN_COLUMNS, *PREDICTION_COLUMNS)


PREDICTION_COLUMNS = ("mean_rms_error", "mean_rms_error_low", "mean_rms_error_high")


def test_summarize_point_is_the_functions_each_with_a_fresh_generator() -> None:
    eval_means = [500.0, 480.0, 20.0, 500.0, 9.5, 475.0]
    solved = [250, 300, None, 410, None, float("nan")]
    steps = [5.1e4, 6.3e4, None, 8.0e4, None, None]
    stats = summarize_point(eval_means, None, solved, steps, 475.0)

    # Each column alone, in another order, with its own Generator(PCG64(0)).
    steps_column = median_interval([5.1e4, 6.3e4, 8.0e4])
    episode_column = median_interval([250, 300, 410])
    iqm_column = iqm_interval(eval_means)
    assert stats.as_row() == {
        "seeds": 6,
        "success_rate": 4 / 6,  # 475.0 >= 475.0 counts
        "success_rate_low": wilson_interval(4, 6)[0],
        "success_rate_high": wilson_interval(4, 6)[1],
        "iqm_eval_return": iqm_column[0],
        "iqm_eval_return_low": iqm_column[1],
        "iqm_eval_return_high": iqm_column[2],
        "median_solved_episode": 300.0,
        "median_solved_episode_low": episode_column[1],
        "median_solved_episode_high": episode_column[2],
        "median_env_steps_to_solve": 6.3e4,
        "median_env_steps_to_solve_low": steps_column[1],
        "median_env_steps_to_solve_high": steps_column[2],
        # a control point has no error
        "mean_rms_error": None,
        "mean_rms_error_low": None,
        "mean_rms_error_high": None,
    }
    assert list(stats.as_row()) == [*DESIGN_COLUMNS, *PREDICTION_COLUMNS]


def test_a_prediction_points_error_is_the_mean_over_seeds_with_a_bootstrap_interval() -> None:
    errors = [0.05, 0.07, 0.02, 0.04]
    stats = summarize_point([], [], [], [], rms_errors=errors)
    assert stats.mean_rms_error == float(np.mean(errors))
    low, high = bootstrap_interval(errors, lambda s: np.asarray(s).mean(axis=1))
    assert (stats.mean_rms_error_low, stats.mean_rms_error_high) == (low, high)
    diverged = summarize_point([], [], [], [], rms_errors=[0.05, float("inf")])
    assert diverged.mean_rms_error == float("inf") and diverged.mean_rms_error_low is None


def test_summarize_point_uses_given_successes() -> None:
    stats = summarize_point([500.0, 10.0], [False, True], [None, None], [None, None], 475.0)
    assert stats.success_rate == 0.5
    assert stats.median_solved_episode is None
    assert stats.median_env_steps_to_solve_high is None
    assert stats.iqm_eval_return == 255.0


def test_summarize_point_without_seeds_is_all_missing() -> None:
    row = summarize_point([], [], [], []).as_row()
    assert row.pop("seeds") == 0
    assert set(row.values()) == {None}


def test_summarize_point_refuses_inconsistent_input() -> None:
    with pytest.raises(ValueError, match="solved_episodes has 1 values for 2"):
        summarize_point([1.0, 2.0], [True, True], [None], [None, None])
    with pytest.raises(ValueError, match="successes has 3 values"):
        summarize_point([1.0, 2.0], [True, True, False], [None, None], [None, None])
    with pytest.raises(ValueError, match="threshold"):
        summarize_point([1.0], None, [None], [None])
    with pytest.raises(ValueError, match="nan"):
        summarize_point([math.nan], [True], [None], [None])
