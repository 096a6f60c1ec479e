"""The learned model of the Dyna methods: per (state, action) tried, the last transition seen.

Seven arrays of an algorithm's memory (docs/algorithms.md, "Planning"): ``next_states``
(``-1``: never tried), ``rewards``, ``terminals`` (1: the transition ended the episode; a
truncated one is not), ``seen`` (the states seen, in the order first seen), ``taken`` (for
each state ``x``, from ``x * n_actions``, the actions taken in it, in the order first taken),
``taken_count`` (how many per state) and ``counters`` = ``[states seen, time]``.

>>> import numpy as np
>>> model = model_memory(3, 2)
>>> remember(model, 2, 1, 0, 0.5, False, 2)
>>> [int(model[0][2 * 2 + 1]), float(model[1][5]), int(model[6][0]), int(model[3][0])]
[0, 0.5, 1, 2]
"""

from __future__ import annotations

import numpy as np

from cartpole_q.rl.algorithm import Param
from cartpole_q.rl.tabular import (
    Memory,
    Rng,
    Table,
    action_count,
    best_value,
    compilable,
    update,
)

MODEL_NOT_ON_TILES = (
    "its model is a table over states, and a tiled observation is not one of a finite set of states"
)
"""why the planning algorithms are refused on tiles (their ``not_on_tiles``)"""

MODEL_MEMORY_NAMES = (
    "model_next_states", "model_rewards", "model_terminals", "model_states_seen",
    "model_actions_taken", "model_actions_count", "model_counters",
)  # fmt: skip
"""the names of :func:`model_memory`'s arrays, in order (the start of a planning
algorithm's ``memory_names``)"""

PLANNING_STEPS = Param(
    "planning_steps", 10, "planning updates per real step (0: none)",
    kind="int", low=0, high=10_000,
)  # fmt: skip
"""``agent.planning_steps`` of the Dyna methods"""


@compilable
def remember(
    model: Memory, state: int, action: int, next_state: int, reward: float, terminated: bool,
    n_actions: int,
) -> None:  # fmt: skip
    """Record a real transition: ``state`` and ``action`` as seen, and the outcome."""
    next_states, rewards, terminals = model[0], model[1], model[2]
    seen, taken, taken_count, counters = model[3], model[4], model[5], model[6]
    flat = state * n_actions + action
    if next_states[flat] < 0:  # a pair never tried: maybe a state never seen
        if taken_count[state] == 0:
            seen[counters[0]] = state
            counters[0] += 1
        taken[state * n_actions + taken_count[state]] = action
        taken_count[state] += 1
    next_states[flat] = next_state
    rewards[flat] = reward
    terminals[flat] = 1 if terminated else 0


@compilable
def plan_dyna_q(q: Table, model: Memory, steps: int, alpha: float, gamma: float, rng: Rng) -> None:
    """``steps`` Q-learning updates on transitions drawn from the model (Dyna-Q)."""
    next_states, rewards, terminals = model[0], model[1], model[2]
    seen, taken, taken_count, counters = model[3], model[4], model[5], model[6]
    n_actions = action_count(q)
    for _ in range(steps):
        state = seen[rng.integers(0, counters[0])]
        action = taken[state * n_actions + rng.integers(0, taken_count[state])]
        flat = state * n_actions + action
        target = rewards[flat]
        if terminals[flat] == 0:
            target = rewards[flat] + gamma * best_value(q, next_states[flat])
        update(q, state, action, target, alpha)


def model_memory(n_states: int, n_actions: int) -> tuple[np.ndarray, ...]:
    """An empty model."""
    pairs = n_states * n_actions
    return (
        np.full(pairs, -1, dtype=np.int64),
        np.zeros(pairs, dtype=np.float64),
        np.zeros(pairs, dtype=np.int64),
        np.zeros(n_states, dtype=np.int64),
        np.zeros(pairs, dtype=np.int64),
        np.zeros(n_states, dtype=np.int64),
        np.zeros(2, dtype=np.int64),
    )
