"""The tabular TD algorithms: one compiled step function each, and their dispatch.

Stated precisely in ``design.md`` ("Algorithms"); per step, after the environment returned
``(reward, next_state, terminated, truncated)`` for ``action`` taken in ``state``:

- ``visits[state, action] += 1`` first, always;
- a terminated step's target is the reward alone; a step that is only truncated
  bootstraps (a time limit is not a terminal state);
- ``Q(s, a) += alpha * (y - Q(s, a))``;
- the next action is the epsilon-greedy draw for the next state, made only when the
  episode goes on, except for SARSA, which draws it before its update, also at truncation.

Every step function takes the same arguments, so that the training loops of both engines
call :func:`learn_step` and :func:`first_action` with an algorithm code and nothing is
written twice. ``q_b`` is Double Q-learning's second table; the other algorithms' step
functions do not take it (the engines hold an empty ``(0, n_actions)`` array there).

>>> import numpy as np
>>> q = np.array([[1.0, 0.0], [2.0, 3.0]])
>>> visits = np.zeros((2, 2), dtype=np.int64)
>>> rng = np.random.default_rng(0)
>>> q_learning_step(q, visits, 0, 0, 1.0, 1, False, True, 0.5, 0.9, 0.0, rng)
-1
>>> float(q[0, 0])  # truncated, so it bootstraps: 1 + 0.5 * (1 + 0.9 * 3 - 1) = 2.35
2.35
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numba import njit, types
from numba.extending import overload

from cartpole_q.config.schema import ALGORITHMS
from cartpole_q.numba_cache import configure as configure_numba_cache
from cartpole_q.rl.policy import (
    best_action,
    best_value,
    epsilon_greedy,
    epsilon_greedy_on_sum,
)

configure_numba_cache()  # before any cache=True function is defined

Q_LEARNING, SARSA, EXPECTED_SARSA, DOUBLE_Q_LEARNING = range(len(ALGORITHMS))
ENDED = -1
"""the next action returned when the episode ended"""


@njit(cache=True, nogil=True, inline="always")
def _update(q: np.ndarray, state: int, action: int, target: float, alpha: float) -> None:
    q[state, action] += alpha * (target - q[state, action])


@njit(cache=True, nogil=True, inline="always")
def q_learning_step(q, visits, state, action, reward, next_state, terminated, truncated,
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
def sarsa_step(q, visits, state, action, reward, next_state, terminated, truncated,
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
def expected_sarsa_step(q, visits, state, action, reward, next_state, terminated, truncated,
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
    # Two explicit branches rather than swapped names: an array alias costs reference
    # counting on every step.
    if rng.random() < 0.5:
        target = reward
        if not terminated:
            target = reward + gamma * q_b[next_state, best_action(q, next_state)]
        _update(q, state, action, target, alpha)
    else:
        target = reward
        if not terminated:
            target = reward + gamma * q[next_state, best_action(q_b, next_state)]
        _update(q_b, state, action, target, alpha)
    if terminated or truncated:
        return ENDED
    return epsilon_greedy_on_sum(q, q_b, next_state, epsilon, rng)


STEP_FUNCTIONS = (q_learning_step, sarsa_step, expected_sarsa_step, double_q_learning_step)
"""each algorithm's step function, indexed by its code"""


def learn_step(algorithm, q, q_b, visits, state, action, reward, next_state, terminated,
               truncated, alpha, gamma, epsilon, rng):  # fmt: skip
    """Learn from one transition with the algorithm ``algorithm`` (a code of ``ALGORITHMS``).

    Compiled code only, with ``algorithm`` a compile-time constant: the call becomes that
    algorithm's step function, inlined, with no branch on the code left (see
    :func:`~cartpole_q.engines.kernel.training_kernel`).

    Returns:
        The next action, or :data:`ENDED` when the episode ended.
    """
    raise NotImplementedError("learn_step is called from compiled code only")


@overload(learn_step, inline="always")
def _learn_step(algorithm, q, q_b, visits, state, action, reward, next_state, terminated,
                truncated, alpha, gamma, epsilon, rng):  # fmt: skip
    if not isinstance(algorithm, types.IntegerLiteral):
        return None  # numba then retries with the constant's literal type
    step: Any = STEP_FUNCTIONS[algorithm.literal_value]
    if algorithm.literal_value == DOUBLE_Q_LEARNING:

        def two_tables(algorithm, q, q_b, visits, state, action, reward, next_state,
                       terminated, truncated, alpha, gamma, epsilon, rng):  # fmt: skip
            return step(q, q_b, visits, state, action, reward, next_state, terminated,
                        truncated, alpha, gamma, epsilon, rng)  # fmt: skip

        return two_tables

    # The one-table algorithms do not take q_b: every array handed to an inlined function
    # costs reference counting on every step.
    def one_table(algorithm, q, q_b, visits, state, action, reward, next_state,
                  terminated, truncated, alpha, gamma, epsilon, rng):  # fmt: skip
        return step(q, visits, state, action, reward, next_state, terminated, truncated,
                    alpha, gamma, epsilon, rng)  # fmt: skip

    return one_table


def first_action(algorithm, q, q_b, state, epsilon, rng):
    """The first action of an episode: epsilon-greedy (on ``A + B`` for Double Q-learning).

    Compiled code only, with ``algorithm`` a compile-time constant (as :func:`learn_step`).
    """
    raise NotImplementedError("first_action is called from compiled code only")


@overload(first_action, inline="always")
def _first_action(algorithm, q, q_b, state, epsilon, rng):
    if not isinstance(algorithm, types.IntegerLiteral):
        return None
    if algorithm.literal_value == DOUBLE_Q_LEARNING:

        def on_sum(algorithm, q, q_b, state, epsilon, rng):
            return epsilon_greedy_on_sum(q, q_b, state, epsilon, rng)

        return on_sum

    def on_q(algorithm, q, q_b, state, epsilon, rng):
        return epsilon_greedy(q, state, epsilon, rng)

    return on_q
