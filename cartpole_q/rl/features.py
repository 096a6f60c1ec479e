"""Linear features: the one layer every linear method reads (Sutton & Barto 9.4-9.5).

A layer gives each state ``s`` of a world's table its **row**: ``K`` pairs ``(index[s, j],
value[s, j])`` of a weight's index and the feature's value, so that ``v̂(s, w) = sum_j
w[index[s, j]] * value[s, j]`` (summed in row order from 0.0) and the gradient of
``v̂(s, w)`` is the row itself. Every kind of feature the book uses is such a row:

- ``table``: one pair ``(o(s), 1.0)``, ``o(s)`` the state's observation: the state, or its
  group where the world aggregates states (state aggregation, section 9.3);
- ``tiles``: the ``T`` tiles of the state's point, one per tiling, each ``1.0``: the tile
  rule CartPole, Mountain Car and Acrobot are coded with (:func:`~cartpole_q.rl.tiles.active_tiles`,
  section 9.5.4); one tiling is state aggregation by the grid;
- ``polynomial`` and ``fourier`` of an order ``m``: ``(m + 1)^k`` dense features of the
  state's point scaled to ``[0, 1]^k`` (sections 9.5.1, 9.5.2);
- ``declared``: the matrix the world gives (Baird's counterexample, Example 11.1).

The rows are built once, in plain Python (so every engine reads the same floats), and kept
as two arrays ``(N, K)``; a table world's tabular algorithms index their table directly
and never pay for this layer. The contract is docs/algorithms.md, "Feature layers".

>>> rows = polynomial_rows(np.array([[0.0], [0.5], [1.0]]), order=2)
>>> rows.value.tolist()
[[1.0, 0.0, 0.0], [1.0, 0.5, 0.25], [1.0, 1.0, 1.0]]
>>> fourier_rows(np.array([[0.5]]), order=2).value.round(12).tolist()  # cos(0), cos(pi/2), cos(pi)
[[1.0, 0.0, -1.0]]
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

KINDS = ("table", "tiles", "polynomial", "fourier", "declared")
"""the feature layers a linear study's curve may name"""
MAX_ORDER = 1_000
"""the highest polynomial or Fourier order (its features grow as ``(order + 1)^k``)"""


@dataclass(frozen=True)
class FeatureRows:
    """Every state's row of a layer: ``K`` (index, value) pairs per state, ``d`` weights."""

    index: np.ndarray
    """int64 ``(N, K)``: the weight index of each pair (distinct within a row, ascending)"""
    value: np.ndarray
    """float64 ``(N, K)``: each pair's feature value"""
    weights: int
    """``d``: how many weights the layer has"""

    def dense(self, states: np.ndarray | None = None) -> np.ndarray:
        """float64 ``(len(states), d)``: the rows as vectors (every state when ``None``)."""
        chosen = np.arange(self.index.shape[0]) if states is None else np.asarray(states)
        matrix = np.zeros((len(chosen), self.weights))
        for row, state in enumerate(chosen):
            matrix[row, self.index[state]] = self.value[state]
        return matrix


def table_rows(observation_of_state: np.ndarray, observations: int) -> FeatureRows:
    """One-hot rows: state ``s`` has ``1.0`` at its observation ``o(s)`` (its group, or itself).

    >>> table_rows(np.array([0, 0, 1]), 2).index.ravel().tolist()
    [0, 0, 1]
    """
    index = np.asarray(observation_of_state, dtype=np.int64).reshape(-1, 1)
    return FeatureRows(index, np.ones(index.shape), int(observations))


def tile_rows(
    points: np.ndarray, bins: Sequence[int], low: Sequence[float], high: Sequence[float],
    tilings: int,
) -> FeatureRows:  # fmt: skip
    """Each state's ``T`` tiles by the tile rule, ``1.0`` each, in tiling order.

    ``points`` is the world's ``point_of_state`` (float32 ``(N, k)``), ``bins``, ``low`` and
    ``high`` as ``discretization``'s. The 1000-state walk with 5 bins over ``[1, 1001]`` and
    50 tilings is the book's 50 tilings of tiles 200 states wide, each offset by 4 states
    (Figure 9.10); 1 tiling, groups of 200 states. Tiling ``t`` is shifted by ``4 t`` states:
    the last (``t = 49``, rows ``294 ..``) moves to its second tile at state 5, the first at 201.

    >>> walk = np.arange(1002, dtype=np.float32).reshape(-1, 1)
    >>> rows = tile_rows(walk, [5], [1.0], [1001.0], 50)
    >>> rows.weights, rows.index[[4, 5], 49].tolist(), rows.index[[200, 201], 0].tolist()
    (300, [294, 295], [0, 1])
    """
    from cartpole_q.rl.tiles import active_tiles, tile_shape

    low_array = np.asarray(low, dtype=np.float64)
    high_array = np.asarray(high, dtype=np.float64)
    bins_array = np.asarray(bins, dtype=np.int64)
    index = np.empty((points.shape[0], tilings), dtype=np.int64)
    for state, point in enumerate(points):
        active_tiles(point, low_array, high_array, bins_array, tilings, index[state])
    weights = int(np.prod(tile_shape(list(bins), tilings)))
    return FeatureRows(index, np.ones(index.shape), weights)


def scaled_points(points: np.ndarray, low: np.ndarray, high: np.ndarray) -> np.ndarray:
    """Each state's point scaled to ``[0, 1]`` by the observation space's bounds.

    ``u_j = (float(p_j) - float(low_j)) / (float(high_j) - float(low_j))`` (float64).

    >>> scaled_points(np.array([[0.0], [500.5], [1001.0]], dtype=np.float32), np.array([0.0]), np.array([1001.0])).ravel().tolist()
    [0.0, 0.5, 1.0]
    """
    scaled = np.empty(points.shape, dtype=np.float64)
    for state in range(points.shape[0]):
        for j in range(points.shape[1]):
            span = float(high[j]) - float(low[j])
            scaled[state, j] = (float(points[state, j]) - float(low[j])) / span
    return scaled


def exponents(order: int, dimensions: int) -> list[tuple[int, ...]]:
    """Every exponent vector ``c`` of ``{0 .. order}^k`` in C order (the last component fastest).

    >>> exponents(1, 2)
    [(0, 0), (0, 1), (1, 0), (1, 1)]
    """
    return list(itertools.product(range(order + 1), repeat=dimensions))


def power(u: float, exponent: int) -> float:
    """``u`` multiplied by itself: ``1.0 * u * u * ...`` (``exponent`` factors; 0: ``1.0``)."""
    result = 1.0
    for _ in range(exponent):
        result = result * u
    return result


def polynomial_rows(scaled: np.ndarray, order: int) -> FeatureRows:
    """Section 9.5.1: ``x_c(s) = prod_j u_j^c_j`` for every ``c`` of :func:`exponents`, dense."""
    vectors = exponents(order, scaled.shape[1])
    value = np.empty((scaled.shape[0], len(vectors)))
    for state in range(scaled.shape[0]):
        for feature, c in enumerate(vectors):
            product = 1.0
            for j, e in enumerate(c):
                product = product * power(float(scaled[state, j]), e)
            value[state, feature] = product
    return _dense(value)


def fourier_rows(scaled: np.ndarray, order: int) -> FeatureRows:
    """Section 9.5.2: ``x_c(s) = cos(pi * c . u)`` for every ``c`` of :func:`exponents`, dense."""
    vectors = exponents(order, scaled.shape[1])
    value = np.empty((scaled.shape[0], len(vectors)))
    for state in range(scaled.shape[0]):
        for feature, c in enumerate(vectors):
            dot = 0.0
            for j, e in enumerate(c):
                dot = dot + float(e) * float(scaled[state, j])
            value[state, feature] = math.cos(math.pi * dot)
    return _dense(value)


def declared_rows(matrix: np.ndarray) -> FeatureRows:
    """The world's own features: each row's nonzero entries by ascending index.

    >>> rows = declared_rows(np.array([[2.0, 0.0, 1.0], [0.0, 1.0, 2.0]]))
    >>> rows.index.tolist(), rows.value.tolist()
    ([[0, 2], [1, 2]], [[2.0, 1.0], [1.0, 2.0]])
    """
    matrix = np.asarray(matrix, dtype=np.float64)
    width = max(1, int(np.count_nonzero(matrix, axis=1).max(initial=0)))
    index = np.zeros((matrix.shape[0], width), dtype=np.int64)
    value = np.zeros((matrix.shape[0], width))
    for state in range(matrix.shape[0]):
        nonzero = np.flatnonzero(matrix[state])
        # a row with fewer nonzeros is padded with zero-valued pairs at its last index
        # (distinct indices: padding is placed after the listed ones and reads 0.0)
        listed = list(nonzero)
        spare = [i for i in range(matrix.shape[1]) if i not in set(listed)]
        pairs = listed + spare[: width - len(listed)]
        index[state] = sorted(pairs)
        value[state] = matrix[state, index[state]]
    return FeatureRows(index, value, int(matrix.shape[1]))


def feature_count(order: int, dimensions: int) -> int:
    """``(order + 1)^k``: the features of a polynomial or Fourier layer of ``k`` dimensions."""
    return int((order + 1) ** dimensions)


def _dense(value: np.ndarray) -> FeatureRows:
    """Rows that list every feature, in order."""
    index = np.broadcast_to(np.arange(value.shape[1], dtype=np.int64), value.shape).copy()
    return FeatureRows(index, value, int(value.shape[1]))
