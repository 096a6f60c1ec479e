"""A compiled twin of the puddle world (``cartpole_q/PuddleWorld-v0``), bit-identical to it.

``reset`` and ``step`` repeat :class:`~cartpole_q.families.puddle.world.PuddleWorldEnv`'s
operation by operation, drawing from the environment's generator what it draws, in the
same order: two ``random()`` per start tried, one ``normal(0.0, 0.01)`` per coordinate per
step. The state is float64 ``(x, y)``; the observation is that state rounded to float32.
``params`` is empty: the world takes no ``gymnasium.make`` arguments but
``max_episode_steps`` (the caller's time limit).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np
from numba import njit

from cartpole_q.families.base import unsupported_key
from cartpole_q.families.puddle.world import GOAL_SUM, MOVE, NOISE, puddle_cost
from cartpole_q.numba_cache import configure as configure_numba_cache

configure_numba_cache()  # before any cache=True function is defined

STATE_SIZE = 2
OBSERVATION_SIZE = 2
OBSERVATION_DTYPE = np.float32
OBSERVATION_KIND = "box"
STATE_DTYPE = np.float64
READS_ENVIRONMENT = False
N_ACTIONS = 4
PARAM_NAMES: tuple[str, ...] = ()
"""the ``gymnasium.make`` arguments in ``params``: none"""
SUPPORTED_KWARGS = ("max_episode_steps",)
_MOVES_X = np.array([0.0, 0.0, -MOVE, MOVE])
_MOVES_Y = np.array([MOVE, -MOVE, 0.0, 0.0])


def twin_params(kwargs: Mapping[str, Any]) -> tuple[float, ...] | str:
    """Return ``params`` (none) for ``gymnasium.make("cartpole_q/PuddleWorld-v0", **kwargs)``, or why not."""
    problem = unsupported_key(kwargs, SUPPORTED_KWARGS)
    if problem is not None:
        return problem
    return ()


# The world's own function, compiled: the same operations in the same order.
_puddle_cost = njit(cache=True, nogil=True, inline="always")(puddle_cost)


@njit(cache=True, nogil=True, inline="always")
def reset(
    state: np.ndarray, observation: np.ndarray, rng: np.random.Generator, params: tuple[float, ...]
) -> None:
    """Draw a start that is not a goal into ``state``; write its float32 ``observation``."""
    while True:
        x = rng.random()
        y = rng.random()
        if not x + y >= GOAL_SUM:
            break
    state[0], state[1] = x, y
    observation[0] = np.float32(x)
    observation[1] = np.float32(y)


@njit(cache=True, nogil=True, inline="always")
def step(
    state: np.ndarray,
    action: int,
    observation: np.ndarray,
    rng: np.random.Generator,
    params: tuple[float, ...],
) -> tuple[float, bool]:
    """Move, draw the noise of ``x`` then ``y``, clip; return the reward and whether at the goal."""
    x = state[0] + _MOVES_X[action] + rng.normal(0.0, NOISE)
    y = state[1] + _MOVES_Y[action] + rng.normal(0.0, NOISE)
    x = min(max(x, 0.0), 1.0)
    y = min(max(y, 0.0), 1.0)
    state[0], state[1] = x, y
    observation[0] = np.float32(x)
    observation[1] = np.float32(y)
    return -1.0 + _puddle_cost(x, y), x + y >= GOAL_SUM
