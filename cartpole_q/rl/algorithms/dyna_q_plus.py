"""Dyna-Q+ (Sutton & Barto 8.3): Dyna-Q with a bonus for pairs not tried for long.

As Dyna-Q, with a counter of real steps ``time``: each real step first sets ``time = time + 1``
and ``last_tried(s, a) = time``. Planning draws a state seen, then **any** action
(``rng.integers(0, n)``); a pair never tried leads back to its state with reward 0; the
planning target adds ``kappa * sqrt(time - last_tried)``. The direct update has no bonus. The
contract: docs/algorithms.md.

>>> import numpy as np
>>> q = np.zeros((2, 2))
>>> memory = dyna_plus_memory(MemoryContext(2, 2, 0.0, {}, 10))
>>> step(q, memory, (0.0, 0.1, 0.0), Transition(0, 1, 1.0, 1, False, False),
...     Rates(0.5, 1.0, 0.0), np.random.default_rng(0))
0
>>> float(q[0, 1]), int(memory[6][1]), int(memory[7][1])
(0.5, 1, 1)
"""

from __future__ import annotations

import math

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
)


@compilable
def plan_with_bonus(
    q: Table, model: Memory, last_tried: np.ndarray, steps: int, kappa: float, alpha: float,
    gamma: float, rng: Rng,
) -> None:  # fmt: skip
    """``steps`` planning updates with the exploration bonus ``kappa * sqrt(tau)``."""
    next_states, rewards, terminals = model[0], model[1], model[2]
    seen, counters = model[3], model[6]
    n_actions = action_count(q)
    time = counters[1]
    for _ in range(steps):
        state = seen[rng.integers(0, counters[0])]
        action = int(rng.integers(0, n_actions))
        flat = state * n_actions + action
        reward, after, terminal = 0.0, state, False  # never tried: back to itself, reward 0
        if next_states[flat] >= 0:
            reward, after, terminal = rewards[flat], next_states[flat], terminals[flat] == 1
        tau = float(time - last_tried[flat])
        bonus = reward + kappa * math.sqrt(tau)
        target = bonus
        if not terminal:
            target = bonus + gamma * best_value(q, after)
        update(q, state, action, target, alpha)


def step(
    q: Table, memory: Memory, params: Params, transition: Transition, rates: Rates, rng: Rng
) -> int:
    """Count the step, learn from it, remember it, plan with bonuses, then draw."""
    state, action, reward = transition.state, transition.action, transition.reward
    next_state, terminated = transition.next_state, transition.terminated
    truncated = transition.truncated
    alpha, gamma, epsilon = rates.alpha, rates.gamma, rates.epsilon
    n_actions = action_count(q)
    counters, last_tried = memory[6], memory[7]
    counters[1] += 1
    last_tried[state * n_actions + action] = counters[1]
    target = reward
    if not terminated:
        target = reward + gamma * best_value(q, next_state)
    update(q, state, action, target, alpha)
    remember(memory, state, action, next_state, reward, terminated, n_actions)
    plan_with_bonus(
        q, memory, last_tried, int(params[PLANNING_STEPS_AT]), params[KAPPA_AT], alpha, gamma, rng
    )
    if terminated or truncated:
        return ENDED
    return behaviour_action(q, params, next_state, epsilon, rng)


def dyna_plus_memory(context: MemoryContext) -> tuple[np.ndarray, ...]:
    """An empty model, and every pair last tried at time 0."""
    pairs = context.n_states * context.n_actions
    return (*model_memory(context.n_states, context.n_actions), np.zeros(pairs, dtype=np.int64))


KAPPA = Param("kappa", 0.001, "the exploration bonus kappa * sqrt(steps since tried)", low=0.0)

PARAMS = (PLANNING_STEPS, KAPPA)
"""the parameters, in the order the hooks get them"""
PLANNING_STEPS_AT = param_index(PARAMS, PLANNING_STEPS)
KAPPA_AT = param_index(PARAMS, KAPPA)


ALGORITHM = Algorithm(
    name="dyna_q_plus",
    no_sample_average="",  # every step size reaches update
    description="Dyna-Q+: Dyna-Q with a bonus for pairs not tried for long (agent.kappa)",
    book="8.3",
    not_on_tiles=MODEL_NOT_ON_TILES,
    step=step,
    params=PARAMS,
    memory=dyna_plus_memory,
    memory_names=(*MODEL_MEMORY_NAMES, "model_last_tried"),
)  # fmt: skip
