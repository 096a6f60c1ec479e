"""n-step TD prediction (Sutton & Barto 7.1): state values from n-step returns.

A step is settled ``n`` steps later (or when the episode ends): ``V(S)`` moves toward
``R_1 + gamma R_2 + ... + gamma^(k-1) R_k + gamma^k V(s')`` (no ``V(s')`` after a terminal
state), as n-step SARSA settles ``Q`` with the action 0. With ``n = 1`` it is TD(0), byte
for byte. The contract: docs/algorithms.md, "Prediction".

>>> import numpy as np
>>> v = np.array([[0.0], [0.0], [0.0]])
>>> memory = n_step_memory(MemoryContext(3, 2, 0.0, {"policy": "random", "n": 2}, 10))
>>> rng = np.random.default_rng(0)
>>> step(v, memory, (0.0, 2.0), Transition(0, 0, 1.0, 1, False, False),
...     Rates(0.5, 0.5, 0.0), rng) in (0, 1)
True
>>> step(v, memory, (0.0, 2.0), Transition(1, 0, 2.0, 2, True, False), Rates(0.5, 0.5, 0.0), rng)
-1
>>> float(v[0, 0]), float(v[1, 0])  # toward 1 + 0.5 * 2 and 2
(1.0, 1.0)
"""

from __future__ import annotations

import numpy as np

from cartpole_q.rl.algorithm import Algorithm, MemoryContext
from cartpole_q.rl.pending import N, oldest_is_due, push, queue_memory, settle_oldest
from cartpole_q.rl.prediction import (
    POLICY,
    POLICY_SOURCE,
    first_policy_action,
    policy_action,
    policy_table,
)
from cartpole_q.rl.tabular import ENDED, Memory, Params, Rates, Rng, Table, Transition


def step(
    q: Table, memory: Memory, params: Params, transition: Transition, rates: Rates, rng: Rng
) -> int:
    """Queue the step, then settle what is due; the next action is the policy's."""
    state, reward, next_state = transition.state, transition.reward, transition.next_state
    terminated, truncated = transition.terminated, transition.truncated
    policy, states, actions, rewards, counter = (
        memory[0],
        memory[1],
        memory[2],
        memory[3],
        memory[4],
    )
    push(states, actions, rewards, counter, state, 0, reward)
    ended = terminated or truncated
    while oldest_is_due(counter, states.shape[0], ended):  # terminated only if ended
        settle_oldest(q, states, actions, rewards, counter, next_state, 0, not terminated,
                      rates)  # fmt: skip
    if ended:
        return ENDED
    return policy_action(policy, next_state, params, rng)


def n_step_memory(context: MemoryContext) -> tuple[np.ndarray, ...]:
    """The policy and the queue of pending steps, for ``agent.n`` of them."""
    return (policy_table(context), *queue_memory(int(context.params["n"])))


ALGORITHM = Algorithm(
    name="n_step_td",
    no_sample_average="",  # every step size reaches update
    description="n-step TD prediction: the state values of agent.policy from n-step returns (agent.n)",
    book="7.1",
    task="prediction",
    step=step,
    start=first_policy_action,
    params=(POLICY, N, *POLICY_SOURCE),
    memory=n_step_memory,
    memory_names=("policy", "pending_states", "pending_actions", "pending_rewards", "queue"),
)
