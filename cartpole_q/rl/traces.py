"""Sparse eligibility traces: only the (state, action) pairs with a trace are stored and touched.

Five arrays of an algorithm's memory: ``values`` (each trace), ``states`` and ``actions``
(its pair), in the order the pairs got their trace, ``slots`` (each pair's position in them
by flat index ``state * n_actions + action``, ``-1`` without a trace) and ``count``. A step
costs O(pairs with a trace), not O(table). A trace that decays to exactly 0.0 is dropped;
the list keeps its order (which never changes a value: each pair is updated on its own).
On tiles (:mod:`cartpole_q.rl.tiles`) the traced pairs are (tile, action): a visit of
``(s, a)`` gives each of ``s``'s tiles its trace, and a traced tile moves by ``alpha / T``
times what a traced pair moves by. The contract: docs/algorithms.md, "Eligibility traces".

>>> import numpy as np
>>> q = np.zeros((2, 2))
>>> values, states, actions, slots, count = trace_memory(2, 2)
>>> give_trace(q, values, states, actions, slots, count, 1, 0, 0, 0.5, 2)
>>> give_trace(q, values, states, actions, slots, count, 1, 0, 0, 0.5, 2)  # accumulating
>>> apply_and_decay(q, values, states, actions, slots, count, 0.5, 1.0, 0.25)  # alpha, delta
>>> float(q[1, 0]), float(values[0])
(1.0, 0.5)

Under ``agent.alpha: sample_average`` the engines pass the counts where ``alpha`` goes, and
compile the averaged variants: a visit counts, a traced entry moves by ``delta / N``.

>>> counts = np.zeros((2, 2))
>>> counted_visit_step(counts, 1, 0), counted_visit_step(counts, 1, 0)
(1.0, 0.5)
>>> averaged_trace_step(counts, 3.0, 1, 0)
1.5
"""

from __future__ import annotations

import numpy as np

from cartpole_q.rl.algorithm import Param
from cartpole_q.rl.tabular import (
    Table,
    averaged_variant,
    compilable,
    feature_alpha,
    tiles_variant,
)

TRACE_KINDS = ("accumulating", "replacing", "dutch", "clearing")
"""``agent.trace`` values, in the order of their codes"""
ACCUMULATING, REPLACING, DUTCH, CLEARING = 0, 1, 2, 3

LAMBDA = Param("lambda", 0.9, "the trace decay lambda (0: one-step)", low=0.0, high=1.0)
"""``agent.lambda`` of the trace methods"""
TRACE = Param(
    "trace", "replacing",
    "how a visit sets its pair's trace: z + 1, 1, (1 - alpha) z + 1, or 1 with the traces of "
    "the state's other actions set to 0 (replacing with clearing)",
    kind="choice", choices=TRACE_KINDS,
)  # fmt: skip
"""``agent.trace`` of SARSA(lambda) and Watkins's Q(lambda)"""
TRUE_ONLINE_NOT_AVERAGED = (
    "its dutch traces and its correction are derived for one step size shared by every "
    "entry (alpha enters the traces themselves), which a count per entry is not"
)
"""why the true online methods take no ``agent.alpha: sample_average``"""


@compilable
def trace_step(alpha: float, delta: float, state: int, action: int) -> float:
    """How far a traced entry moves per unit of its trace: ``alpha * delta``."""
    return alpha * delta


@averaged_variant(trace_step)
def averaged_trace_step(counts: np.ndarray, delta: float, state: int, action: int) -> float:
    """Under ``agent.alpha: sample_average``: ``delta / N(state, action)``, ``N`` its visits."""
    return float(delta / counts[state, action])


@compilable
def visit_step(alpha: float, state: int, action: int) -> float:
    """The step size a visit's dutch trace uses, ``(1 - alpha) z + 1``: ``alpha``."""
    return alpha


@averaged_variant(visit_step)
def counted_visit_step(counts: np.ndarray, state: int, action: int) -> float:
    """Under sample averages: count the visit, ``N(s, a) = N(s, a) + 1.0``; ``1.0 / N(s, a)``."""
    counts[state, action] = counts[state, action] + 1.0
    return float(1.0 / counts[state, action])


@compilable
def trace_slot(
    values: np.ndarray, states: np.ndarray, actions: np.ndarray, slots: np.ndarray,
    count: np.ndarray, state: int, action: int, n_actions: int,
) -> int:  # fmt: skip
    """The slot of the pair's trace, appending one of value 0.0 if it has none."""
    flat = state * n_actions + action
    where = slots[flat]
    if where < 0:
        where = count[0]
        slots[flat] = where
        values[where] = 0.0
        states[where] = state
        actions[where] = action
        count[0] = where + 1
    return int(where)


@compilable
def set_trace(values: np.ndarray, where: int, kind: int, alpha: float) -> None:
    """The trace at ``where`` after a visit: ``z + 1``, ``1`` or ``(1 - alpha) z + 1``."""
    if kind == ACCUMULATING:
        values[where] = values[where] + 1.0
    elif kind in (REPLACING, CLEARING):
        values[where] = 1.0
    else:
        values[where] = (1.0 - alpha) * values[where] + 1.0


@compilable
def give_trace(
    q: Table, values: np.ndarray, states: np.ndarray, actions: np.ndarray, slots: np.ndarray,
    count: np.ndarray, state: int, action: int, kind: int, alpha: float, n_actions: int,
) -> None:  # fmt: skip
    """Give ``(state, action)`` its trace: ``z + 1``, ``1`` or ``(1 - alpha) z + 1``.

    Under sample averages ``alpha`` is the table of counts: the visit is counted, and
    dutch's ``alpha`` is ``1 / N(state, action)`` (:func:`counted_visit_step`).
    """
    where = trace_slot(values, states, actions, slots, count, state, action, n_actions)
    set_trace(values, where, kind, visit_step(alpha, state, action))
    if kind == CLEARING:
        clear_other_actions(values, slots, state, action, n_actions)


@compilable
def clear_other_actions(
    values: np.ndarray, slots: np.ndarray, row: int, action: int, n_actions: int
) -> None:
    """Replacing with clearing: every other action's trace of ``row`` that exists becomes 0.0.

    A cleared trace stays in the list (its slot) until a decay drops it, as any trace of 0.0.
    """
    for other in range(n_actions):
        if other != action:
            where = slots[row * n_actions + other]
            if where >= 0:
                values[where] = 0.0


@tiles_variant(give_trace)
def give_tile_traces(
    q: Table, values: np.ndarray, states: np.ndarray, actions: np.ndarray, slots: np.ndarray,
    count: np.ndarray, state: int, action: int, kind: int, alpha: float, n_actions: int,
) -> None:  # fmt: skip
    """Give each of the state's tiles its trace, the dutch one over all of them at once.

    Accumulating, replacing and clearing set each tile's trace alone (clearing also zeroes
    that tile's traces of the other actions). Dutch is Sutton & Barto's
    (eq. 12.11) for the binary features of the ``T`` tiles, whose decayed traces sum to
    ``S``: every tile ``z = z + (1.0 - (alpha / T) * S)`` (one-hot features, ``T = 1``, give
    ``(1 - alpha) z + 1``).
    """
    if kind == DUTCH:
        dot = tile_trace_dot(q, slots, values, state, action)
        amount = 1.0 - feature_alpha(q, alpha) * dot
        grow_tile_traces(q, values, states, actions, slots, count, state, action, amount, n_actions)
        return
    features = q[1]
    for t in range(features.shape[1]):
        row = features[state, t]
        where = trace_slot(values, states, actions, slots, count, row, action, n_actions)
        set_trace(values, where, kind, alpha)
        if kind == CLEARING:
            clear_other_actions(values, slots, row, action, n_actions)


@compilable
def grow_trace(
    q: Table, values: np.ndarray, states: np.ndarray, actions: np.ndarray, slots: np.ndarray,
    count: np.ndarray, state: int, action: int, amount: float, n_actions: int,
) -> None:  # fmt: skip
    """``z(state, action) = z + amount`` (a pair without a trace starts at 0.0)."""
    where = trace_slot(values, states, actions, slots, count, state, action, n_actions)
    values[where] = values[where] + amount


@tiles_variant(grow_trace)
def grow_tile_traces(
    q: Table, values: np.ndarray, states: np.ndarray, actions: np.ndarray, slots: np.ndarray,
    count: np.ndarray, state: int, action: int, amount: float, n_actions: int,
) -> None:  # fmt: skip
    """Each of the state's tiles ``z = z + amount``, in tiling order."""
    features = q[1]
    for t in range(features.shape[1]):
        row = features[state, t]
        where = trace_slot(values, states, actions, slots, count, row, action, n_actions)
        values[where] = values[where] + amount


@compilable
def trace_dot(q: Table, slots: np.ndarray, values: np.ndarray, state: int, action: int) -> float:
    """``z . x(state, action)``: the pair's trace (tiles: its tiles' traces summed)."""
    return trace_value(slots, values, state * q.shape[1] + action)


@tiles_variant(trace_dot)
def tile_trace_dot(
    q: Table, slots: np.ndarray, values: np.ndarray, state: int, action: int
) -> float:  # fmt: skip
    """The traces of the state's tiles for ``action``, summed in tiling order from 0.0."""
    weights, features = q[0], q[1]
    total = 0.0
    for t in range(features.shape[1]):
        total += trace_value(slots, values, features[state, t] * weights.shape[1] + action)
    return total


@compilable
def trace_value(slots: np.ndarray, values: np.ndarray, flat: int) -> float:
    """The trace of a pair by flat index (0.0 without one)."""
    where = slots[flat]
    if where < 0:
        return 0.0
    return float(values[where])


@compilable
def apply_and_decay(
    q: Table, values: np.ndarray, states: np.ndarray, actions: np.ndarray, slots: np.ndarray,
    count: np.ndarray, alpha: float, delta: float, decay: float,
) -> None:  # fmt: skip
    """``Q[x] = Q[x] + (alpha * delta) * z``, then ``z = decay * z``, for every trace, in one pass.

    A trace that decays to exactly 0.0 is dropped. Under sample averages each entry moves by
    ``(delta / N[x]) * z`` (:func:`trace_step`).
    """
    n_actions = q.shape[1]
    kept = 0
    for read in range(count[0]):
        state, action, z = states[read], actions[read], values[read]
        q[state, action] = q[state, action] + trace_step(alpha, delta, state, action) * z
        z = decay * z
        if z == 0.0:
            slots[state * n_actions + action] = -1
            continue
        if kept != read:
            states[kept], actions[kept] = state, action
            slots[state * n_actions + action] = kept
        values[kept] = z
        kept += 1
    count[0] = kept


@tiles_variant(apply_and_decay)
def apply_tile_traces_and_decay(
    q: Table, values: np.ndarray, states: np.ndarray, actions: np.ndarray, slots: np.ndarray,
    count: np.ndarray, alpha: float, delta: float, decay: float,
) -> None:  # fmt: skip
    """:func:`apply_and_decay` on the weights, each traced tile by ``((alpha * delta) / T) * z``.

    (The tile's step goes in as ``alpha`` with a ``delta`` of 1.0: ``x * 1.0`` is ``x``.)
    """
    tile_step = (alpha * delta) / q[1].shape[1]
    apply_and_decay(q[0], values, states, actions, slots, count, tile_step, 1.0, decay)


@compilable
def decay_traces(
    values: np.ndarray, states: np.ndarray, actions: np.ndarray, slots: np.ndarray,
    count: np.ndarray, decay: float, n_actions: int,
) -> None:  # fmt: skip
    """``z = decay * z`` for every trace; one that becomes exactly 0.0 is dropped."""
    kept = 0
    for read in range(count[0]):
        state, action = states[read], actions[read]
        z = decay * values[read]
        if z == 0.0:
            slots[state * n_actions + action] = -1
            continue
        if kept != read:
            states[kept], actions[kept] = state, action
            slots[state * n_actions + action] = kept
        values[kept] = z
        kept += 1
    count[0] = kept


@compilable
def apply_traces(
    q: Table, values: np.ndarray, states: np.ndarray, actions: np.ndarray, count: np.ndarray,
    alpha: float, delta: float,
) -> None:  # fmt: skip
    """``Q[x] = Q[x] + (alpha * delta) * z`` for every trace, in list order.

    Under sample averages each entry moves by ``(delta / N[x]) * z`` (:func:`trace_step`).
    """
    for read in range(count[0]):
        state, action = states[read], actions[read]
        q[state, action] = q[state, action] + trace_step(alpha, delta, state, action) * values[read]


@compilable
def clear_traces(
    states: np.ndarray, actions: np.ndarray, slots: np.ndarray, count: np.ndarray,
    n_actions: int,
) -> None:  # fmt: skip
    """Remove every trace."""
    for read in range(count[0]):
        slots[states[read] * n_actions + actions[read]] = -1
    count[0] = 0


@tiles_variant(apply_traces)
def apply_tile_traces(
    q: Table, values: np.ndarray, states: np.ndarray, actions: np.ndarray, count: np.ndarray,
    alpha: float, delta: float,
) -> None:  # fmt: skip
    """:func:`apply_traces` on the weights, each traced tile by ``((alpha * delta) / T) * z``."""
    apply_traces(q[0], values, states, actions, count, (alpha * delta) / q[1].shape[1], 1.0)


def trace_memory(n_states: int, n_actions: int) -> tuple[np.ndarray, ...]:
    """No traces yet: values, states, actions, slots (all -1) and ``[count]``."""
    pairs = n_states * n_actions
    return (
        np.zeros(pairs, dtype=np.float64),
        np.zeros(pairs, dtype=np.int64),
        np.zeros(pairs, dtype=np.int64),
        np.full(pairs, -1, dtype=np.int64),
        np.zeros(1, dtype=np.int64),
    )
