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

from cartpole_q.families.base import unsupported_key
from cartpole_q.numba_cache import configure as configure_numba_cache

configure_numba_cache()  # before any cache=True function is defined

STATE_SIZE = 4
OBSERVATION_SIZE = 4
OBSERVATION_DTYPE = np.float32
OBSERVATION_KIND = "box"
STATE_DTYPE = np.float64
READS_ENVIRONMENT = False
N_ACTIONS = 2
PARAM_NAMES = (
    "sutton_barto_reward",
    "gravity",
    "masscart",
    "masspole",
    "total_mass",
    "length",
    "polemass_length",
    "force_mag",
    "tau",
    "euler",
    "theta_threshold_radians",
    "x_threshold",
)
"""what ``params`` holds, in order: the reward flag (1.0 or 0.0), the physics with its derived
values, and the integrator (1.0: euler, 0.0: semi-implicit euler)"""
(
    SUTTON_BARTO_REWARD, GRAVITY_, MASSCART_, MASSPOLE_, TOTAL_MASS_, LENGTH_,
    POLEMASS_LENGTH_, FORCE_MAG_, TAU_, EULER_, THETA_THRESHOLD_, X_THRESHOLD_,
) = range(len(PARAM_NAMES))  # fmt: skip
SUPPORTED_KWARGS = ("sutton_barto_reward", "max_episode_steps")

# The constants of CartPoleEnv.__init__, computed the same way.
GRAVITY = 9.8
MASSCART = 1.0
MASSPOLE = 0.1
LENGTH = 0.5  # half the pole's length
FORCE_MAG = 10.0
TAU = 0.02
THETA_THRESHOLD_RADIANS = 12 * 2 * math.pi / 360
X_THRESHOLD = 2.4
RESET_LOW, RESET_HIGH = -0.05, 0.05


def twin_params(
    kwargs: Mapping[str, Any], physics: Mapping[str, float | str] | None = None
) -> tuple[float, ...] | str:
    """Return ``params`` for ``gymnasium.make("CartPole-v1", **kwargs)`` with ``physics``.

    Args:
        kwargs: the ``gymnasium.make`` arguments.
        physics: ``env.physics`` (validated by the config): attributes set after making.

    Returns:
        The tuple of :data:`PARAM_NAMES`, or a sentence naming the first key the twin
        cannot reproduce.
    """
    problem = unsupported_key(kwargs, SUPPORTED_KWARGS)
    if problem is not None:
        return problem
    sutton_barto = kwargs.get("sutton_barto_reward", False)
    if not isinstance(sutton_barto, bool):
        return f"env.kwargs key 'sutton_barto_reward' must be true or false, got {sutton_barto!r}"
    values: dict[str, Any] = {
        "gravity": GRAVITY, "masscart": MASSCART, "masspole": MASSPOLE, "length": LENGTH,
        "force_mag": FORCE_MAG, "tau": TAU, "kinematics_integrator": "euler",
        "theta_threshold_radians": THETA_THRESHOLD_RADIANS, "x_threshold": X_THRESHOLD,
        **(physics or {}),
    }  # fmt: skip
    masscart, masspole, length = (float(values[k]) for k in ("masscart", "masspole", "length"))
    return (
        1.0 if sutton_barto else 0.0,
        float(values["gravity"]),
        masscart,
        masspole,
        masspole + masscart,  # total_mass, as CartPoleEnv.__init__ computes it
        length,
        masspole * length,  # polemass_length, likewise
        float(values["force_mag"]),
        float(values["tau"]),
        1.0 if values["kinematics_integrator"] == "euler" else 0.0,
        float(values["theta_threshold_radians"]),
        float(values["x_threshold"]),
    )


@njit(cache=True, nogil=True, inline="always")
def with_physics(
    params: tuple[float, ...], gravity: float, masscart: float, masspole: float, length: float,
    force_mag: float, tau: float,
) -> tuple[float, ...]:  # fmt: skip
    """``params`` with new physics; derived values computed as ``CartPoleEnv.__init__`` does."""
    total_mass = masspole + masscart
    polemass_length = masspole * length
    return (
        params[SUTTON_BARTO_REWARD], gravity, masscart, masspole, total_mass, length,
        polemass_length, force_mag, tau, params[EULER_], params[THETA_THRESHOLD_],
        params[X_THRESHOLD_],
    )  # fmt: skip


@njit(cache=True, nogil=True, inline="always")
def randomized(
    params: tuple[float, ...], rng: np.random.Generator, keys: np.ndarray, lows: np.ndarray,
    highs: np.ndarray,
) -> tuple[float, ...]:  # fmt: skip
    """``params`` with one ``rng.uniform(low, high)`` drawn per randomised key, in order.

    ``keys`` index ``env.randomize``'s keys in the order gravity, masscart, masspole,
    length, force_mag, tau; the other values come from ``params`` (``env.physics``).
    """
    values = np.array(
        [params[GRAVITY_], params[MASSCART_], params[MASSPOLE_], params[LENGTH_],
         params[FORCE_MAG_], params[TAU_]]
    )  # fmt: skip
    for i in range(keys.size):
        values[keys[i]] = rng.uniform(lows[i], highs[i])
    return with_physics(params, values[0], values[1], values[2], values[3], values[4], values[5])


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
    state: np.ndarray,
    action: int,
    observation: np.ndarray,
    rng: np.random.Generator,
    params: tuple[float, ...],
) -> tuple[float, bool]:
    """Advance ``state`` by one step in place (nothing drawn from ``rng``); write the observation.

    Returns:
        The reward and whether the step terminated the episode (the pole fell or the cart
        left the track). Truncation is the caller's time limit.
    """
    x, x_dot, theta, theta_dot = state[0], state[1], state[2], state[3]
    total_mass, polemass_length = params[TOTAL_MASS_], params[POLEMASS_LENGTH_]
    tau = params[TAU_]
    force = params[FORCE_MAG_] if action == 1 else -params[FORCE_MAG_]
    costheta = np.cos(theta)
    sintheta = np.sin(theta)
    temp = (force + polemass_length * (theta_dot * theta_dot) * sintheta) / total_mass
    thetaacc = (params[GRAVITY_] * sintheta - costheta * temp) / (
        params[LENGTH_] * (4.0 / 3.0 - params[MASSPOLE_] * (costheta * costheta) / total_mass)
    )
    xacc = temp - polemass_length * thetaacc * costheta / total_mass
    if params[EULER_] != 0.0:
        x = x + tau * x_dot
        x_dot = x_dot + tau * xacc
        theta = theta + tau * theta_dot
        theta_dot = theta_dot + tau * thetaacc
    else:  # semi-implicit euler
        x_dot = x_dot + tau * xacc
        x = x + tau * x_dot
        theta_dot = theta_dot + tau * thetaacc
        theta = theta + tau * theta_dot
    state[0], state[1], state[2], state[3] = x, x_dot, theta, theta_dot
    for i in range(4):
        observation[i] = np.float32(state[i])
    x_threshold, theta_threshold = params[X_THRESHOLD_], params[THETA_THRESHOLD_]
    terminated = (
        x < -x_threshold or x > x_threshold or theta < -theta_threshold or theta > theta_threshold
    )
    if params[SUTTON_BARTO_REWARD] != 0.0:
        return (-1.0 if terminated else 0.0), terminated
    return 1.0, terminated
