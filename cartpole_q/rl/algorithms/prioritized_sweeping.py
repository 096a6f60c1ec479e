"""Prioritized sweeping (Sutton & Barto 8.4, Example 8.4), for a deterministic model.

Per real step, as the book's box: the model remembers the transition
(:mod:`cartpole_q.rl.model`); its priority ``P = |y - Q(s, a)|`` (``y`` Q-learning's target)
puts ``(s, a)`` in the queue when ``P > theta``; then, ``agent.planning_steps`` times while
the queue is not empty, the pair of highest priority leaves it and gets Q-learning's update
on its remembered transition, and every pair remembered as leading to its state (not
terminally) is queued by its own priority. There is no direct update: every update comes
from the queue. The next action is drawn from the table after planning. The memory's
``sweep_updates`` counts the updates made (one cell, never read by the algorithm: Example
8.4's measure, updates until the greedy path is optimal). The contract: docs/algorithms.md.

**The queue** is an indexed binary max-heap over the pairs ``state * n_actions + action``,
ordered by priority, the lower pair first among equal priorities (:func:`ahead`): its top
is exactly the pair a scan of every priority would pick, so the order of the updates does
not depend on the data structure, only the cost: ``O(log pairs)`` per queueing or taking,
where a scan costs ``O(pairs)``. Queueing a queued pair with a larger priority raises it in
place (increase-key).

**The predecessors** of each state, the pairs whose remembered next state it is, are a
doubly-linked list threaded through per-pair arrays (a pair whose remembered outcome
changes moves lists in ``O(1)``), so a planning update visits only its state's predecessors
instead of every pair. They are queued in list order; the order does not matter, since
queueing keeps the larger priority and nothing else changes meanwhile.

>>> import numpy as np
>>> q = np.zeros((2, 2))
>>> memory = sweeping_memory(MemoryContext(2, 2, 0.0, {}, 10))
>>> step(q, memory, (5.0, 0.0, 0.0), Transition(0, 1, 1.0, 1, False, False),
...     Rates(0.5, 1.0, 0.0), np.random.default_rng(0))
0
>>> float(q[0, 1])  # P = 1 queued (0, 1); planning: its update, nothing else queued
0.5
>>> int(memory[UPDATES][0])  # one update so far
1
>>> line = queue_of(memory)
>>> queue(*line, 3, 0.25, 0.0); queue(*line, 0, 0.25, 0.0); queue(*line, 2, 0.5, 0.0)
>>> [take_first(*line) for _ in range(4)]  # by priority, the lower pair among equals
[2, 0, 3, -1]
"""

from __future__ import annotations

import numpy as np

from cartpole_q.rl.algorithm import Algorithm, MemoryContext, Param, param_index
from cartpole_q.rl.model import (
    MODEL_MEMORY_NAMES,
    MODEL_NOT_ON_TILES,
    PLANNING_STEPS,
    model_memory,
    remember,
)
from cartpole_q.rl.tabular import (
    ENDED,
    Memory,
    Params,
    Rates,
    Rng,
    Table,
    Transition,
    action_count,
    behaviour_action,
    best_value,
    compilable,
    update,
    value,
)

NEXT_STATES, REWARDS, TERMINALS = 0, 1, 2
"""the model's arrays this module reads (:mod:`cartpole_q.rl.model`)"""
QUEUE, UPDATES = 7, 8
"""the memory's queue (priorities per pair) and its count of updates made"""
HEAP, HEAP_PLACES, HEAP_SIZE = 9, 10, 11
"""the queue's heap: the queued pairs in heap order, each pair's place in it (-1: not
queued), and how many are queued"""
LEADING_FIRST, LEADING_NEXT, LEADING_PREVIOUS = 12, 13, 14
"""the predecessor lists: per state the first pair remembered as leading to it, per pair the
next and the previous pair of its list (-1: none)"""
OLDER_MEMORY = 9
"""the arrays of a memory written before the heap and the predecessor lists (``memory_0``
to ``memory_8``): :func:`memory_from_older` rebuilds the rest"""
ABSENT = -1.0
"""the priority of a pair not in the queue (every queued priority is above ``theta >= 0``)"""
NONE = -1
"""no pair: the end of a list, a pair not in the heap, an empty queue"""


@compilable
def ahead(priorities: np.ndarray, pair: int, other: int) -> bool:
    """Whether ``pair`` leaves the queue before ``other``: a larger priority, or equal and lower."""
    return priorities[pair] > priorities[other] or (
        priorities[pair] == priorities[other] and pair < other
    )


@compilable
def sift_up(heap: np.ndarray, heap_at: np.ndarray, priorities: np.ndarray, at: int) -> None:
    """Move the pair at heap place ``at`` up past every parent it goes ahead of."""
    pair = heap[at]
    while at > 0:
        parent = (at - 1) // 2
        above = heap[parent]
        if not ahead(priorities, pair, above):
            break
        heap[at], heap_at[above] = above, at
        at = parent
    heap[at], heap_at[pair] = pair, at


@compilable
def sift_down(
    heap: np.ndarray, heap_at: np.ndarray, priorities: np.ndarray, size: int, at: int
) -> None:
    """Move the pair at heap place ``at`` down below every child that goes ahead of it."""
    pair = heap[at]
    while True:
        child = 2 * at + 1
        if child >= size:
            break
        if child + 1 < size and ahead(priorities, heap[child + 1], heap[child]):
            child += 1
        below = heap[child]
        if not ahead(priorities, below, pair):
            break
        heap[at], heap_at[below] = below, at
        at = child
    heap[at], heap_at[pair] = pair, at


@compilable
def queue(
    priorities: np.ndarray, heap: np.ndarray, heap_at: np.ndarray, size: np.ndarray, flat: int,
    priority: float, theta: float,
) -> None:  # fmt: skip
    """Put pair ``flat`` in the queue with ``priority`` if above ``theta`` (a queued pair keeps the larger).

    The queue is four arrays of the memory (:func:`queue_of`), passed one by one: compiled
    code pays for every array it takes out of the memory tuple (a reference count, twice
    the cost of the heap's work), so a sweep takes them out once.
    """
    if priority > theta and priority > priorities[flat]:
        priorities[flat] = priority
        at = heap_at[flat]
        if at == NONE:  # a new pair: at the bottom, then up (else only up: a larger priority)
            at = size[0]
            heap[at] = flat
            size[0] += 1
        sift_up(heap, heap_at, priorities, at)


@compilable
def take_first(
    priorities: np.ndarray, heap: np.ndarray, heap_at: np.ndarray, size: np.ndarray
) -> int:
    """Take the queue's first pair off it (its priority becomes ``ABSENT``); -1 when it is empty.

    The first: the highest priority, the lowest ``state * n + action`` among equal ones.
    """
    if size[0] == 0:
        return NONE
    first = heap[0]
    size[0] -= 1
    heap_at[first], priorities[first] = NONE, ABSENT
    if size[0] > 0:
        heap[0] = heap[size[0]]
        sift_down(heap, heap_at, priorities, size[0], 0)
    return int(first)


@compilable
def queue_of(memory: Memory) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The queue's arrays in a memory, as :func:`queue` and :func:`take_first` take them."""
    return memory[QUEUE], memory[HEAP], memory[HEAP_PLACES], memory[HEAP_SIZE]


@compilable
def relink(
    first: np.ndarray, following: np.ndarray, preceding: np.ndarray, flat: int, was: int,
    now: int,
) -> None:  # fmt: skip
    """Move pair ``flat`` from the list of state ``was`` (-1: none) to the list of state ``now``.

    The lists are ``memory[LEADING_FIRST]``, ``[LEADING_NEXT]`` and ``[LEADING_PREVIOUS]``;
    a pair joins a list at its front.
    """
    if was == now:
        return
    if was != NONE:
        before, after = preceding[flat], following[flat]
        if before == NONE:
            first[was] = after
        else:
            following[before] = after
        if after != NONE:
            preceding[after] = before
    head = first[now]
    following[flat], preceding[flat] = head, NONE
    if head != NONE:
        preceding[head] = flat
    first[now] = flat


@compilable
def sweep(
    q: Table, memory: Memory, steps: int, theta: float, alpha: float, gamma: float
) -> None:  # fmt: skip
    """Up to ``steps`` updates of the queue's first pairs, queueing their predecessors.

    ``memory[UPDATES][0]`` is increased by one per update made.
    """
    next_states, rewards, terminals = memory[NEXT_STATES], memory[REWARDS], memory[TERMINALS]
    priorities, heap, heap_at, size = queue_of(memory)
    first, following, updates = memory[LEADING_FIRST], memory[LEADING_NEXT], memory[UPDATES]
    n_actions = action_count(q)
    for _ in range(steps):
        flat = take_first(priorities, heap, heap_at, size)
        if flat == NONE:
            return
        state, action = flat // n_actions, flat % n_actions
        target = rewards[flat]
        if terminals[flat] == 0:
            target = rewards[flat] + gamma * best_value(q, next_states[flat])
        update(q, state, action, target, alpha)
        updates[0] += 1
        best = best_value(q, state)
        before = first[state]
        while before != NONE:
            if terminals[before] == 0:
                lead = rewards[before] + gamma * best
                gap = lead - value(q, before // n_actions, before % n_actions)
                queue(priorities, heap, heap_at, size, before, abs(gap), theta)
            before = following[before]


def step(
    q: Table, memory: Memory, params: Params, transition: Transition, rates: Rates, rng: Rng
) -> int:
    """Remember the step, queue it by its priority, sweep, then draw the next action."""
    state, action, reward = transition.state, transition.action, transition.reward
    next_state, terminated = transition.next_state, transition.terminated
    truncated = transition.truncated
    alpha, gamma, epsilon = rates.alpha, rates.gamma, rates.epsilon
    n_actions = action_count(q)
    theta = params[THETA_AT]
    flat = state * n_actions + action
    was = memory[NEXT_STATES][flat]
    remember(memory, state, action, next_state, reward, terminated, n_actions)
    relink(memory[LEADING_FIRST], memory[LEADING_NEXT], memory[LEADING_PREVIOUS], flat, was,
           next_state)  # fmt: skip
    target = reward
    if not terminated:
        target = reward + gamma * best_value(q, next_state)
    priorities, heap, heap_at, size = queue_of(memory)
    queue(priorities, heap, heap_at, size, flat, abs(target - value(q, state, action)), theta)
    sweep(q, memory, int(params[PLANNING_STEPS_AT]), theta, alpha, gamma)
    if terminated or truncated:
        return ENDED
    return behaviour_action(q, params, next_state, epsilon, rng)


def sweeping_memory(context: MemoryContext) -> tuple[np.ndarray, ...]:
    """An empty model, an empty queue, no update made, and no predecessors."""
    pairs = context.n_states * context.n_actions
    return (
        *model_memory(context.n_states, context.n_actions),
        np.full(pairs, ABSENT),
        np.zeros(1, dtype=np.int64),
        np.zeros(pairs, dtype=np.int64),
        np.full(pairs, NONE, dtype=np.int64),
        np.zeros(1, dtype=np.int64),
        np.full(context.n_states, NONE, dtype=np.int64),
        np.full(pairs, NONE, dtype=np.int64),
        np.full(pairs, NONE, dtype=np.int64),
    )


def memory_from_older(saved: tuple[np.ndarray, ...]) -> tuple[np.ndarray, ...]:
    """A whole memory from one written before the heap and the lists (its first nine arrays).

    The heap holds the queued pairs (priority not ``ABSENT``) sorted by :func:`ahead`'s
    order (a sorted array is a heap); each state's list, the pairs whose remembered next
    state it is, in increasing pair order. An array after the ninth (the engine's update
    counts under ``agent.alpha: sample_average``) stays last. The saved arrays are copied,
    not shared; a whole memory is returned as it is (copied).

    Raises:
        ValueError: ``saved`` is not a prioritized sweeping memory of either layout.
    """
    whole = len(ALGORITHM.memory_names)
    if len(saved) in (whole, whole + 1):
        return tuple(array.copy() for array in saved)
    if len(saved) not in (OLDER_MEMORY, OLDER_MEMORY + 1):
        raise ValueError(
            f"a prioritized sweeping memory has {OLDER_MEMORY} or {whole} arrays (one more "
            f"under sample averages), not {len(saved)}"
        )
    n_states = saved[3].shape[0]
    pairs = saved[QUEUE].shape[0]
    if n_states == 0 or pairs % n_states or saved[NEXT_STATES].shape != (pairs,):
        raise ValueError("its arrays are not shaped as a prioritized sweeping memory's")
    rebuilt = sweeping_memory(MemoryContext(n_states, pairs // n_states, 0.0, {}, 0))
    copied = tuple(array.copy() for array in saved)
    memory = (*copied[:OLDER_MEMORY], *rebuilt[OLDER_MEMORY:], *copied[OLDER_MEMORY:])
    priorities = memory[QUEUE]
    queued = np.flatnonzero(priorities != ABSENT)
    in_order = queued[np.lexsort((queued, -priorities[queued]))]
    memory[HEAP][: len(in_order)] = in_order
    memory[HEAP_PLACES][in_order] = np.arange(len(in_order))
    memory[HEAP_SIZE][0] = len(in_order)
    next_states = memory[NEXT_STATES]
    tried = np.flatnonzero(next_states >= 0)
    by_state = tried[np.argsort(next_states[tried], kind="stable")]
    leads_to = next_states[by_state]
    same = leads_to[1:] == leads_to[:-1]  # consecutive pairs of one list
    memory[LEADING_NEXT][by_state[:-1][same]] = by_state[1:][same]
    memory[LEADING_PREVIOUS][by_state[1:][same]] = by_state[:-1][same]
    starts = np.ones(len(by_state), dtype=bool)
    starts[1:] = ~same
    memory[LEADING_FIRST][leads_to[starts]] = by_state[starts]
    return memory


THETA = Param(
    "theta", 0.0001, "prioritized sweeping: the smallest priority queued (strictly above)",
    low=0.0,
)  # fmt: skip

PARAMS = (PLANNING_STEPS, THETA)
"""the parameters, in the order the hooks get them"""
PLANNING_STEPS_AT = param_index(PARAMS, PLANNING_STEPS)
THETA_AT = param_index(PARAMS, THETA)


ALGORITHM = Algorithm(
    name="prioritized_sweeping",
    no_sample_average="",  # every step size reaches update
    description="Prioritized sweeping: planning updates in order of priority (agent.theta)",
    book="8.4",
    not_on_tiles=MODEL_NOT_ON_TILES,
    step=step,
    params=PARAMS,
    memory=sweeping_memory,
    memory_names=(
        *MODEL_MEMORY_NAMES, "queue_priorities", "sweep_updates", "queue_heap",
        "queue_heap_places", "queue_heap_size", "predecessors_first", "predecessors_next",
        "predecessors_previous",
    ),
    older_memory=memory_from_older,
)  # fmt: skip
