"""The binning rule: hand-computed edges, clipping, ignored dimensions, and the contract."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from cartpole_q.engines.compile import jit
from cartpole_q.rl.binning import bin_indices, state_index

# One dimension over [-1, 1] with 4 bins has edges at -0.5, 0 and 0.5.
LOW, HIGH, BINS = -1.0, 1.0, 4


@pytest.mark.parametrize(
    ("x", "expected"),
    [
        (-1.0, 0),  # the low edge itself
        (-0.5000001, 0),
        (-0.5, 1),  # an inner edge belongs to the bin above it
        (-0.25, 1),
        (0.0, 2),
        (0.4999999, 2),
        (0.5, 3),
        (0.999, 3),
        (1.0, 3),  # the high edge is clipped into the last bin
        (1.5, 3),  # above the bounds
        (-7.0, 0),  # below the bounds
        (np.inf, 3),
        (-np.inf, 0),
        (np.nan, 0),
    ],
)
def test_bin_edges_and_clipping(x: float, expected: int) -> None:
    assert state_index([x], [LOW], [HIGH], [BINS]) == expected
    assert (
        jit(state_index)(np.array([x]), np.array([LOW]), np.array([HIGH]), np.array([BINS]))
        == expected
    )


def test_float32_observation_is_widened_before_binning() -> None:
    # 0.1 as float32 is 0.100000001490116...; with 10 bins over [0, 1] it lands in bin 1,
    # and widening keeps it there (no rounding back to a float64 0.1).
    observation = np.array([0.1], dtype=np.float32)
    assert state_index(observation, [0.0], [1.0], [10]) == 1
    assert float(observation[0]) > 0.1


def test_dimensions_with_one_bin_are_ignored() -> None:
    low, high, bins = [-1.0, -1.0, -1.0], [1.0, 1.0, 1.0], [1, 4, 3]
    # the first coordinate never changes the row, whatever its value
    for first in (-100.0, 0.0, 0.99, np.nan):
        assert state_index([first, 0.25, 0.9], low, high, bins) == 2 * 3 + 2
    assert bin_indices([5.0, 0.25, 0.9], low, high, bins) == (0, 2, 2)


def test_flat_row_is_c_order_of_the_bin_indices() -> None:
    low, high, bins = [-2.4, -3.0, -0.2, -3.5], [2.4, 3.0, 0.2, 3.5], [3, 2, 6, 12]
    observation = np.array([1.0, -0.5, 0.05, 2.0], dtype=np.float32)
    indices = bin_indices(observation, low, high, bins)
    # (1+2.4)/4.8*3 = 2.125, (-0.5+3)/6*2 = 0.83, (0.05+0.2)/0.4*6 = 3.75, (2+3.5)/7*12 = 9.43
    assert indices == (2, 0, 3, 9)
    assert state_index(observation, low, high, bins) == np.ravel_multi_index(indices, bins)


def contract_rule(
    observation: np.ndarray, low: np.ndarray, high: np.ndarray, bins: np.ndarray
) -> tuple:
    """The run-directory contract's formula, written with NumPy as another tool would."""
    x = observation.astype(np.float32).astype(np.float64)
    index = np.clip(np.floor((x - low) / (high - low) * bins), 0, bins - 1).astype(np.int64)
    return tuple(int(i) for i in index)


finite = st.floats(-1e6, 1e6, allow_nan=False, width=32)


@given(
    st.lists(st.tuples(finite, finite, st.integers(1, 50), finite), min_size=1, max_size=6).filter(
        lambda dims: all(lo < hi for lo, hi, _, _ in dims)
    )
)
def test_both_implementations_follow_the_contract(
    dims: list[tuple[float, float, int, float]],
) -> None:
    low = np.array([d[0] for d in dims], dtype=np.float64)
    high = np.array([d[1] for d in dims], dtype=np.float64)
    bins = np.array([d[2] for d in dims], dtype=np.int64)
    observation = np.array([d[3] for d in dims], dtype=np.float32)
    expected = contract_rule(observation, low, high, bins)
    assert bin_indices(observation, low, high, bins) == expected
    flat = int(np.ravel_multi_index(expected, bins))
    assert state_index(observation, low, high, bins) == flat
    assert state_index(observation, low.tolist(), high.tolist(), bins.tolist()) == flat
    assert jit(state_index)(observation, low, high, bins) == flat


def test_property_tests_have_no_deadline() -> None:
    # A cold numba cache makes the first example slow (issue: DeadlineExceeded on a fresh
    # clone); the suite's Hypothesis profile must not time examples.
    from hypothesis import settings

    assert settings().deadline is None
