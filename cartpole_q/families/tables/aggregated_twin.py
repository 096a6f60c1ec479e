"""A compiled twin of a world moved by its transition table and observed in groups of states.

State aggregation (Sutton & Barto 9.3): the world moves by ``P`` exactly as the table twin
plays it (:mod:`cartpole_q.families.tables.twin`: one ``random()`` per step and per
reset), but its observation is not the state: it is ``observation_of_state[s]``, the group
the world puts state ``s`` in (:class:`~cartpole_q.families.tables.world.TableWorld`), from 0 to the
observation space's ``n - 1``. A world without ``observation_of_state`` is observed as its
states (the map is the identity). ``params`` are the table's arrays followed by the map
(int64, one per state). ``max_episode_steps`` is the caller's time limit; ``render_mode`` is
refused.

The world this twin plays: ``cartpole_q/RandomWalk1000-v0`` (Example 9.1) with or without
``env.kwargs.groups``.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np
from numba import njit

from cartpole_q.families.tables import twin as transition_table
from cartpole_q.families.tables.twin import initial_state, read_environment, table_step
from cartpole_q.numba_cache import configure as configure_numba_cache

configure_numba_cache()  # before any cache=True function is defined

STATE_SIZE = 1
STATE_DTYPE = np.int64
"""the state ``s``"""
OBSERVATION_SIZE = 1
OBSERVATION_DTYPE = np.int64
OBSERVATION_KIND = "discrete"
READS_ENVIRONMENT = True
PARAM_NAMES = (*transition_table.PARAM_NAMES, "observations")
"""what ``params`` holds, in order: the table's arrays, then the observation of each state"""
OBSERVATIONS = len(transition_table.PARAM_NAMES)

_BAKED: dict[tuple[str, str], tuple[np.ndarray, ...] | str] = {}
"""the tables already read, by id and arguments"""


def twin_params(kwargs: Mapping[str, Any], env_id: str) -> tuple[np.ndarray, ...] | str:
    """Return ``params`` for ``gymnasium.make(env_id, **kwargs)``, or why not.

    Returns:
        The arrays of :data:`PARAM_NAMES`, or a sentence saying why the twin cannot
        reproduce the environment.
    """
    for key in transition_table.REFUSED_KWARGS:
        if key in kwargs:
            return f"env.kwargs key {key!r} is not reproduced by the compiled twin"
    return read_environment(env_id, kwargs, aggregated_params, _BAKED)


def aggregated_params(env: Any) -> tuple[np.ndarray, ...] | str:
    """The arrays of :data:`PARAM_NAMES` of an unwrapped environment, or why there are none."""
    table = transition_table.table_params(env, aggregated=True)
    if isinstance(table, str):
        return table
    n_states = table[transition_table.OUTCOMES].shape[0]
    given = getattr(env, "observation_of_state", None)
    observations = np.arange(n_states, dtype=np.int64) if given is None else np.asarray(given)
    space = env.observation_space
    n = getattr(space, "n", None)
    if observations.shape != (n_states,) or observations.dtype.kind not in "iu":
        return "observation_of_state does not give one integer per state of the table"
    if not isinstance(n, int | np.integer) or getattr(space, "start", None) != 0:
        return "the environment's observation space is not Discrete(n) from 0"
    if observations.min() < 0 or observations.max() >= n:
        return f"observation_of_state leaves the observation space Discrete({n})"
    return (*table, observations.astype(np.int64))


@njit(cache=True, nogil=True, inline="always")
def reset(
    state: np.ndarray, observation: np.ndarray, rng: np.random.Generator, params: Any
) -> None:
    """Draw the start state as Gymnasium's ``reset`` does; observe its group."""
    state[0] = initial_state(params, rng)
    observation[0] = params[OBSERVATIONS][state[0]]


@njit(cache=True, nogil=True, inline="always")
def step(
    state: np.ndarray,
    action: int,
    observation: np.ndarray,
    rng: np.random.Generator,
    params: Any,
) -> tuple[float, bool]:
    """Draw the outcome of ``action`` as Gymnasium's ``step`` does; move there, observe its group.

    Returns:
        The outcome's reward and whether it terminates the episode. Truncation is the
        caller's time limit.
    """
    next_state, reward, terminated = table_step(state[0], action, rng, params)
    state[0] = next_state
    observation[0] = params[OBSERVATIONS][next_state]
    return reward, terminated
