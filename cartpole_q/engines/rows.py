"""The Q-table row of an observation, for each kind of observation the engines take.

The numba engine knows its twin's observation kind before it compiles anything, so it
binds that kind's rule into its loop (:data:`ARRAY_STATE_RULES`): no branch on the kind is
left at run time. A compiled twin writes the observation into an array, float32 values
(Box) or int64 integers (Discrete, Tuple of Discrete), and the loop takes the grid's arrays
one by one. The gymnasium engine passes every observation but tiles' as a float64 array of
its values (a Box's float32 values widened, a Discrete or Tuple one's integer components)
and picks the grid's rule at run time (:func:`observation_state`), so that one compilation
per algorithm serves every world (:data:`STATE_RULES`). Both apply the same rule: the
binning rule of :func:`~cartpole_q.rl.binning.state_index`, or :func:`indexed_row`. On tile
coding (:mod:`cartpole_q.rl.tiles`) the state a hook gets is a handle whose tiles the rule
writes into the table's features (:func:`tile_state`).
"""

from __future__ import annotations

from typing import Any

from cartpole_q.rl.binning import state_index
from cartpole_q.rl.tabular import compilable
from cartpole_q.rl.tiles import active_tiles


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
def binned_array_row(observation: Any, low: Any, high: Any, bins: Any, starts: Any) -> int:
    """A twin's Box observation (float32 values): the binning rule."""
    row: int = state_index(observation, low, high, bins)
    return row


@compilable
def indexed_array_row(observation: Any, low: Any, high: Any, bins: Any, starts: Any) -> int:
    """A twin's Discrete or Tuple observation (int64 components): :func:`indexed_row`."""
    row: int = indexed_row(observation, bins, starts)
    return row


# -- the state a hook gets: a row, or on tiles a handle of the observation's tiles ---------


@compilable
def tile_handle(q: Any, previous: int) -> int:
    """The handle after ``previous`` (``-1`` at a reset): ``(previous + 1) mod len(features)``."""
    handle: int = (previous + 1) % q[1].shape[0]
    return handle


@compilable
def tile_state(q: Any, observation: Any, low: Any, high: Any, bins: Any, previous: int) -> int:
    """Write the observation's tiles at the handle after ``previous``; return that handle."""
    handle = tile_handle(q, previous)
    features = q[1]
    active_tiles(observation, low, high, bins, features.shape[1], features[handle])
    return handle


@compilable
def component_row(components: Any, bins: Any, starts: Any) -> int:
    """:func:`indexed_row` of integer components held as float64 values (exact below 2**53)."""
    index = 0
    for k in range(len(starts)):
        index = index * bins[k] + (int(components[k]) - starts[k])
    return index


@compilable
def observation_state(q: Any, observation: Any, grid: Any, previous: int) -> int:
    """Any observation but tiles', as the gymnasium engine passes it (float64 values): its row.

    A Box observation's float32 values widened to float64 (the binning rule widens them
    anyway, so the row is the same), or a Discrete or Tuple observation's integer
    components: one rule, so that one compilation serves every world.
    """
    if grid.starts.size:
        return component_row(observation, grid.bins, grid.starts)
    return binned_row(observation, grid)


@compilable
def tiled_state(q: Any, observation: Any, grid: Any, previous: int) -> int:
    """A Box observation on tiles: its tiles written at the next handle, which it returns."""
    return tile_state(q, observation, grid.low, grid.high, grid.bins, previous)


STATE_RULES = {"values": observation_state, "tiles": tiled_state}
"""how the gymnasium engine passes observations (``values``: any observation's values as a
float64 array, see :func:`observation_state`; ``tiles``: a Box observation on tiles) -> the
state rule of its step functions"""


@compilable
def binned_array_state(
    q: Any, observation: Any, low: Any, high: Any, bins: Any, starts: Any, previous: int
) -> int:
    """A twin's Box observation: its row."""
    return binned_array_row(observation, low, high, bins, starts)


@compilable
def indexed_array_state(
    q: Any, observation: Any, low: Any, high: Any, bins: Any, starts: Any, previous: int
) -> int:
    """A twin's Discrete or Tuple observation: its row."""
    return indexed_array_row(observation, low, high, bins, starts)


@compilable
def tiled_array_state(
    q: Any, observation: Any, low: Any, high: Any, bins: Any, starts: Any, previous: int
) -> int:
    """A twin's Box observation on tiles: its tiles at the next handle, which it returns."""
    return tile_state(q, observation, low, high, bins, previous)


ARRAY_STATE_RULES = {"box": binned_array_state, "discrete": indexed_array_state,
                     "tuple": indexed_array_state, "tiles": tiled_array_state}  # fmt: skip
"""observation kind -> the state rule of the numba engine's loop"""
