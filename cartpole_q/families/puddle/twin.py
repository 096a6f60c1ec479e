"""A compiled twin of the puddle world (``cartpole_q/PuddleWorld-v0``), bit-identical to it.

``reset`` and ``step`` repeat :class:`~cartpole_q.families.puddle.world.PuddleWorldEnv`'s
operation by operation, drawing from the environment's generator what it draws, in the
same order: two ``random()`` per start tried, one ``normal(0.0, 0.01)`` per coordinate per
step. The state is float64 ``(x, y)``; the observation is that state rounded to float32.
``params`` is empty: the world takes no ``gymnasium.make`` arguments but
``max_episode_steps`` (the caller's time limit).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np
from numba import njit

from cartpole_q.families.base import unsupported_key
from cartpole_q.families.puddle.world import (
    DEPTH_COST,
    GOAL_SUM,
    HORIZONTAL,
    MOVE,
    NOISE,
    RADIUS,
    VERTICAL,
)
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
_H_LOW, _H_HIGH, _H_LEVEL = HORIZONTAL
_V_LOW, _V_HIGH, _V_LEVEL = VERTICAL


def twin_params(kwargs: Mapping[str, Any]) -> tuple[float, ...] | str:
    """Return ``params`` (none) for ``gymnasium.make("cartpole_q/PuddleWorld-v0", **kwargs)``, or why not."""
    problem = unsupported_key(kwargs, SUPPORTED_KWARGS)
    if problem is not None:
        return problem
    return ()


@njit(cache=True, nogil=True, inline="always")
def _puddle_cost(x: float, y: float) -> float:
    """:func:`~cartpole_q.families.puddle.world.puddle_cost`, operation by operation."""
    cost = 0.0
    dx = x - min(max(x, _H_LOW), _H_HIGH)
    dy = y - _H_LEVEL
    distance = math.sqrt(dx * dx + dy * dy)
    if distance < RADIUS:
        cost = cost - DEPTH_COST * (RADIUS - distance)
    dx = x - _V_LEVEL
    dy = y - min(max(y, _V_LOW), _V_HIGH)
    distance = math.sqrt(dx * dx + dy * dy)
    if distance < RADIUS:
        cost = cost - DEPTH_COST * (RADIUS - distance)
    return cost


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
