"""Double Q-learning (van Hasselt 2010; Sutton & Barto 6.7): two tables, no maximisation bias.

Memory: the second table ``B`` (``Q`` is ``A``), both starting at ``q_init``, and under
``agent.alpha: sample_average`` ``B``'s update counts (``A``'s are the run's). Per step a coin
``u = rng.random()`` is drawn first; if ``u < 0.5`` table ``A`` is updated with
``g = argmax_b A(s', b)``, ``y = r + gamma * B(s', g)``; else ``B`` with
``g = argmax_b B(s', b)``, ``y = r + gamma * A(s', g)`` (``y = r`` when terminated). Every
action, an episode's first included, is epsilon-greedy on ``A + B``. ``q_table.npy`` holds
``0.5 * (A + B)`` (halving is exact: the same greedy actions and ties as ``A + B``).

>>> import numpy as np
>>> a, b = np.zeros((2, 2)), np.array([[0.0, 0.0], [1.0, 3.0]])
>>> step(a, (b,), (0.0,), Transition(0, 0, 1.0, 1, False, False),
...     Rates(1.0, 1.0, 0.0), np.random.default_rng(2))
1
>>> float(a[0, 0]), float(b[0, 0])  # the coin picked A: 1 + B(1, argmax A(1, .) = 0) = 2
(2.0, 0.0)
"""

from __future__ import annotations

import numpy as np

from cartpole_q.rl.algorithm import Algorithm, MemoryContext
from cartpole_q.rl.tabular import (
    ENDED,
    Memory,
    Params,
    Rates,
    Rng,
    Table,
    Transition,
    action_count,
    averaged_variant,
    best_action,
    compilable,
    random_ties,
    update,
    value,
    with_weights,
)


@compilable
def best_action_of_sum(q_a: Table, q_b: Table, state: int) -> int:
    """``argmax_a (A(state, a) + B(state, a))``, the lowest action on ties."""
    best = 0
    best_sum = value(q_a, state, 0) + value(q_b, state, 0)
    for action in range(1, action_count(q_a)):
        total = value(q_a, state, action) + value(q_b, state, action)
        if total > best_sum:
            best, best_sum = action, total
    return best


@compilable
def tied_best_action_of_sum(q_a: Table, q_b: Table, state: int, rng: Rng) -> int:
    """One of the actions with the largest ``A + B``, as ``tied_best_action`` picks on ``Q``."""
    best = best_action_of_sum(q_a, q_b, state)
    best_sum = value(q_a, state, best) + value(q_b, state, best)
    tied = 0
    for action in range(action_count(q_a)):
        if value(q_a, state, action) + value(q_b, state, action) == best_sum:
            tied += 1
    if tied <= 1:
        return best
    pick = int(rng.integers(0, tied))
    for action in range(action_count(q_a)):
        if value(q_a, state, action) + value(q_b, state, action) == best_sum:
            if pick == 0:
                return action
            pick -= 1
    return best


@compilable
def epsilon_greedy_on_sum(
    q_a: Table, q_b: Table, params: Params, state: int, epsilon: float, rng: Rng
) -> int:
    """Epsilon-greedy on ``A + B``, with the draws of ``behaviour_action``."""
    if epsilon >= 1.0 or (epsilon > 0.0 and rng.random() < epsilon):
        return int(rng.integers(0, action_count(q_a)))
    if random_ties(params):
        return tied_best_action_of_sum(q_a, q_b, state, rng)
    return best_action_of_sum(q_a, q_b, state)


@compilable
def step_size_of_b(alpha: float, memory: Memory) -> float:
    """The step size of an update of ``B``: the episode's ``alpha``, as ``A``'s."""
    return alpha


@averaged_variant(step_size_of_b)
def update_counts_of_b(counts_of_a: np.ndarray, memory: Memory) -> np.ndarray:
    """Under sample averages, ``B``'s own update counts (``memory_1``; ``A``'s are the run's)."""
    counts: np.ndarray = memory[1]
    return counts


def start(q: Table, memory: Memory, params: Params, state: int, epsilon: float, rng: Rng) -> int:
    """The first action: epsilon-greedy on ``A + B``."""
    return epsilon_greedy_on_sum(q, with_weights(q, memory[0]), params, state, epsilon, rng)


def step(
    q: Table, memory: Memory, params: Params, transition: Transition, rates: Rates, rng: Rng
) -> int:
    """A coin picks the table to update; the other one values the updated one's choice."""
    state, action, reward = transition.state, transition.action, transition.reward
    next_state, terminated = transition.next_state, transition.terminated
    truncated = transition.truncated
    alpha, gamma, epsilon = rates.alpha, rates.gamma, rates.epsilon
    q_b = with_weights(q, memory[0])
    # Two explicit branches rather than swapped names: an array alias costs reference
    # counting on every step.
    if rng.random() < 0.5:
        target = reward
        if not terminated:
            target = reward + gamma * value(q_b, next_state, best_action(q, next_state))
        update(q, state, action, target, alpha)
    else:
        target = reward
        if not terminated:
            target = reward + gamma * value(q, next_state, best_action(q_b, next_state))
        update(q_b, state, action, target, step_size_of_b(alpha, memory))
    if terminated or truncated:
        return ENDED
    return epsilon_greedy_on_sum(q, q_b, params, next_state, epsilon, rng)


def memory(context: MemoryContext) -> tuple[np.ndarray, ...]:
    """Table ``B``, at ``q_init`` like ``A`` (and under sample averages its counts, zeros)."""
    shape = (context.n_states, context.n_actions)
    b = np.full(shape, context.q_init, dtype=np.float64)
    if context.averaged:
        return (b, np.zeros(shape, dtype=np.float64))
    return (b,)


def policy(q: np.ndarray, memory: tuple[np.ndarray, ...]) -> np.ndarray:
    """``0.5 * (A + B)``."""
    mean: np.ndarray = 0.5 * (q + memory[0])
    return mean


ALGORITHM = Algorithm(
    name="double_q_learning",
    no_sample_average="",  # every step size reaches update (B's through step_size_of_b)
    description="Double Q-learning: two tables, a coin picks which to update; acts on A + B",
    book="6.7",
    step=step,
    start=start,
    memory=memory,
    memory_names=("q_b", "q_b_update_counts"),
    policy=policy,
)
