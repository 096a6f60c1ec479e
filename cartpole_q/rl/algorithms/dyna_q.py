"""Dyna-Q (Sutton & Barto 8.2): Q-learning plus planning on a learned model.

Per real step: Q-learning's update; the model remembers the transition
(:mod:`cartpole_q.rl.model`); then ``agent.planning_steps`` times, a state seen is drawn
(``rng.integers``), then an action taken in it, and Q-learning's update is made on the
remembered transition; the next action is drawn from the table after planning. With
``planning_steps = 0`` this is Q-learning, byte for byte. The contract: docs/algorithms.md.

>>> import numpy as np
>>> q = np.zeros((2, 2))
>>> memory = dyna_memory(MemoryContext(2, 2, 0.0, {}, 10))
>>> step(q, memory, (3.0, 0.0), Transition(0, 1, 1.0, 1, False, False),
...     Rates(0.5, 1.0, 0.0), np.random.default_rng(0))
0
>>> float(q[0, 1])  # once for real, three times from the model: 1 - 0.5 ** 4
0.9375
"""

from __future__ import annotations

import numpy as np

from cartpole_q.rl.algorithm import Algorithm, MemoryContext, param_index
from cartpole_q.rl.model import (
    MODEL_MEMORY_NAMES,
    MODEL_NOT_ON_TILES,
    PLANNING_STEPS,
    model_memory,
    plan_dyna_q,
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
    update,
)


def step(
    q: Table, memory: Memory, params: Params, transition: Transition, rates: Rates, rng: Rng
) -> int:
    """Learn from the real step, remember it, plan, then draw the next action."""
    state, action, reward = transition.state, transition.action, transition.reward
    next_state, terminated = transition.next_state, transition.terminated
    truncated = transition.truncated
    alpha, gamma, epsilon = rates.alpha, rates.gamma, rates.epsilon
    target = reward
    if not terminated:
        target = reward + gamma * best_value(q, next_state)
    update(q, state, action, target, alpha)
    remember(memory, state, action, next_state, reward, terminated, action_count(q))
    plan_dyna_q(q, memory, int(params[PLANNING_STEPS_AT]), alpha, gamma, rng)
    if terminated or truncated:
        return ENDED
    return behaviour_action(q, params, next_state, epsilon, rng)


def dyna_memory(context: MemoryContext) -> tuple[np.ndarray, ...]:
    """An empty model."""
    return model_memory(context.n_states, context.n_actions)


PARAMS = (PLANNING_STEPS,)
"""the parameters, in the order the hooks get them"""
PLANNING_STEPS_AT = param_index(PARAMS, PLANNING_STEPS)


ALGORITHM = Algorithm(
    name="dyna_q",
    no_sample_average="",  # every step size reaches update
    description="Dyna-Q: Q-learning plus planning on a learned model (agent.planning_steps)",
    book="8.2",
    not_on_tiles=MODEL_NOT_ON_TILES,
    step=step,
    params=PARAMS,
    memory=dyna_memory,
    memory_names=MODEL_MEMORY_NAMES,
)  # fmt: skip
