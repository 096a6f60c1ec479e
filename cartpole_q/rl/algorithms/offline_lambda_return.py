"""The offline λ-return algorithm (Sutton & Barto 12.1, Figure 12.3): V toward λ-returns, after the episode.

Nothing changes during an episode; it is recorded. When it ends, the λ-return of every step
is computed backwards from ``V`` as it then is, ``G_t = R_{t+1} + gamma * ((1 - lambda) *
V(S_{t+1}) + lambda * G_{t+1})`` (the last step's: its reward plus ``gamma * V(s')`` when a
time limit cut it), and then each step in order moves ``V(S_t)`` toward its return by
``alpha`` (eq. 12.4). The contract: docs/algorithms.md, "Prediction".

>>> import numpy as np
>>> v = np.array([[0.5], [0.5], [0.0]])
>>> memory = lambda_return_memory(MemoryContext(3, 2, 0.5, {"policy": "random"}, 5))
>>> rng = np.random.default_rng(0)
>>> params = (0.0, 0.5)  # policy random, lambda 0.5
>>> step(v, memory, params, Transition(0, 0, 0.0, 1, False, False),
...     Rates(0.1, 1.0, 0.0), rng) in (0, 1)
True
>>> step(v, memory, params, Transition(1, 0, 1.0, 2, True, False), Rates(0.1, 1.0, 0.0), rng)
-1
>>> float(v[1, 0])  # G_1 = 1: 0.5 + 0.1 * (1 - 0.5)
0.55
>>> float(v[0, 0])  # G_0 = 0 + (0.5 * 0.5 + 0.5 * 1) = 0.75, from V(1) before the updates
0.525
"""

from __future__ import annotations

import numpy as np

from cartpole_q.rl.algorithm import Algorithm, MemoryContext, param_index
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
from cartpole_q.rl.traces import LAMBDA


def step(
    q: Table, memory: Memory, params: Params, transition: Transition, rates: Rates, rng: Rng
) -> int:
    """Record the step; at the episode's end, move every visit toward its λ-return."""
    state, reward, next_state = transition.state, transition.reward, transition.next_state
    terminated, truncated = transition.terminated, transition.truncated
    alpha, gamma = rates.alpha, rates.gamma
    policy, states, rewards, returns, length = memory[0], memory[1], memory[2], memory[3], memory[4]
    t = length[0]
    states[t], rewards[t] = state, reward
    length[0] = t + 1
    if not (terminated or truncated or length[0] == states.shape[0]):
        return policy_action(policy, next_state, params, rng)
    lam = params[LAMBDA_AT]
    last = length[0] - 1
    tail = 0.0 if terminated else value(q, next_state, 0)
    target = rewards[last] + gamma * tail
    returns[last] = target
    for t in range(last - 1, -1, -1):
        target = rewards[t] + gamma * ((1.0 - lam) * value(q, states[t + 1], 0) + lam * target)
        returns[t] = target
    for t in range(length[0]):
        update(q, states[t], 0, returns[t], alpha)
    length[0] = 0
    return ENDED


def lambda_return_memory(context: MemoryContext) -> tuple[np.ndarray, ...]:
    """The policy, an empty episode record (states, rewards, λ-returns) and its length."""
    return (
        policy_table(context),
        np.zeros(context.max_steps, dtype=np.int64),
        np.zeros(context.max_steps, dtype=np.float64),
        np.zeros(context.max_steps, dtype=np.float64),
        np.zeros(1, dtype=np.int64),
    )


PARAMS = (POLICY, LAMBDA, *POLICY_SOURCE)
"""the parameters, in the order the hooks get them"""
LAMBDA_AT = param_index(PARAMS, LAMBDA)


ALGORITHM = Algorithm(
    name="offline_lambda_return",
    no_sample_average="",  # every step size reaches update
    description="the offline lambda-return algorithm: V toward each step's lambda-return after the episode",
    book="12.1",
    task="prediction",
    step=step,
    start=first_policy_action,
    params=PARAMS,
    memory=lambda_return_memory,
    memory_names=(
        "policy",
        "episode_states",
        "episode_rewards",
        "lambda_returns",
        "episode_length",
    ),
)
