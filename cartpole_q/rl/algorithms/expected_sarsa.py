"""Expected SARSA (van Seijen et al. 2009; Sutton & Barto 6.6).

Per step: ``y = r + gamma * ((1 - epsilon) * Q(s', g) + (epsilon / n) * S)``, ``g`` the greedy
action of ``s'``, ``S = Q(s', 0) + Q(s', 1) + ...`` summed in action order (``y = r`` when
terminated); update, then draw the next action from the updated table.

>>> import numpy as np
>>> q = np.array([[0.0, 0.0], [2.0, 4.0]])
>>> step(q, (), (0.0,), Transition(0, 0, 0.0, 1, False, False),
...     Rates(1.0, 1.0, 0.5), np.random.default_rng(0)) in (0, 1)
True
>>> float(q[0, 0])  # 0.5 * 4 + 0.25 * 6
3.5
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
    expected_value,
    update,
)


def step(
    q: Table, memory: Memory, params: Params, transition: Transition, rates: Rates, rng: Rng
) -> int:
    """Update toward the expected value of ``s'`` under epsilon-greedy, then draw."""
    state, action, reward = transition.state, transition.action, transition.reward
    next_state, terminated = transition.next_state, transition.terminated
    truncated = transition.truncated
    alpha, gamma, epsilon = rates.alpha, rates.gamma, rates.epsilon
    target = reward
    if not terminated:
        target = reward + gamma * expected_value(q, next_state, epsilon)
    update(q, state, action, target, alpha)
    if terminated or truncated:
        return ENDED
    return behaviour_action(q, params, next_state, epsilon, rng)


ALGORITHM = Algorithm(
    name="expected_sarsa",
    no_sample_average="",  # every step size reaches update
    description="Expected SARSA: target r + gamma * the epsilon-greedy expectation of Q(s', .)",
    book="6.6",
    step=step,
)
