"""A compiled twin of Gymnasium's ``CartPoleEnv``, bit-identical to it.

The physics below repeats ``gymnasium.envs.classic_control.cartpole.CartPoleEnv.step``
operation by operation (same constants, same evaluation order, Euler integration), on a
float64 state; the observation is that state rounded to float32. Reset draws four
``uniform(-0.05, 0.05)`` values from a NumPy Generator seeded the way Gymnasium seeds
``env.np_random``. Tests compare trajectories with Gymnasium's by exact equality.

What the twin reproduces of ``gymnasium.make``'s arguments: ``sutton_barto_reward`` and
``max_episode_steps``. Anything else is refused by :func:`twin_settings`.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
from numba import njit

from cartpole_q.numba_cache import configure as configure_numba_cache

configure_numba_cache()  # before any cache=True function is defined

TWIN_ENV_IDS = ("CartPole-v1", "CartPole-v0")
SUPPORTED_KWARGS = ("sutton_barto_reward", "max_episode_steps")

# The constants of CartPoleEnv.__init__, computed the same way.
GRAVITY = 9.8
MASSCART = 1.0
MASSPOLE = 0.1
TOTAL_MASS = MASSPOLE + MASSCART
LENGTH = 0.5  # half the pole's length
POLEMASS_LENGTH = MASSPOLE * LENGTH
FORCE_MAG = 10.0
TAU = 0.02
THETA_THRESHOLD_RADIANS = 12 * 2 * math.pi / 360
X_THRESHOLD = 2.4
RESET_LOW, RESET_HIGH = -0.05, 0.05


@dataclass(frozen=True)
class TwinSettings:
    """The environment arguments the twin runs with."""

    max_episode_steps: int
    """the time limit (truncation), as ``gymnasium.make`` applies it"""
    sutton_barto_reward: bool
    """0 per surviving step and -1 on termination, instead of +1 per step"""


def twin_settings(
    env_id: str, kwargs: Mapping[str, Any], spec_max_steps: int | None
) -> TwinSettings | str:
    """Return the twin's settings for an environment, or why it cannot reproduce it.

    Returns:
        ``TwinSettings`` when the twin reproduces ``gymnasium.make(env_id, **kwargs)``
        exactly, else a sentence naming the id or key it cannot reproduce.
    """
    if env_id not in TWIN_ENV_IDS:
        return f"env.id {env_id!r} has no compiled twin (only {', '.join(TWIN_ENV_IDS)} do)"
    for key in kwargs:
        if key not in SUPPORTED_KWARGS:
            return (
                f"env.kwargs key {key!r} is not reproduced by the compiled twin "
                f"(it supports {', '.join(SUPPORTED_KWARGS)})"
            )
    max_steps = kwargs.get("max_episode_steps", spec_max_steps)
    if isinstance(max_steps, bool) or not isinstance(max_steps, int) or max_steps < 1:
        return f"env.kwargs key 'max_episode_steps' must be a positive integer, got {max_steps!r}"
    sutton_barto = kwargs.get("sutton_barto_reward", False)
    if not isinstance(sutton_barto, bool):
        return f"env.kwargs key 'sutton_barto_reward' must be true or false, got {sutton_barto!r}"
    return TwinSettings(max_episode_steps=max_steps, sutton_barto_reward=sutton_barto)


@njit(cache=True, nogil=True, inline="always")
def reset(state: np.ndarray, observation: np.ndarray, rng: np.random.Generator) -> None:
    """Draw a start state into ``state`` and write its float32 ``observation``."""
    for i in range(4):
        state[i] = rng.uniform(RESET_LOW, RESET_HIGH)
        observation[i] = np.float32(state[i])


@njit(cache=True, nogil=True, inline="always")
def step(
    state: np.ndarray, action: int, observation: np.ndarray, sutton_barto_reward: bool
) -> tuple[float, bool]:
    """Advance ``state`` by one step in place; write the observation.

    Returns:
        The reward and whether the step terminated the episode (the pole fell or the cart
        left the track). Truncation is the caller's time limit.
    """
    x, x_dot, theta, theta_dot = state[0], state[1], state[2], state[3]
    force = FORCE_MAG if action == 1 else -FORCE_MAG
    costheta = np.cos(theta)
    sintheta = np.sin(theta)
    temp = (force + POLEMASS_LENGTH * (theta_dot * theta_dot) * sintheta) / TOTAL_MASS
    thetaacc = (GRAVITY * sintheta - costheta * temp) / (
        LENGTH * (4.0 / 3.0 - MASSPOLE * (costheta * costheta) / TOTAL_MASS)
    )
    xacc = temp - POLEMASS_LENGTH * thetaacc * costheta / TOTAL_MASS
    x = x + TAU * x_dot
    x_dot = x_dot + TAU * xacc
    theta = theta + TAU * theta_dot
    theta_dot = theta_dot + TAU * thetaacc
    state[0], state[1], state[2], state[3] = x, x_dot, theta, theta_dot
    for i in range(4):
        observation[i] = np.float32(state[i])
    terminated = (
        x < -X_THRESHOLD
        or x > X_THRESHOLD
        or theta < -THETA_THRESHOLD_RADIANS
        or theta > THETA_THRESHOLD_RADIANS
    )
    if sutton_barto_reward:
        return (-1.0 if terminated else 0.0), terminated
    return 1.0, terminated
