"""TD(0) prediction (Sutton & Barto 6.1): the state values of a fixed policy, one step at a time.

Per step: ``V(s) = V(s) + alpha * (y - V(s))`` with ``y = r + gamma * V(s')`` (``r`` when
terminated), then the next action is the evaluated policy's (:mod:`cartpole_q.rl.prediction`).
The contract: docs/algorithms.md, "Prediction".

>>> import numpy as np
>>> v = np.array([[0.5], [0.5], [0.0]])
>>> memory = (policy_table(MemoryContext(3, 2, 0.5, {"policy": "random"}, 10)),)
>>> step(v, memory, (0.0,), Transition(1, 0, 0.0, 0, False, False),
...     Rates(0.1, 1.0, 0.0), np.random.default_rng(0)) in (0, 1)
True
>>> float(v[1, 0])  # 0.5 + 0.1 * (0 + 0.5 - 0.5): unchanged
0.5
>>> step(v, memory, (0.0,), Transition(0, 0, 1.0, 2, True, False),
...     Rates(0.1, 1.0, 0.0), np.random.default_rng(0))
-1
>>> float(v[0, 0])  # 0.5 + 0.1 * (1 - 0.5)
0.55
"""

from __future__ import annotations

import numpy as np

from cartpole_q.rl.algorithm import Algorithm, MemoryContext
from cartpole_q.rl.prediction import (
    POLICY,
    POLICY_SOURCE,
    first_policy_action,
    policy_action,
    policy_table,
)
from cartpole_q.rl.tabular import (
    ENDED,
    Memory,
    Params,
    Rates,
    Rng,
    Table,
    Transition,
    update,
    value,
)


def step(
    q: Table, memory: Memory, params: Params, transition: Transition, rates: Rates, rng: Rng
) -> int:
    """Move ``V(s)`` toward ``r + gamma * V(s')``; the next action is the policy's."""
    state, reward, next_state = transition.state, transition.reward, transition.next_state
    terminated, truncated = transition.terminated, transition.truncated
    alpha, gamma = rates.alpha, rates.gamma
    target = reward
    if not terminated:
        target = reward + gamma * value(q, next_state, 0)
    update(q, state, 0, target, alpha)
    if terminated or truncated:
        return ENDED
    return policy_action(memory[0], next_state, params, rng)


def memory(context: MemoryContext) -> tuple[np.ndarray, ...]:
    """The evaluated policy."""
    return (policy_table(context),)


ALGORITHM = Algorithm(
    name="td",
    no_sample_average="",  # every step size reaches update
    description="TD(0) prediction: the state values of agent.policy, learnt one step at a time",
    book="6.1",
    task="prediction",
    step=step,
    start=first_policy_action,
    params=(POLICY, *POLICY_SOURCE),
    memory=memory,
    memory_names=("policy",),
)
