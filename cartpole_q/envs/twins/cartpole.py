"""A compiled twin of Gymnasium's ``CartPoleEnv``, bit-identical to it.

The physics below repeats ``gymnasium.envs.classic_control.cartpole.CartPoleEnv.step``
operation by operation (same constants, same evaluation order, Euler integration), on a
float64 state; the observation is that state rounded to float32. Reset draws four
``uniform(-0.05, 0.05)`` values from a NumPy Generator seeded the way Gymnasium seeds
``env.np_random``. Tests compare trajectories with Gymnasium's by exact equality.

What the twin reproduces of ``gymnasium.make``'s arguments: ``sutton_barto_reward`` (in
``params``) and ``max_episode_steps`` (the caller's time limit). Anything else is refused by
:func:`twin_params`.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np
from numba import njit

from cartpole_q.envs.twins import unsupported_key
from cartpole_q.numba_cache import configure as configure_numba_cache

configure_numba_cache()  # before any cache=True function is defined

ENV_IDS = ("CartPole-v1", "CartPole-v0")
STATE_SIZE = 4
OBSERVATION_SIZE = 4
N_ACTIONS = 2
PARAM_NAMES = ("sutton_barto_reward",)
"""the ``gymnasium.make`` arguments in ``params``, in order"""
SUTTON_BARTO_REWARD = 0
"""index of ``sutton_barto_reward`` (1.0 or 0.0) in ``params``"""
SUPPORTED_KWARGS = (*PARAM_NAMES, "max_episode_steps")

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


def twin_params(kwargs: Mapping[str, Any]) -> tuple[float, ...] | str:
    """Return ``params`` for ``gymnasium.make("CartPole-v1", **kwargs)``, or why not.

    Returns:
        The tuple ``(sutton_barto_reward,)`` (1.0 or 0.0), or a sentence naming the
        first key the twin cannot reproduce.
    """
    problem = unsupported_key(kwargs, SUPPORTED_KWARGS)
    if problem is not None:
        return problem
    sutton_barto = kwargs.get("sutton_barto_reward", False)
    if not isinstance(sutton_barto, bool):
        return f"env.kwargs key 'sutton_barto_reward' must be true or false, got {sutton_barto!r}"
    return (1.0 if sutton_barto else 0.0,)


@njit(cache=True, nogil=True, inline="always")
def reset(
    state: np.ndarray, observation: np.ndarray, rng: np.random.Generator, params: tuple[float, ...]
) -> None:
    """Draw a start state into ``state`` and write its float32 ``observation``."""
    for i in range(4):
        state[i] = rng.uniform(RESET_LOW, RESET_HIGH)
        observation[i] = np.float32(state[i])


@njit(cache=True, nogil=True, inline="always")
def step(
    state: np.ndarray, action: int, observation: np.ndarray, params: tuple[float, ...]
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
    if params[SUTTON_BARTO_REWARD] != 0.0:
        return (-1.0 if terminated else 0.0), terminated
    return 1.0, terminated
