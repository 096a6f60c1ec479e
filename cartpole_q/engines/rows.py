"""The Q-table row of an observation, for each kind of observation the engines take.

An engine knows its environment's observation space before it compiles anything, so it
binds the rule of that kind (:data:`ROW_RULES`) into its compiled step functions: no
branch on the kind is left at run time, and no typing-time dispatch is needed.
"""

from __future__ import annotations

from typing import Any

from cartpole_q.rl.binning import state_index
from cartpole_q.rl.tabular import compilable


@compilable
def binned_row(observation: Any, grid: Any) -> int:
    """A Box observation: the binning rule on ``grid``'s edges."""
    row: int = state_index(observation, grid.low, grid.high, grid.bins)
    return row


@compilable
def discrete_row(observation: Any, grid: Any) -> int:
    """A ``Discrete(n, start)`` observation (an integer): ``obs - start``."""
    row: int = observation - grid.starts[0]
    return row


@compilable
def tuple_row(observation: Any, grid: Any) -> int:
    """A ``Tuple`` of ``Discrete`` (integers): the C-order row of ``obs[k] - start_k``."""
    index = 0
    for k in range(len(observation)):
        index = index * grid.bins[k] + (observation[k] - grid.starts[k])
    return index


ROW_RULES = {"box": binned_row, "discrete": discrete_row, "tuple": tuple_row}
"""observation kind -> its row rule (as :func:`cartpole_q.rl.binning.discrete_index`)"""
