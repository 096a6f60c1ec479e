"""Batch updating (Sutton & Barto 6.3, Figure 6.2): TD(0) or constant-alpha MC on all episodes seen.

Every transition of every episode so far is kept. Nothing changes during an episode; when it
ends, the whole batch is presented again and again: each pass sums, per state, the errors
``y - V(s)`` of all kept transitions against the ``V`` the pass started from, and moves every
state by ``alpha`` times its sum, until a pass's total move is below ``agent.tolerance``
(or ``agent.max_passes`` passes). ``agent.target``: ``td``, the one-step target ``y = r +
gamma * V(s')``; ``mc``, the episode's return. Both are kept as ``y = g + w * V(b)``: TD's
``g = r``, ``w = gamma`` (0 when terminated), ``b = s'``; MC's ``g`` the discounted reward
sum to the episode's end, ``w = gamma ** (steps to the end)`` when a time limit cut it (else
0), ``b`` the state it was cut in. The contract: docs/algorithms.md, "Batch updating".

>>> import numpy as np
>>> v = np.full((3, 1), 0.5)
>>> context = MemoryContext(3, 2, 0.5, {"policy": "random", "target": "td"}, 4, episodes=2)
>>> memory = batch_memory(context)
>>> rng = np.random.default_rng(0)
>>> params = (0.0, 0.0, 1e-9, 100000.0)  # policy random, target td, tolerance, max_passes
>>> step(v, memory, params, Transition(0, 0, 0.0, 1, False, False),
...     Rates(0.1, 1.0, 0.0), rng) in (0, 1)
True
>>> step(v, memory, params, Transition(1, 0, 1.0, 2, True, False), Rates(0.1, 1.0, 0.0), rng)
-1
>>> [round(float(x), 6) for x in v[:, 0]]  # converged: V(1) = 1, V(0) = V(1); 2 is terminal
[1.0, 1.0, 0.5]
"""

from __future__ import annotations

import math

import numpy as np

from cartpole_q.rl.algorithm import Algorithm, MemoryContext, Param, param_index
from cartpole_q.rl.prediction import (
    POLICY,
    POLICY_SOURCE,
    first_policy_action,
    policy_action,
    policy_table,
)
from cartpole_q.rl.tabular import ENDED, Memory, Params, Rates, Rng, Table, Transition, shift, value

TARGETS = ("td", "mc")
"""``agent.target`` values, in the order of their codes"""


def step(
    q: Table, memory: Memory, params: Params, transition: Transition, rates: Rates, rng: Rng
) -> int:
    """Keep the transition; at the episode's end, learn from the whole batch until it settles."""
    state, reward, next_state = transition.state, transition.reward, transition.next_state
    terminated, truncated = transition.terminated, transition.truncated
    alpha, gamma = rates.alpha, rates.gamma
    policy, states, targets, bootstraps, weights = (
        memory[0],
        memory[1],
        memory[2],
        memory[3],
        memory[4],
    )
    increments, counters = memory[5], memory[6]
    kept = counters[0]
    states[kept], targets[kept], bootstraps[kept] = state, reward, next_state
    weights[kept] = 0.0 if terminated else gamma
    counters[0] = kept + 1
    if not (terminated or truncated or counters[0] - counters[1] == counters[2]):
        return policy_action(policy, next_state, params, rng)
    if params[TARGET_AT] == 1.0:  # mc: the returns of this episode, backwards
        total_return = 0.0
        weight = 0.0 if terminated else 1.0
        for i in range(kept, counters[1] - 1, -1):
            total_return = gamma * total_return + targets[i]
            weight = gamma * weight
            targets[i], bootstraps[i], weights[i] = total_return, next_state, weight
    counters[1] = kept + 1
    tolerance, max_passes = params[TOLERANCE_AT], int(params[MAX_PASSES_AT])
    for _ in range(max_passes):
        for s in range(increments.shape[0]):
            increments[s] = 0.0
        for i in range(counters[0]):
            s = states[i]
            error = targets[i] + weights[i] * value(q, bootstraps[i], 0) - value(q, s, 0)
            increments[s] = increments[s] + error
        moved = 0.0
        for s in range(increments.shape[0]):
            moved += abs(alpha * increments[s])
        if moved < tolerance or not math.isfinite(moved):
            break
        for s in range(increments.shape[0]):
            shift(q, s, 0, alpha * increments[s])
    return ENDED


def batch_memory(context: MemoryContext) -> tuple[np.ndarray, ...]:
    """The policy, room for every transition of the run's episodes, the sums, the counters.

    The counters: the transitions kept, where this episode's begin, and the most steps an
    episode has (``L``, as ``mc_prediction``'s: one that goes on longer is cut there).
    """
    capacity = max(context.episodes, 1) * context.max_steps
    return (
        policy_table(context),
        np.zeros(capacity, dtype=np.int64),
        np.zeros(capacity, dtype=np.float64),
        np.zeros(capacity, dtype=np.int64),
        np.zeros(capacity, dtype=np.float64),
        np.zeros(context.n_states, dtype=np.float64),
        np.array([0, 0, context.max_steps], dtype=np.int64),
    )


TARGET = Param(
    "target", "td",
    "what the batch learns: td (TD(0)'s one-step targets) or mc (constant-alpha MC's returns)",
    kind="choice", choices=TARGETS,
)  # fmt: skip
TOLERANCE = Param(
    "tolerance", 1e-6,
    "the batch has converged when a pass moves the values by less than this in total",
    low=0.0, low_open=True,
)  # fmt: skip
MAX_PASSES = Param(
    "max_passes", 100_000, "the most passes over the batch after an episode", kind="int", low=1
)

PARAMS = (POLICY, TARGET, TOLERANCE, MAX_PASSES, *POLICY_SOURCE)
"""the parameters, in the order the hooks get them"""
TARGET_AT = param_index(PARAMS, TARGET)
TOLERANCE_AT = param_index(PARAMS, TOLERANCE)
MAX_PASSES_AT = param_index(PARAMS, MAX_PASSES)


ALGORITHM = Algorithm(
    name="batch_prediction",
    no_sample_average="its alpha is the step of an iteration over the whole batch run to convergence, not a weight of one target",
    description="batch updating: TD(0) or constant-alpha MC on all episodes seen, to convergence",
    book="6.3",
    task="prediction",
    not_on_tiles="its sums are kept per state",
    step=step,
    start=first_policy_action,
    params=PARAMS,
    memory=batch_memory,
    memory_names=(
        "policy", "batch_states", "batch_targets", "batch_bootstrap_states",
        "batch_bootstrap_weights", "increments", "counters",
    ),
    growing_memory=(1, 2, 3, 4),
)  # fmt: skip
