"""Acting on a Q-table: greedy and epsilon-greedy choices, compiled with numba.

The Q-table is addressed as a 2-D ``(n_states, n_actions)`` array: the C-order view of
the ``(*bins, n_actions)`` table that is saved. Every argmax is the lowest action among
the maxima, as ``np.argmax``.

The compiled functions index single entries instead of taking row views: a view costs two
atomic reference-count updates, and numba's ``np.max`` of a two-entry row costs more than
a whole CartPole step.

Epsilon-greedy, stated precisely: at ``epsilon <= 0`` greedy, nothing drawn; at
``epsilon >= 1`` ``rng.integers(0, n_actions)``; otherwise ``rng.random() < epsilon``
decides, then ``rng.integers(0, n_actions)`` when exploring.

>>> import numpy as np
>>> q = np.array([[1.0, 3.0, 3.0]])
>>> best_action(q, 0), best_value(q, 0)
(1, 3.0)
"""

from __future__ import annotations

import numpy as np
from numba import njit, types
from numba.extending import overload

from cartpole_q.numba_cache import configure as configure_numba_cache
from cartpole_q.rl import binning

configure_numba_cache()  # before any cache=True function is defined

state_index = njit(cache=True, nogil=True, inline="always")(binning.state_index)
"""the binning rule of :mod:`cartpole_q.rl.binning`, compiled (the same source)"""


def observation_row(observation, grid):
    """The Q-table row of an observation: binned (an array) or indexed (Discrete, Tuple).

    Compiled code only: numba picks the rule by the observation's type. An array follows
    the binning rule on ``grid``'s edges; an integer (``Discrete``) gives
    ``obs - grid.starts[0]``; a tuple of integers (``Tuple`` of ``Discrete``) the C-order
    row of ``obs[k] - grid.starts[k]`` over ``grid.bins`` (the components' sizes), as
    :func:`cartpole_q.rl.binning.discrete_index`.
    """
    raise NotImplementedError("observation_row is called from compiled code only")


@overload(observation_row, inline="always")
def _observation_row(observation, grid):
    if isinstance(observation, types.Array):

        def binned(observation, grid):
            return state_index(observation, grid.low, grid.high, grid.bins)

        return binned
    if isinstance(observation, types.Integer):

        def single(observation, grid):
            return observation - grid.starts[0]

        return single
    if isinstance(observation, types.UniTuple) and isinstance(observation.dtype, types.Integer):

        def components(observation, grid):
            index = 0
            for k in range(len(observation)):
                index = index * grid.bins[k] + (observation[k] - grid.starts[k])
            return index

        return components
    return None


@njit(cache=True, nogil=True, inline="always")
def best_action(q: np.ndarray, state: int) -> int:
    """``argmax_a Q(state, a)``, the lowest action on ties."""
    best = 0
    for action in range(1, q.shape[1]):
        if q[state, action] > q[state, best]:
            best = action
    return best


@njit(cache=True, nogil=True, inline="always")
def best_value(q: np.ndarray, state: int) -> float:
    """``max_a Q(state, a)``."""
    best = q[state, 0]
    for action in range(1, q.shape[1]):
        if q[state, action] > best:
            best = q[state, action]
    return best


@njit(cache=True, nogil=True, inline="always")
def epsilon_greedy(q: np.ndarray, state: int, epsilon: float, rng: np.random.Generator) -> int:
    """A uniform random action with probability ``epsilon``, else the greedy one."""
    if epsilon <= 0.0:
        return best_action(q, state)
    if epsilon >= 1.0 or rng.random() < epsilon:
        return int(rng.integers(0, q.shape[1]))
    return best_action(q, state)


@njit(cache=True, nogil=True, inline="always")
def best_action_of_sum(q_a: np.ndarray, q_b: np.ndarray, state: int) -> int:
    """``argmax_a (A(state, a) + B(state, a))``, the lowest action on ties."""
    best = 0
    best_sum = q_a[state, 0] + q_b[state, 0]
    for action in range(1, q_a.shape[1]):
        total = q_a[state, action] + q_b[state, action]
        if total > best_sum:
            best, best_sum = action, total
    return best


@njit(cache=True, nogil=True, inline="always")
def epsilon_greedy_on_sum(
    q_a: np.ndarray, q_b: np.ndarray, state: int, epsilon: float, rng: np.random.Generator
) -> int:
    """Epsilon-greedy on ``A + B`` (Double Q-learning), with the same draws as above."""
    if epsilon <= 0.0:
        return best_action_of_sum(q_a, q_b, state)
    if epsilon >= 1.0 or rng.random() < epsilon:
        return int(rng.integers(0, q_a.shape[1]))
    return best_action_of_sum(q_a, q_b, state)
