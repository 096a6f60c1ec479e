"""Prioritized sweeping (Sutton & Barto 8.4, Example 8.4), for a deterministic model.

Per real step, as the book's box: the model remembers the transition
(:mod:`cartpole_q.rl.model`); its priority ``P = |y - Q(s, a)|`` (``y`` Q-learning's target)
puts ``(s, a)`` in the queue when ``P > theta``; then, ``agent.planning_steps`` times while
the queue is not empty, the pair of highest priority leaves it and gets Q-learning's update
on its remembered transition, and every pair remembered as leading to its state (not
terminally) is queued by its own priority. There is no direct update: every update comes
from the queue. The next action is drawn from the table after planning. The memory's last
array, ``sweep_updates``, counts the updates made (one cell, never read by the algorithm:
Example 8.4's measure, updates until the greedy path is optimal). The contract:
docs/algorithms.md.

>>> import numpy as np
>>> q = np.zeros((2, 2))
>>> memory = sweeping_memory(MemoryContext(2, 2, 0.0, {}, 10))
>>> step(q, memory, (5.0, 0.0, 0.0), 0, 1, 1.0, 1, False, False, 0.5, 1.0, 0.0,
...      np.random.default_rng(0))
0
>>> float(q[0, 1])  # P = 1 queued (0, 1); planning: its update, nothing else queued
0.5
>>> int(memory[UPDATES][0])  # one update so far
1
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
    Rng,
    Table,
    action_count,
    behaviour_action,
    best_value,
    compilable,
    update,
    value,
)

QUEUE, UPDATES = 7, 8
"""the memory's queue (priorities per pair) and its count of updates made"""
ABSENT = -1.0
"""the priority of a pair not in the queue (every queued priority is above ``theta >= 0``)"""


@compilable
def queue(priorities: np.ndarray, flat: int, priority: float, theta: float) -> None:
    """Put pair ``flat`` in the queue with ``priority`` if above ``theta`` (a queued pair keeps the larger)."""
    if priority > theta and priority > priorities[flat]:
        priorities[flat] = priority


@compilable
def first_in_queue(priorities: np.ndarray) -> int:
    """The queued pair of highest priority (the lowest ``state * n + action`` among equals), or -1."""
    best, first = ABSENT, -1
    for flat in range(priorities.shape[0]):
        if priorities[flat] > best:
            best, first = priorities[flat], flat
    return first


@compilable
def sweep(
    q: Table, model: Memory, priorities: np.ndarray, steps: int, theta: float, alpha: float,
    gamma: float, updates: np.ndarray,
) -> None:  # fmt: skip
    """Up to ``steps`` updates of the queue's first pairs, queueing their predecessors.

    ``updates[0]`` is increased by one per update made.
    """
    next_states, rewards, terminals = model[0], model[1], model[2]
    n_actions = action_count(q)
    for _ in range(steps):
        flat = first_in_queue(priorities)
        if flat < 0:
            return
        priorities[flat] = ABSENT
        state, action = flat // n_actions, flat % n_actions
        target = rewards[flat]
        if terminals[flat] == 0:
            target = rewards[flat] + gamma * best_value(q, next_states[flat])
        update(q, state, action, target, alpha)
        updates[0] += 1
        best = best_value(q, state)
        for before in range(next_states.shape[0]):
            if next_states[before] == state and terminals[before] == 0:
                lead = rewards[before] + gamma * best
                gap = lead - value(q, before // n_actions, before % n_actions)
                queue(priorities, before, abs(gap), theta)


def step(q: Table, memory: Memory, params: Params, state: int, action: int, reward: float,
         next_state: int, terminated: bool, truncated: bool, alpha: float, gamma: float,
         epsilon: float, rng: Rng) -> int:  # fmt: skip
    """Remember the step, queue it by its priority, sweep, then draw the next action."""
    n_actions = action_count(q)
    theta = params[THETA_AT]
    remember(memory, state, action, next_state, reward, terminated, n_actions)
    target = reward
    if not terminated:
        target = reward + gamma * best_value(q, next_state)
    priorities = memory[QUEUE]
    queue(priorities, state * n_actions + action, abs(target - value(q, state, action)), theta)
    sweep(
        q, memory, priorities, int(params[PLANNING_STEPS_AT]), theta, alpha, gamma, memory[UPDATES]
    )
    if terminated or truncated:
        return ENDED
    return behaviour_action(q, params, next_state, epsilon, rng)


def sweeping_memory(context: MemoryContext) -> tuple[np.ndarray, ...]:
    """An empty model, an empty queue and no update made."""
    pairs = context.n_states * context.n_actions
    return (
        *model_memory(context.n_states, context.n_actions),
        np.full(pairs, ABSENT),
        np.zeros(1, dtype=np.int64),
    )


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
    memory_names=(*MODEL_MEMORY_NAMES, "queue_priorities",
        "sweep_updates"),
)  # fmt: skip
