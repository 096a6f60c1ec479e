"""SARSA (Rummery and Niranjan 1994; Sutton & Barto 6.4): on-policy TD control.

Per step: the next action ``a'`` is drawn epsilon-greedily for ``s'`` from the table as it
is, first (also at truncation, where ``a'`` is not played; not when terminated); then
``y = r + gamma * Q(s', a')`` (``y = r`` when terminated), ``Q(s, a) += alpha * (y - Q(s, a))``.

>>> import numpy as np
>>> q = np.array([[0.0, 0.0], [2.0, 4.0]])
>>> step(q, (), (0.0,), Transition(0, 0, 1.0, 1, False, False),
...     Rates(0.5, 1.0, 0.0), np.random.default_rng(0))
1
>>> float(q[0, 0])  # 0 + 0.5 * (1 + 4 - 0)
2.5
"""

from __future__ import annotations

from cartpole_q.rl.algorithm import Algorithm
from cartpole_q.rl.tabular import (
    ENDED,
    Memory,
    Params,
    Rates,
    Rng,
    Table,
    Transition,
    behaviour_action,
    update,
    value,
)


def step(
    q: Table, memory: Memory, params: Params, transition: Transition, rates: Rates, rng: Rng
) -> int:
    """Draw ``a'`` first, then update toward ``r + gamma * Q(s', a')``."""
    state, action, reward = transition.state, transition.action, transition.reward
    next_state, terminated = transition.next_state, transition.terminated
    truncated = transition.truncated
    alpha, gamma, epsilon = rates.alpha, rates.gamma, rates.epsilon
    target = reward
    next_action = ENDED
    if not terminated:
        next_action = behaviour_action(q, params, next_state, epsilon, rng)
        target = reward + gamma * value(q, next_state, next_action)
    update(q, state, action, target, alpha)
    if terminated or truncated:
        return ENDED
    return next_action


ALGORITHM = Algorithm(
    name="sarsa",
    no_sample_average="",  # every step size reaches update
    description="SARSA: one-step on-policy TD control, target r + gamma * Q(s', a')",
    book="6.4",
    step=step,
)
