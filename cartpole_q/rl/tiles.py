"""Tile coding: ``T`` offset grids whose values are summed (Sutton & Barto 9.5.4, ``tiles3``).

With ``discretization.tilings: T > 1`` a Box observation is not one row of a table but
``T`` tiles, one in each tiling, and ``Q(s, a) = sum_t w[tile_t(s), a]``. The tile rule, for
each tiling ``t = 0 .. T-1`` and each dimension with ``bins[d] > 1`` (the ``k``-th such
dimension, ``k = 0, 1, ...``; one-bin dimensions are ignored as the binning rule ignores
them)::

    scaled_d = (x_d - low_d) / (high_d - low_d) * bins_d      clipped to [0, bins_d] (NaN: 0)
    coord_d  = (floor(scaled_d * T) + (t * (1 + 2k)) mod T) // T       in [0, bins_d]

so each tiling is the grid of ``bins_d`` intervals shifted by ``(t * (1 + 2k) mod T) / T``
of an interval in dimension ``k`` (Sutton's asymmetric offsets), with one more tile per
dimension for the shifted overhang. The tile's row in the weight table is the C-order
index of ``(t, coord_0, coord_1, ...)`` in ``(T, bins_0 + 1, bins_1 + 1, ...)``:
``q_table.npy`` holds the weights with shape ``(T, *sizes, n_actions)``, ``sizes_d =
bins_d + 1`` (1 for a one-bin dimension).

The algorithms run on tiles unchanged: they address the table only through
:func:`~cartpole_q.rl.tabular.value`, :func:`~cartpole_q.rl.tabular.shift` and a few trace
functions, and the engines compile them with the variants below (see
:func:`~cartpole_q.rl.tabular.tiles_variant`). On tiles the table the hooks get is the pair
``(weights, features)``: ``features[h]`` holds the ``T`` rows of the observation of handle
``h``, and the "state" a hook gets is that handle: ``0`` at an episode's reset, then
``(h + 1) mod len(features)`` after each step (a time limit never wraps it). A change of
``Q(s, a)`` by ``amount`` moves each of its ``T`` tiles by ``amount / T``: the step size of a
tile is ``alpha / T``.

>>> import numpy as np
>>> rows = np.zeros(2, dtype=np.int64)
>>> active_tiles([0.3, 9.9], [0.0, 0.0], [1.0, 1.0], [2, 1], 2, rows)
>>> rows.tolist()  # tiling 0: interval 0 of 3; tiling 1, shifted by half: interval 1
[0, 4]
>>> weights = np.zeros((6, 2))
>>> q = (weights, np.array([[0, 4]]))
>>> tiled_shift(q, 0, 1, 1.0)
>>> tiled_value(q, 0, 1), float(weights[4, 1])
(1.0, 0.5)
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from cartpole_q.rl.tabular import (
    Table,
    action_count,
    compilable,
    feature_alpha,
    shift,
    tiles_variant,
    value,
    visit,
    weights_of,
    with_weights,
)


@compilable
def active_tiles(observation: Any, low: Any, high: Any, bins: Any, tilings: int, out: Any) -> None:
    """Write the ``tilings`` rows of ``observation``'s tiles into ``out`` (the module's rule)."""
    for t in range(tilings):
        row = t
        k = 0
        for d in range(len(bins)):
            n_bins = bins[d]
            if n_bins == 1:
                continue
            scaled = (float(observation[d]) - low[d]) / (high[d] - low[d]) * n_bins
            if not scaled >= 0.0:  # also NaN
                scaled = 0.0
            elif scaled > n_bins:
                scaled = float(n_bins)
            offset = (t * (1 + 2 * k)) % tilings
            coord = (int(scaled * tilings) + offset) // tilings
            row = row * (n_bins + 1) + coord
            k += 1
        out[t] = row


def tile_shape(bins: Sequence[int], tilings: int) -> tuple[int, ...]:
    """``(T, *sizes)``: the weight table's shape without the action axis.

    >>> tile_shape([1, 1, 6, 12], 8)
    (8, 1, 1, 7, 13)
    """
    return (tilings, *(n + 1 if n > 1 else 1 for n in bins))


def greedy_tile_action(weights: np.ndarray, rows: np.ndarray, n_actions: int) -> int:
    """``argmax_a sum_t weights[rows[t], a]``, the lowest action on ties (plain Python).

    What the compiled ``best_action`` computes on tiles, for ``cartpole-q eval`` (which
    never imports numba).
    """
    best, best_total = 0, 0.0
    for action in range(n_actions):
        total = 0.0
        for row in rows:
            total += float(weights[row, action])
        if action == 0 or total > best_total:
            best, best_total = action, total
    return best


@tiles_variant(action_count)
def tiled_action_count(q: Any) -> int:
    """How many actions the weights have."""
    n: int = q[0].shape[1]
    return n


@tiles_variant(value)
def tiled_value(q: Any, state: int, action: int) -> float:
    """``sum_t w[features[state, t], action]``, summed in tiling order from 0.0."""
    weights, features = q[0], q[1]
    total = 0.0
    for t in range(features.shape[1]):
        total += weights[features[state, t], action]
    return float(total)


@tiles_variant(shift)
def tiled_shift(q: Any, state: int, action: int, amount: float) -> None:
    """Each of the state's tiles ``w = w + amount / T``, in tiling order."""
    weights, features = q[0], q[1]
    step = amount / features.shape[1]
    for t in range(features.shape[1]):
        row = features[state, t]
        weights[row, action] = weights[row, action] + step


@tiles_variant(feature_alpha)
def tiled_feature_alpha(q: Any, alpha: float) -> float:
    """``alpha / T``."""
    tile_alpha: float = alpha / q[1].shape[1]
    return tile_alpha


@tiles_variant(visit)
def tiled_visit(visits: np.ndarray, q: Any, state: int, action: int) -> None:
    """Count a visit of each of the state's tiles."""
    features = q[1]
    for t in range(features.shape[1]):
        visits[features[state, t], action] += 1


@tiles_variant(weights_of)
def tiled_weights_of(q: Any) -> np.ndarray:
    """The tiles' weights (``q`` is ``(weights, features)``)."""
    weights: np.ndarray = q[0]
    return weights


@tiles_variant(with_weights)
def tiled_with_weights(q: Any, weights: Table) -> Any:
    """Other weights addressed through ``q``'s features."""
    return (weights, q[1])


def values_on_grid(
    weights: np.ndarray,
    bins: Sequence[int],
    low: Sequence[float],
    high: Sequence[float],
    dims: tuple[int, int],
    cells: tuple[int, int],
) -> np.ndarray:
    """``Q`` of a tiled table at the centres of a ``cells`` grid over two dimensions.

    The other dimensions sit at the centre of their range. For pictures (the policy map
    and the value surface of a tiled table): the tiles' sums as greedy play computes them.

    Args:
        weights: ``q_table.npy`` of a tiled run, ``(T, *sizes, n_actions)``.
        bins: ``discretization.bins``.
        low: ``discretization.low``.
        high: ``discretization.high``.
        dims: the two dimensions drawn (rows, columns).
        cells: how many cells along each.

    Returns:
        ``(cells[0], cells[1], n_actions)`` values.

    >>> w = np.zeros((2, 3, 3, 2)); w[:, 1:, :, 1] = 1.0   # tiles from coord 1 up: 1 each
    >>> values_on_grid(w, [2, 2], [0, 0], [1, 1], (0, 1), (2, 1))[:, 0, 1].tolist()
    [1.0, 2.0]

    (At 0.25 only the shifted tiling has reached its coordinate 1; at 0.75 both have.)
    """
    tilings, n_actions = weights.shape[0], weights.shape[-1]
    flat = weights.reshape(-1, n_actions)
    centre = [(lo + hi) / 2 for lo, hi in zip(low, high, strict=True)]
    rows = np.zeros(tilings, dtype=np.int64)
    out = np.zeros((*cells, n_actions), dtype=np.float64)
    point = list(centre)
    for i in range(cells[0]):
        point[dims[0]] = low[dims[0]] + (i + 0.5) / cells[0] * (high[dims[0]] - low[dims[0]])
        for j in range(cells[1]):
            point[dims[1]] = low[dims[1]] + (j + 0.5) / cells[1] * (high[dims[1]] - low[dims[1]])
            active_tiles(point, low, high, bins, tilings, rows)
            out[i, j] = flat[rows].sum(axis=0)
    return out
