"""The Q-table row of an observation, for each kind of observation the engines take.

An engine knows its environment's observation space before it compiles anything, so it
binds the rule of that kind into its compiled step functions: no branch on the kind is
left at run time, and no typing-time dispatch is needed. The gymnasium engine passes the
observation as Gymnasium returns it (:data:`ROW_RULES`); a compiled twin writes it into an
array, float32 values (Box) or int64 integers (Discrete, Tuple of Discrete), and the numba
engine's loop takes the grid's arrays one by one (:data:`ARRAY_ROW_RULES`). Both apply the
same rule: the binning rule of :func:`~cartpole_q.rl.binning.state_index`, or
:func:`indexed_row`.
"""

from __future__ import annotations

from typing import Any

from cartpole_q.rl.binning import state_index
from cartpole_q.rl.tabular import compilable


@compilable
def indexed_row(components: Any, bins: Any, starts: Any) -> int:
    """The C-order row of ``components[k] - starts[k]``, component ``k`` of size ``bins[k]``.

    The rule of Discrete observations (one component: ``obs - start``) and of Tuples of
    Discrete (component 0 the first axis of ``q_table.npy``).
    """
    index = 0
    for k in range(len(starts)):
        index = index * bins[k] + (components[k] - starts[k])
    return index


@compilable
def binned_row(observation: Any, grid: Any) -> int:
    """A Box observation: the binning rule on ``grid``'s edges."""
    row: int = state_index(observation, grid.low, grid.high, grid.bins)
    return row


@compilable
def discrete_row(observation: Any, grid: Any) -> int:
    """A ``Discrete(n, start)`` observation (an integer): ``obs - start``.

    :func:`indexed_row` of one component, without making a tuple of the integer.
    """
    row: int = observation - grid.starts[0]
    return row


@compilable
def tuple_row(observation: Any, grid: Any) -> int:
    """A ``Tuple`` of ``Discrete`` (integers): :func:`indexed_row` of its components."""
    row: int = indexed_row(observation, grid.bins, grid.starts)
    return row


ROW_RULES = {"box": binned_row, "discrete": discrete_row, "tuple": tuple_row}
"""observation kind -> its row rule (as :func:`cartpole_q.rl.binning.discrete_index`)"""


@compilable
def binned_array_row(observation: Any, low: Any, high: Any, bins: Any, starts: Any) -> int:
    """A twin's Box observation (float32 values): the binning rule."""
    row: int = state_index(observation, low, high, bins)
    return row


@compilable
def indexed_array_row(observation: Any, low: Any, high: Any, bins: Any, starts: Any) -> int:
    """A twin's Discrete or Tuple observation (int64 components): :func:`indexed_row`."""
    row: int = indexed_row(observation, bins, starts)
    return row


ARRAY_ROW_RULES = {"box": binned_array_row, "discrete": indexed_array_row,
                   "tuple": indexed_array_row}  # fmt: skip
"""observation kind -> its row rule for an observation a twin wrote into an array"""
