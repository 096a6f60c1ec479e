"""Tabular Q-learning, written once: pure functions compiled with numba.

Both engines drive exactly these functions, in the same order and with the same random
draws, which is why they produce byte-identical Q-tables. Each function is callable from
Python too (numba compiles it on first use and caches it on disk).

The Q-table is addressed as a 2-D ``(n_states, n_actions)`` array: the C-order view of
the ``(*bins, n_actions)`` table that is saved (see :mod:`cartpole_q.discretize`).

Q-learning, stated precisely:

- target ``r + gamma * max_a' Q(s', a')`` when the step did not terminate, ``r`` when it
  terminated; truncation (a time limit) is not termination, so it bootstraps;
- epsilon-greedy draws ``rng.random()`` to decide (unless epsilon is 0 or 1) and
  ``rng.integers`` for the action when it explores; ties go to the lowest action;
- schedules advance once per episode.

>>> import numpy as np
>>> q = np.array([[1.0, 0.0], [2.0, 3.0]])
>>> td_update(q, 0, 0, 1.0, 1, False, 0.5, 0.9)  # target 1 + 0.9 * 3 = 3.7
>>> float(q[0, 0])
2.35
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from cartpole_q import discretize
from cartpole_q.environment import SOLVE_WINDOW
from cartpole_q.numba_cache import configure as configure_numba_cache

configure_numba_cache()  # before any cache=True function is defined

CONSTANT, EXPONENTIAL, LOG = 0, 1, 2

state_index = njit(cache=True, nogil=True, inline="always")(discretize.state_index)
"""the binning rule of :mod:`cartpole_q.discretize`, compiled (the same source)"""


@njit(cache=True, nogil=True, inline="always")
def schedule_value(kind: int, start: float, end: float, rate: float, episode: int) -> float:
    """Return a schedule's value at a 0-based episode index.

    Args:
        kind: ``CONSTANT``, ``EXPONENTIAL`` or ``LOG`` (see :class:`cartpole_q.config.Schedule`).
        start: the constant, the initial value, or the log schedule's cap.
        end: the floor.
        rate: the per-episode decay factor, or the log schedule's ``k``.
        episode: 0 for the first episode.
    """
    if kind == CONSTANT:
        return start
    if kind == EXPONENTIAL:
        return max(end, start * rate ** float(episode))
    return max(end, min(start, 1.0 - math.log10((episode + 1.0) / rate)))


@njit(cache=True, nogil=True, inline="always")
def best_action(q: np.ndarray, state: int) -> int:
    """``argmax_a Q(state, a)``, the lowest action on ties (as ``np.argmax``)."""
    best = 0
    for action in range(1, q.shape[1]):
        if q[state, action] > q[state, best]:
            best = action
    return best


@njit(cache=True, nogil=True, inline="always")
def epsilon_greedy(q: np.ndarray, state: int, epsilon: float, rng: np.random.Generator) -> int:
    """Choose an action: a uniform random one with probability ``epsilon``, else the greedy one.

    The generator is drawn from only when the outcome is uncertain: at ``epsilon == 0``
    nothing is drawn, at ``epsilon == 1`` only the random action. Otherwise
    ``rng.random()`` decides, then ``rng.integers`` picks the action when exploring.
    """
    if epsilon <= 0.0:
        return best_action(q, state)
    if epsilon >= 1.0 or rng.random() < epsilon:
        return int(rng.integers(0, q.shape[1]))
    return best_action(q, state)


@njit(cache=True, nogil=True, inline="always")
def best_value(q: np.ndarray, state: int) -> float:
    """``max_a Q(state, a)``.

    The compiled functions index single entries instead of taking row views: a view
    costs two atomic reference-count updates, and numba's ``np.max`` of a two-entry row
    costs more than a whole CartPole step.
    """
    best = q[state, 0]
    for action in range(1, q.shape[1]):
        if q[state, action] > best:
            best = q[state, action]
    return best


@njit(cache=True, nogil=True, inline="always")
def td_update(
    q: np.ndarray,
    state: int,
    action: int,
    reward: float,
    next_state: int,
    terminated: bool,
    alpha: float,
    gamma: float,
) -> None:
    """Move ``Q(state, action)`` toward the one-step Q-learning target, in place."""
    target = reward
    if not terminated:
        target = reward + gamma * best_value(q, next_state)
    q[state, action] += alpha * (target - q[state, action])


@njit(cache=True, nogil=True, inline="always")
def greedy_action(
    q: np.ndarray, observation: np.ndarray, low: np.ndarray, high: np.ndarray, bins: np.ndarray
) -> int:
    """Return the greedy action for an observation (lowest action on ties)."""
    return best_action(q, state_index(observation, low, high, bins))


@njit(cache=True, nogil=True, inline="always")
def begin_episode(
    q: np.ndarray,
    observation: np.ndarray,
    low: np.ndarray,
    high: np.ndarray,
    bins: np.ndarray,
    epsilon: float,
    rng: np.random.Generator,
) -> tuple[int, int]:
    """Return the first state and action of an episode from its reset observation."""
    state = state_index(observation, low, high, bins)
    return state, epsilon_greedy(q, state, epsilon, rng)


@njit(cache=True, nogil=True, inline="always")
def learn_step(
    q: np.ndarray,
    visits: np.ndarray,
    state: int,
    action: int,
    reward: float,
    next_observation: np.ndarray,
    terminated: bool,
    truncated: bool,
    low: np.ndarray,
    high: np.ndarray,
    bins: np.ndarray,
    alpha: float,
    gamma: float,
    epsilon: float,
    rng: np.random.Generator,
) -> tuple[int, int]:
    """Learn from one transition and choose the next action.

    Counts the visit of ``(state, action)``, applies the TD update, and, unless the
    episode ended, draws the next action epsilon-greedily from the updated table.
    The numba engine's compiled loop repeats these four calls inline, in this order
    (a call with six array arguments would double its cost per step); the cross-engine
    tests check that both engines stay byte-identical.

    Returns:
        The next state and the next action (``-1`` when the episode ended).
    """
    visits[state, action] += 1
    next_state = state_index(next_observation, low, high, bins)
    td_update(q, state, action, reward, next_state, terminated, alpha, gamma)
    if terminated or truncated:
        return next_state, -1
    return next_state, epsilon_greedy(q, next_state, epsilon, rng)


@njit(cache=True, nogil=True, inline="always")
def record_episode(
    returns: np.ndarray,
    lengths: np.ndarray,
    epsilons: np.ndarray,
    alphas: np.ndarray,
    episode: int,
    episode_return: float,
    length: int,
    epsilon: float,
    alpha: float,
) -> None:
    """Store one finished episode's metrics at its 0-based index."""
    returns[episode] = episode_return
    lengths[episode] = length
    epsilons[episode] = epsilon
    alphas[episode] = alpha


@njit(cache=True, nogil=True, inline="always")
def reaches_threshold(returns: np.ndarray, episode: int, threshold: float) -> bool:
    """Whether the moving average of the last ``SOLVE_WINDOW`` returns reaches the threshold.

    Needs a full window: no episode before the 100th can solve a run.
    """
    if episode + 1 < SOLVE_WINDOW:
        return False
    total = 0.0
    for i in range(episode + 1 - SOLVE_WINDOW, episode + 1):
        total += returns[i]
    return total / SOLVE_WINDOW >= threshold
