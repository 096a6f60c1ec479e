"""The binning rule that maps a continuous observation to a Q-table row.

The rule is part of the run-directory contract, so that a saved Q-table can be used
without this package. For each dimension ``d`` with ``bins[d] > 1``::

    index_d = clip(floor((x_d - low_d) / (high_d - low_d) * bins_d), 0, bins_d - 1)

with ``x`` the float32 observation widened to float64; a dimension with one bin is
ignored. The Q-table has shape ``(*bins, n_actions)``; the flat row used by the compiled
code is the C-order index, ``numpy.ravel_multi_index(indices, bins)``.

:func:`state_index` is written once, in plain Python that numba can compile: the training
engines call the compiled copy (``cartpole_q.rl.policy``), while greedy evaluation calls this
one directly, so ``cartpole-q eval`` never imports numba. A NaN coordinate falls in bin 0.

>>> low, high, bins = [-1.0, -2.0], [1.0, 2.0], [4, 1]
>>> bin_indices([0.0, 5.0], low, high, bins)
(2, 0)
>>> state_index([0.0, 5.0], low, high, bins), state_index([9.0, 0.0], low, high, bins)
(2, 3)

Discrete observations need no binning: ``Discrete(n, start)`` gives row ``obs - start``, a
``Tuple(Discrete(n_0, start_0), Discrete(n_1, start_1), ...)`` the C-order row of
``i_k = obs[k] - start_k`` (:func:`discrete_index`, compiled as
:func:`cartpole_q.rl.policy.observation_row`).

>>> discrete_index(7, [3], [10]), discrete_index((2, 1), [0, 1], [4, 3])
(4, 6)
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from cartpole_q.rl.tabular import compilable


@compilable
def state_index(observation: Any, low: Any, high: Any, bins: Any) -> int:
    """The flat (C-order) Q-table row of an observation.

    Args:
        observation: one value per dimension (float32 values are widened to float64).
        low: lower grid edge per dimension.
        high: upper grid edge per dimension.
        bins: bins per dimension; dimensions with one bin are ignored.
    """
    index = 0
    for d in range(len(bins)):
        n_bins = bins[d]
        if n_bins == 1:
            continue
        scaled = (float(observation[d]) - low[d]) / (high[d] - low[d]) * n_bins
        if not scaled >= 0.0:  # also NaN
            position = 0
        elif scaled >= n_bins:
            position = n_bins - 1
        else:
            position = int(scaled)
        index = index * n_bins + position
    return index


def bin_indices(
    observation: Sequence[float], low: Sequence[float], high: Sequence[float], bins: Sequence[int]
) -> tuple[int, ...]:
    """The per-dimension bin indices: the Q-table index without the action axis."""
    return tuple(
        state_index([x], [lo], [hi], [n]) if n > 1 else 0
        for x, lo, hi, n in zip(observation, low, high, bins, strict=True)
    )


def discrete_index(observation: Any, starts: Any, sizes: Any) -> int:
    """The flat (C-order) Q-table row of a Discrete or Tuple-of-Discrete observation.

    Args:
        observation: an integer (``Discrete``) or a tuple of integers (``Tuple``).
        starts: each component's ``start``.
        sizes: each component's ``n``.
    """
    components = observation if isinstance(observation, tuple | list) else (observation,)
    index = 0
    for k in range(len(sizes)):
        index = index * sizes[k] + (int(components[k]) - starts[k])
    return index
