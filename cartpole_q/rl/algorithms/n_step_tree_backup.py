"""n-step tree backup (Sutton & Barto 7.5): off-policy n-step returns without importance sampling.

The target policy is epsilon-greedy on ``Q`` (greedy at epsilon 0, the book's case), so that
``n = 1`` is Expected SARSA, byte for byte. A step is settled ``n`` steps later (or when the
episode ends) with the tree-backup return: from the newest step backwards,
``G = R + gamma * (sum_{c != A} pi(c | S) Q(S, c) + pi(A | S) G)`` over the later steps'
states and actions, the leaf ``R + gamma * E(s')`` (``R`` after a terminal state). The next
action is drawn after the update, as Expected SARSA does. The contract: docs/algorithms.md.

>>> import numpy as np
>>> q = np.array([[0.0, 0.0], [2.0, 4.0]])
>>> step(q, queue_memory(1), (1.0, 0.0), Transition(0, 0, 0.0, 1, False, False),
...     Rates(1.0, 1.0, 0.5), np.random.default_rng(0)) in (0, 1)
True
>>> float(q[0, 0])  # as Expected SARSA: 0.5 * 4 + 0.25 * 6
3.5
"""

from __future__ import annotations

import numpy as np

from cartpole_q.rl.algorithm import Algorithm, MemoryContext
from cartpole_q.rl.pending import N, drop_oldest, oldest_is_due, push, queue_memory, slot
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
    best_action,
    compilable,
    expected_value,
    policy_probability,
    update,
    value,
)


@compilable
def settle_oldest(
    q: Table, states: np.ndarray, actions: np.ndarray, rewards: np.ndarray,
    counter: np.ndarray, next_state: int, terminated: bool, rates: Rates,
) -> None:  # fmt: skip
    """Update the oldest pending step toward its tree-backup return, and remove it."""
    alpha, gamma, epsilon = rates.alpha, rates.gamma, rates.epsilon
    n = states.shape[0]
    n_actions = action_count(q)
    pending = counter[1]
    target = rewards[slot(counter, n, pending - 1)]
    if not terminated:
        target = target + gamma * expected_value(q, next_state, epsilon)
    for m in range(pending - 2, -1, -1):
        later = slot(counter, n, m + 1)
        state, action = states[later], actions[later]
        greedy = best_action(q, state)
        others = 0.0
        for other in range(n_actions):
            if other != action:
                others = others + policy_probability(other, greedy, epsilon, n_actions) * value(
                    q, state, other
                )
        taken = policy_probability(action, greedy, epsilon, n_actions)
        target = rewards[slot(counter, n, m)] + gamma * (others + taken * target)
    oldest = slot(counter, n, 0)
    update(q, states[oldest], actions[oldest], target, alpha)
    drop_oldest(counter, n)


def step(
    q: Table, memory: Memory, params: Params, transition: Transition, rates: Rates, rng: Rng
) -> int:
    """Queue the step, settle what is due, then draw the next action."""
    state, action, reward = transition.state, transition.action, transition.reward
    next_state, terminated = transition.next_state, transition.terminated
    truncated = transition.truncated
    epsilon = rates.epsilon
    states, actions, rewards, counter = memory[0], memory[1], memory[2], memory[3]
    push(states, actions, rewards, counter, state, action, reward)
    ended = terminated or truncated
    while oldest_is_due(counter, states.shape[0], ended):  # terminated only if ended
        settle_oldest(q, states, actions, rewards, counter, next_state, terminated, rates)
    if ended:
        return ENDED
    return behaviour_action(q, params, next_state, epsilon, rng)


def memory(context: MemoryContext) -> tuple[np.ndarray, ...]:
    """The queue of pending steps, for ``agent.n`` of them."""
    return queue_memory(int(context.params["n"]))


ALGORITHM = Algorithm(
    name="n_step_tree_backup",
    no_sample_average="",  # every step size reaches update
    description="n-step tree backup: off-policy n-step returns without importance sampling (agent.n)",
    book="7.5",
    step=step,
    params=(N,),
    memory=memory,
    memory_names=("pending_states", "pending_actions", "pending_rewards", "queue"),
)
