"""A user's algorithm, in one file outside the package: Expected SARSA with a fixed behaviour.

It acts epsilon-greedily with its own fixed ``agent.behaviour`` rate (not the config's
schedule) and learns the value of the scheduled epsilon-greedy policy, so it is off-policy;
it counts its updates per state in its memory and divides alpha by that count (a step size
that shrinks as a state is seen more), so that a resumed run matches only if the checkpoint
carried that memory. Registering it is all it takes: configs accept
``agent.algorithm: fixed_behaviour_expected_sarsa`` and ``agent.behaviour``, both engines
train it, checkpoints keep its memory.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from cartpole_q.rl.algorithm import Algorithm, MemoryContext, Param
from cartpole_q.rl.algorithms import register
from cartpole_q.rl.tabular import (
    ENDED,
    Rates,
    Transition,
    epsilon_greedy,
    expected_value,
    update,
)


def start(q: Any, memory: Any, params: Any, state: int, epsilon: float, rng: Any) -> int:
    """The first action: epsilon-greedy with the fixed behaviour rate."""
    return epsilon_greedy(q, state, params[0], rng)


def step(q: Any, memory: Any, params: Any, transition: Transition, rates: Rates, rng: Any) -> int:
    """Target: the scheduled policy's expectation; behaviour: the fixed rate."""
    state, action, reward = transition.state, transition.action, transition.reward
    next_state, terminated = transition.next_state, transition.terminated
    alpha, gamma, epsilon = rates.alpha, rates.gamma, rates.epsilon
    counts = memory[0]
    counts[state] += 1
    target = reward
    if not terminated:
        target = reward + gamma * expected_value(q, next_state, epsilon)
    update(q, state, action, target, alpha / counts[state])
    if terminated or transition.truncated:
        return ENDED
    return epsilon_greedy(q, next_state, params[0], rng)


def memory(context: MemoryContext) -> tuple[np.ndarray, ...]:
    """Updates per state."""
    return (np.zeros(context.n_states, dtype=np.int64),)


ALGORITHM = register(
    Algorithm(
        name="fixed_behaviour_expected_sarsa",
        description="Expected SARSA learning the scheduled policy while acting with a fixed rate",
        step=step,
        start=start,
        params=(
            Param("behaviour", 0.2, "the fixed exploration rate it acts with", low=0.0, high=1.0),
        ),
        memory=memory,
        memory_names=("updates",),
    )
)
