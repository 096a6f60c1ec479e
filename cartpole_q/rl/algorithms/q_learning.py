"""Q-learning (Watkins 1989; Sutton & Barto 6.5): off-policy TD control.

Per step: ``y = r + gamma * max_b Q(s', b)`` (``y = r`` when terminated; a step that is only
truncated bootstraps), ``Q(s, a) += alpha * (y - Q(s, a))``, then the next action is drawn
epsilon-greedily from the updated table (not at the episode's end).

>>> import numpy as np
>>> q = np.array([[1.0, 0.0], [2.0, 3.0]])
>>> step(q, (), (0.0,), Transition(0, 0, 1.0, 1, False, True),
...     Rates(0.5, 0.9, 0.0), np.random.default_rng(0))
-1
>>> float(q[0, 0])  # truncated, so it bootstraps: 1 + 0.5 * (1 + 0.9 * 3 - 1) = 2.35
2.35
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
    best_value,
    update,
)


def step(
    q: Table, memory: Memory, params: Params, transition: Transition, rates: Rates, rng: Rng
) -> int:
    """Update toward ``r + gamma * max_b Q(s', b)``, then draw the next action."""
    state, action, reward = transition.state, transition.action, transition.reward
    next_state, terminated = transition.next_state, transition.terminated
    truncated = transition.truncated
    alpha, gamma, epsilon = rates.alpha, rates.gamma, rates.epsilon
    target = reward
    if not terminated:
        target = reward + gamma * best_value(q, next_state)
    update(q, state, action, target, alpha)
    if terminated or truncated:
        return ENDED
    return behaviour_action(q, params, next_state, epsilon, rng)


ALGORITHM = Algorithm(
    name="q_learning",
    no_sample_average="",  # every step size reaches update
    description="Q-learning: one-step off-policy TD control, target r + gamma * max_b Q(s', b)",
    book="6.5",
    step=step,
)
