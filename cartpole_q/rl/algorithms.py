"""The tabular TD algorithms: one compiled step function each, and their dispatch.

Stated precisely in ``design.md`` ("Algorithms"); per step, after the environment returned
``(reward, next_state, terminated, truncated)`` for ``action`` taken in ``state``:

- ``visits[state, action] += 1`` first, always;
- a terminated step's target is the reward alone; a step that is only truncated
  bootstraps (a time limit is not a terminal state);
- ``Q(s, a) += alpha * (y - Q(s, a))``;
- the next action is the epsilon-greedy draw for the next state, made only when the
  episode goes on, except for SARSA, which draws it before its update, also at truncation.

Every function takes the same arguments, so that the training loops of both engines call
:func:`learn_step` and :func:`first_action` with an algorithm code and nothing is written
twice. ``q_b`` is Double Q-learning's second table; the other algorithms ignore it (an
empty ``(0, n_actions)`` array is passed).

>>> import numpy as np
>>> q, q_b = np.array([[1.0, 0.0], [2.0, 3.0]]), np.zeros((0, 2))
>>> visits = np.zeros((2, 2), dtype=np.int64)
>>> rng = np.random.default_rng(0)
>>> learn_step(Q_LEARNING, q, q_b, visits, 0, 0, 1.0, 1, False, True, 0.5, 0.9, 0.0, rng)
-1
>>> float(q[0, 0])  # truncated, so it bootstraps: 1 + 0.5 * (1 + 0.9 * 3 - 1) = 2.35
2.35
"""

from __future__ import annotations

import numpy as np
from numba import njit

from cartpole_q.numba_cache import configure as configure_numba_cache
from cartpole_q.rl.policy import (
    best_action,
    best_action_of_sum,
    best_value,
    epsilon_greedy,
    epsilon_greedy_on_sum,
)

configure_numba_cache()  # before any cache=True function is defined

ALGORITHMS = ("q_learning", "sarsa", "expected_sarsa", "double_q_learning")
"""``agent.algorithm`` values; the index of each is the code the compiled code takes"""
Q_LEARNING, SARSA, EXPECTED_SARSA, DOUBLE_Q_LEARNING = range(len(ALGORITHMS))
ENDED = -1
"""the next action returned when the episode ended"""


@njit(cache=True, nogil=True, inline="always")
def _update(q: np.ndarray, state: int, action: int, target: float, alpha: float) -> None:
    q[state, action] += alpha * (target - q[state, action])


@njit(cache=True, nogil=True, inline="always")
def q_learning_step(q, q_b, visits, state, action, reward, next_state, terminated, truncated,
                    alpha, gamma, epsilon, rng):  # fmt: skip
    """Q-learning: target ``r + gamma * max_b Q(s', b)``; update, then draw the next action."""
    visits[state, action] += 1
    target = reward
    if not terminated:
        target = reward + gamma * best_value(q, next_state)
    _update(q, state, action, target, alpha)
    if terminated or truncated:
        return ENDED
    return epsilon_greedy(q, next_state, epsilon, rng)


@njit(cache=True, nogil=True, inline="always")
def sarsa_step(q, q_b, visits, state, action, reward, next_state, terminated, truncated,
               alpha, gamma, epsilon, rng):  # fmt: skip
    """SARSA: draw ``a'`` first (also at truncation), target ``r + gamma * Q(s', a')``."""
    visits[state, action] += 1
    target = reward
    next_action = ENDED
    if not terminated:
        next_action = epsilon_greedy(q, next_state, epsilon, rng)
        target = reward + gamma * q[next_state, next_action]
    _update(q, state, action, target, alpha)
    if terminated or truncated:
        return ENDED
    return next_action


@njit(cache=True, nogil=True, inline="always")
def expected_sarsa_value(q: np.ndarray, state: int, epsilon: float) -> float:
    """``(1 - epsilon) * Q(s, g) + (epsilon / n) * S``, ``S`` summed in action order."""
    n_actions = q.shape[1]
    total = q[state, 0]
    for action in range(1, n_actions):
        total += q[state, action]
    greedy = best_action(q, state)
    return (1.0 - epsilon) * q[state, greedy] + (epsilon / n_actions) * total


@njit(cache=True, nogil=True, inline="always")
def expected_sarsa_step(q, q_b, visits, state, action, reward, next_state, terminated, truncated,
                        alpha, gamma, epsilon, rng):  # fmt: skip
    """Expected SARSA: the target averages ``Q(s', .)`` under the epsilon-greedy policy."""
    visits[state, action] += 1
    target = reward
    if not terminated:
        target = reward + gamma * expected_sarsa_value(q, next_state, epsilon)
    _update(q, state, action, target, alpha)
    if terminated or truncated:
        return ENDED
    return epsilon_greedy(q, next_state, epsilon, rng)


@njit(cache=True, nogil=True, inline="always")
def double_q_learning_step(q, q_b, visits, state, action, reward, next_state, terminated,
                           truncated, alpha, gamma, epsilon, rng):  # fmt: skip
    """Double Q-learning: a coin (``rng.random() < 0.5``) picks the table to update.

    The updated table chooses the next state's greedy action, the other one values it;
    actions are chosen epsilon-greedily on ``A + B``.
    """
    visits[state, action] += 1
    if rng.random() < 0.5:
        updated, other = q, q_b
    else:
        updated, other = q_b, q
    target = reward
    if not terminated:
        target = reward + gamma * other[next_state, best_action(updated, next_state)]
    _update(updated, state, action, target, alpha)
    if terminated or truncated:
        return ENDED
    return epsilon_greedy_on_sum(q, q_b, next_state, epsilon, rng)


@njit(cache=True, nogil=True, inline="always")
def learn_step(algorithm, q, q_b, visits, state, action, reward, next_state, terminated,
               truncated, alpha, gamma, epsilon, rng):  # fmt: skip
    """Learn from one transition with the algorithm ``algorithm`` (a code of :data:`ALGORITHMS`).

    Returns:
        The next action, or :data:`ENDED` when the episode ended.
    """
    if algorithm == SARSA:
        return sarsa_step(q, q_b, visits, state, action, reward, next_state, terminated,
                          truncated, alpha, gamma, epsilon, rng)  # fmt: skip
    if algorithm == EXPECTED_SARSA:
        return expected_sarsa_step(q, q_b, visits, state, action, reward, next_state,
                                   terminated, truncated, alpha, gamma, epsilon, rng)  # fmt: skip
    if algorithm == DOUBLE_Q_LEARNING:
        return double_q_learning_step(q, q_b, visits, state, action, reward, next_state,
                                      terminated, truncated, alpha, gamma, epsilon, rng)  # fmt: skip
    return q_learning_step(q, q_b, visits, state, action, reward, next_state, terminated,
                           truncated, alpha, gamma, epsilon, rng)  # fmt: skip


@njit(cache=True, nogil=True, inline="always")
def first_action(algorithm, q, q_b, state, epsilon, rng):
    """The first action of an episode: epsilon-greedy (on ``A + B`` for Double Q-learning)."""
    if algorithm == DOUBLE_Q_LEARNING:
        return epsilon_greedy_on_sum(q, q_b, state, epsilon, rng)
    return epsilon_greedy(q, state, epsilon, rng)


@njit(cache=True, nogil=True, inline="always")
def greedy_action(algorithm, q, q_b, state):
    """The greedy action of the learned table(s), the lowest on ties."""
    if algorithm == DOUBLE_Q_LEARNING:
        return best_action_of_sum(q, q_b, state)
    return best_action(q, state)
