"""A compiled twin of Gymnasium's ``MountainCarEnv`` (``MountainCar-v0``), bit-identical to it.

``step`` repeats ``gymnasium.envs.classic_control.mountain_car.MountainCarEnv.step``
operation by operation: the same constants, the same evaluation order
(``velocity + ((action - 1) * force + cos(3 * position) * -gravity)``), ``np.clip``'s
comparisons, and the velocity set to zero at the left wall. The state is float64
``(position, velocity)``; the observation is that state rounded to float32. ``reset`` draws
one ``uniform(-0.6, -0.4)`` for the position, as Gymnasium draws it from ``env.np_random``;
the velocity starts at 0.

``params`` holds the ``gymnasium.make`` arguments the twin reproduces, in this order:
``goal_velocity`` (default 0.0). ``max_episode_steps`` is accepted too (the caller's time
limit); any other key is refused by :func:`twin_params`.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np
from numba import njit

from cartpole_q.families.base import unsupported_key
from cartpole_q.numba_cache import configure as configure_numba_cache

configure_numba_cache()  # before any cache=True function is defined

MAX_EPISODE_STEPS = 200
"""the time limit ``MountainCar-v0`` is registered with"""
STATE_SIZE = 2
OBSERVATION_SIZE = 2
OBSERVATION_DTYPE = np.float32
OBSERVATION_KIND = "box"
STATE_DTYPE = np.float64
READS_ENVIRONMENT = False
N_ACTIONS = 3
PARAM_NAMES = ("goal_velocity",)
"""the ``gymnasium.make`` arguments in ``params``, in order"""
SUPPORTED_KWARGS = (*PARAM_NAMES, "max_episode_steps")

# The constants of MountainCarEnv.__init__.
MIN_POSITION = -1.2
MAX_POSITION = 0.6
MAX_SPEED = 0.07
GOAL_POSITION = 0.5
FORCE = 0.001
GRAVITY = 0.0025
RESET_LOW, RESET_HIGH = -0.6, -0.4


def twin_params(kwargs: Mapping[str, Any]) -> tuple[float, ...] | str:
    """Return ``params`` for ``gymnasium.make("MountainCar-v0", **kwargs)``, or why not.

    Returns:
        The tuple ``(goal_velocity,)``, or a sentence naming the first key the twin
        cannot reproduce.
    """
    problem = unsupported_key(kwargs, SUPPORTED_KWARGS)
    if problem is not None:
        return problem
    goal_velocity = kwargs.get("goal_velocity", 0.0)
    if (
        isinstance(goal_velocity, bool)
        or not isinstance(goal_velocity, int | float)
        or not math.isfinite(goal_velocity)
        or float(goal_velocity) != goal_velocity  # an int a float64 cannot hold
    ):
        return f"env.kwargs key 'goal_velocity' must be a finite number, got {goal_velocity!r}"
    return (float(goal_velocity),)


@njit(cache=True, nogil=True, inline="always")
def reset(
    state: np.ndarray, observation: np.ndarray, rng: np.random.Generator, params: tuple[float, ...]
) -> None:
    """Draw a start state into ``state`` and write its float32 ``observation``."""
    state[0] = rng.uniform(RESET_LOW, RESET_HIGH)
    state[1] = 0.0
    observation[0] = np.float32(state[0])
    observation[1] = np.float32(state[1])


@njit(cache=True, nogil=True, inline="always")
def step(
    state: np.ndarray,
    action: int,
    observation: np.ndarray,
    rng: np.random.Generator,
    params: tuple[float, ...],
) -> tuple[float, bool]:
    """Advance ``state`` by one step in place (nothing drawn from ``rng``); write the observation.

    Returns:
        The reward (always -1) and whether the car reached the goal at ``goal_velocity``
        or faster. Truncation is the caller's time limit.
    """
    position, velocity = state[0], state[1]
    velocity = velocity + ((action - 1) * FORCE + math.cos(3 * position) * (-GRAVITY))
    # np.clip(velocity, -MAX_SPEED, MAX_SPEED), comparison for comparison
    velocity = velocity if velocity > -MAX_SPEED else -MAX_SPEED
    velocity = velocity if velocity < MAX_SPEED else MAX_SPEED
    position = position + velocity
    position = position if position > MIN_POSITION else MIN_POSITION
    position = position if position < MAX_POSITION else MAX_POSITION
    if position == MIN_POSITION and velocity < 0:
        velocity = 0.0
    state[0], state[1] = position, velocity
    observation[0] = np.float32(position)
    observation[1] = np.float32(velocity)
    terminated = position >= GOAL_POSITION and velocity >= params[0]
    return -1.0, terminated
