"""n-step SARSA (Sutton & Barto 7.2): on-policy TD control with n-step returns.

Each step joins a queue of pending steps (:mod:`cartpole_q.rl.pending`); a step is settled
``n`` steps later with ``G = R_0 + gamma R_1 + ... + gamma^(n-1) R_(n-1) + gamma^n Q(s', a')``,
or when the episode ends with the rewards it saw (bootstrapping after a time limit, not
after a terminal state). ``a'`` is drawn for ``s'`` first, from the table as it is (as SARSA
draws it). With ``n = 1`` this is SARSA, byte for byte. The contract: docs/algorithms.md.

>>> import numpy as np
>>> q = np.array([[0.0, 0.0], [2.0, 4.0]])
>>> memory = queue_memory(1)
>>> step(q, memory, (1.0, 0.0), Transition(0, 0, 1.0, 1, False, False),
...     Rates(0.5, 1.0, 0.0), np.random.default_rng(0))
1
>>> float(q[0, 0])  # as SARSA: 0 + 0.5 * (1 + 4 - 0)
2.5
"""

from __future__ import annotations

import numpy as np

from cartpole_q.rl.algorithm import Algorithm, MemoryContext
from cartpole_q.rl.pending import N, oldest_is_due, push, queue_memory, settle_oldest
from cartpole_q.rl.tabular import (
    ENDED,
    Memory,
    Params,
    Rates,
    Rng,
    Table,
    Transition,
    behaviour_action,
)


def step(
    q: Table, memory: Memory, params: Params, transition: Transition, rates: Rates, rng: Rng
) -> int:
    """Queue the step, draw ``a'``, then settle what is due."""
    state, action, reward = transition.state, transition.action, transition.reward
    next_state, terminated = transition.next_state, transition.terminated
    truncated = transition.truncated
    epsilon = rates.epsilon
    states, actions, rewards, counter = memory[0], memory[1], memory[2], memory[3]
    push(states, actions, rewards, counter, state, action, reward)
    next_action = ENDED
    if not terminated:
        next_action = behaviour_action(q, params, next_state, epsilon, rng)
    ended = terminated or truncated
    while oldest_is_due(counter, states.shape[0], ended):  # terminated only if ended
        settle_oldest(q, states, actions, rewards, counter, next_state, next_action,
                      not terminated, rates)  # fmt: skip
    if ended:
        return ENDED
    return next_action


def memory(context: MemoryContext) -> tuple[np.ndarray, ...]:
    """The queue of pending steps, for ``agent.n`` of them."""
    return queue_memory(int(context.params["n"]))


ALGORITHM = Algorithm(
    name="n_step_sarsa",
    no_sample_average="",  # every step size reaches update
    description="n-step SARSA: on-policy TD control with n-step returns (agent.n)",
    book="7.2",
    step=step,
    params=(N,),
    memory=memory,
    memory_names=("pending_states", "pending_actions", "pending_rewards", "queue"),
)
