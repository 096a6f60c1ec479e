"""The compiled twins and the environments they reproduce, with one compiled dispatch.

A twin is chosen by an integer code, so that one compiled training loop serves every twin:
in compiled code, :func:`twin_reset` and :func:`twin_step` with a constant code become that
twin's functions, inlined (numba's ``overload`` picks them while typing). A new twin is one
module added to :data:`TWINS`.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from types import ModuleType
from typing import Any

from numba import types
from numba.extending import overload

from cartpole_q.envs.twins import acrobot, cartpole, mountaincar
from cartpole_q.numba_cache import configure as configure_numba_cache

configure_numba_cache()  # before any cache=True function is defined

TWINS: tuple[ModuleType, ...] = (cartpole, mountaincar, acrobot)
"""the twin modules; the index of each is its code"""
CARTPOLE, MOUNTAINCAR, ACROBOT = range(len(TWINS))


@dataclass(frozen=True)
class TwinSettings:
    """Everything the compiled loop needs to run one environment's twin."""

    code: int
    """the twin's code (its index in :data:`TWINS`)"""
    max_episode_steps: int
    """the time limit (truncation), as ``gymnasium.make`` applies it"""
    params: tuple[float, ...]
    """the twin's parameters (the ``gymnasium.make`` arguments it reproduces): a tuple,
    which compiled code passes by value, without the reference counting of an array"""
    state_size: int
    observation_size: int


def twin_ids() -> tuple[str, ...]:
    """Every environment id a twin reproduces."""
    return tuple(env_id for twin in TWINS for env_id in twin.ENV_IDS)


def twin_settings(
    env_id: str,
    kwargs: Mapping[str, Any],
    spec_max_steps: int | None,
    physics: Mapping[str, float | str] | None = None,
) -> TwinSettings | str:
    """Return the twin settings for ``gymnasium.make(env_id, **kwargs)``, or why there are none.

    Args:
        env_id: the Gymnasium id.
        kwargs: the ``gymnasium.make`` arguments.
        spec_max_steps: the registered time limit, used when ``kwargs`` gives none.
        physics: ``env.physics`` (CartPole only; the config refuses it elsewhere).

    Returns:
        ``TwinSettings`` when a twin reproduces the environment exactly, else a sentence
        naming the id or key it cannot reproduce.
    """
    code = next((code for code, twin in enumerate(TWINS) if env_id in twin.ENV_IDS), None)
    if code is None:
        return f"env.id {env_id!r} has no compiled twin (only {', '.join(twin_ids())} do)"
    twin = TWINS[code]
    params = twin.twin_params(kwargs, physics) if physics else twin.twin_params(kwargs)
    if isinstance(params, str):
        return params
    max_steps = kwargs.get("max_episode_steps", spec_max_steps)
    if isinstance(max_steps, bool) or not isinstance(max_steps, int) or max_steps < 1:
        return f"env.kwargs key 'max_episode_steps' must be a positive integer, got {max_steps!r}"
    return TwinSettings(code, max_steps, params, twin.STATE_SIZE, twin.OBSERVATION_SIZE)


def twin_reset(code, state, observation, rng, params):
    """Reset the twin ``code``: a start state drawn from ``rng``, its observation written.

    Compiled code only, with ``code`` a compile-time constant: the call becomes that twin's
    ``reset``, inlined.
    """
    raise NotImplementedError("twin_reset is called from compiled code only")


@overload(twin_reset, inline="always")
def _twin_reset(code, state, observation, rng, params):
    if not isinstance(code, types.IntegerLiteral):
        return None  # numba then retries with the constant's literal type
    reset = TWINS[code.literal_value].reset

    def implementation(code, state, observation, rng, params):
        reset(state, observation, rng, params)

    return implementation


def twin_step(code, state, action, observation, params):
    """Step the twin ``code``; return the reward and whether the step terminated.

    Compiled code only, with ``code`` a compile-time constant (as :func:`twin_reset`).
    """
    raise NotImplementedError("twin_step is called from compiled code only")


@overload(twin_step, inline="always")
def _twin_step(code, state, action, observation, params):
    if not isinstance(code, types.IntegerLiteral):
        return None
    step = TWINS[code.literal_value].step

    def implementation(code, state, action, observation, params):
        return step(state, action, observation, params)

    return implementation


def twin_randomize(code, params, rng, keys, lows, highs):
    """The twin's ``params`` with ``env.randomize``'s draws (CartPole), else ``params``.

    Compiled code only, with ``code`` a compile-time constant (as :func:`twin_reset`).
    """
    raise NotImplementedError("twin_randomize is called from compiled code only")


@overload(twin_randomize, inline="always")
def _twin_randomize(code, params, rng, keys, lows, highs):
    if not isinstance(code, types.IntegerLiteral):
        return None
    if code.literal_value == CARTPOLE:

        def physics(code, params, rng, keys, lows, highs):
            return cartpole.randomized(params, rng, keys, lows, highs)

        return physics

    def unchanged(code, params, rng, keys, lows, highs):
        return params

    return unchanged
