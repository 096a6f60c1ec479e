"""A compiled twin of Gymnasium's ``TaxiEnv`` (``Taxi-v4``, and ``Taxi-v3`` where registered).

Taxi moves by its transition table as the table twin does
(:mod:`cartpole_q.families.tables.twin`: one ``random()`` per step and per reset,
``is_rainy`` and ``rainy_probability`` are in ``P``), with one addition outside the table,
``fickle_passenger``, repeated here from ``TaxiEnv.reset`` and ``TaxiEnv.step``:

- ``reset`` draws the start state, then, only with a fickle passenger,
  ``fickle_step = np_random.random() < fickle_probability``;
- ``step`` draws the outcome; then, if ``fickle_step`` is still set, the passenger was in
  the taxi before the step and the taxi moved, ``fickle_step`` is cleared and the
  destination becomes ``np_random.choice`` of the three others (in index order), which
  NumPy draws as ``np_random.integers(0, 3)``.

The state is ``(s, fickle_step)``; the observation is ``s``, as Taxi encodes it:
``((taxi_row * 5 + taxi_col) * 5 + passenger) * 4 + destination``. ``params`` are the
table's arrays followed by ``fickle_passenger`` (1.0 or 0.0) and ``fickle_probability``.
``max_episode_steps`` is the caller's time limit; ``render_mode`` is refused.
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

MAX_EPISODE_STEPS = 200
"""the time limit ``Taxi-v4`` is registered with"""
STATE_SIZE = 2
STATE_DTYPE = np.int64
"""``(s, fickle_step)``"""
OBSERVATION_SIZE = 1
OBSERVATION_DTYPE = np.int64
OBSERVATION_KIND = "discrete"
READS_ENVIRONMENT = True
N_ACTIONS = 6
PARAM_NAMES = (*transition_table.PARAM_NAMES, "fickle_passenger", "fickle_probability")
"""what ``params`` holds, in order"""
FICKLE_PASSENGER = len(transition_table.PARAM_NAMES)
FICKLE_PROBABILITY = FICKLE_PASSENGER + 1
N_STATES = 500
"""Taxi's states: 5 rows, 5 columns, 5 passenger places (4 stops and the taxi), 4 stops"""
IN_TAXI = 4
"""the passenger index of a passenger in the taxi"""
DESTINATIONS = 4

_BAKED: dict[tuple[str, str], tuple[Any, ...] | str] = {}
"""the tables already read, by id and arguments"""


def twin_params(kwargs: Mapping[str, Any], env_id: str) -> tuple[Any, ...] | str:
    """Return ``params`` for ``gymnasium.make(env_id, **kwargs)``, or why not.

    Returns:
        The values of :data:`PARAM_NAMES`, or a sentence saying why the twin cannot
        reproduce the environment.
    """
    for key in transition_table.REFUSED_KWARGS:
        if key in kwargs:
            return f"env.kwargs key {key!r} is not reproduced by the compiled twin"
    return read_environment(env_id, kwargs, taxi_params, _BAKED)


def taxi_params(taxi: Any) -> tuple[Any, ...] | str:
    """The values of :data:`PARAM_NAMES` of an unwrapped ``TaxiEnv``, or why there are none."""
    if getattr(taxi.observation_space, "n", None) != N_STATES:
        return f"Taxi's twin knows {N_STATES} states, not {taxi.observation_space}"
    table = transition_table.table_params(taxi)
    if isinstance(table, str):
        return table
    probability = getattr(taxi, "fickle_probability", None)
    if isinstance(probability, bool) or not isinstance(probability, int | float):
        return f"env.kwargs key 'fickle_probability' must be a number, got {probability!r}"
    return (*table, 1.0 if taxi.fickle_passenger else 0.0, float(probability))


@njit(cache=True, nogil=True, inline="always")
def decode(s: int) -> tuple[int, int, int, int]:
    """``TaxiEnv.decode``: ``(taxi_row, taxi_col, passenger, destination)``."""
    destination = s % 4
    s = s // 4
    passenger = s % 5
    s = s // 5
    return s // 5, s % 5, passenger, destination


@njit(cache=True, nogil=True, inline="always")
def encode(taxi_row: int, taxi_col: int, passenger: int, destination: int) -> int:
    """``TaxiEnv.encode``."""
    return ((taxi_row * 5 + taxi_col) * 5 + passenger) * 4 + destination


@njit(cache=True, nogil=True, inline="always")
def reset(
    state: np.ndarray, observation: np.ndarray, rng: np.random.Generator, params: Any
) -> None:
    """Draw the start state, then (a fickle passenger only) whether they will change their mind."""
    state[0] = initial_state(params, rng)
    state[1] = 0
    if params[FICKLE_PASSENGER] != 0.0:
        state[1] = 1 if rng.random() < params[FICKLE_PROBABILITY] else 0
    observation[0] = state[0]


@njit(cache=True, nogil=True, inline="always")
def step(
    state: np.ndarray,
    action: int,
    observation: np.ndarray,
    rng: np.random.Generator,
    params: Any,
) -> tuple[float, bool]:
    """Draw the outcome of ``action`` from the table; a fickle passenger may then re-route.

    Returns:
        The outcome's reward and whether it terminates the episode (a drop-off at the
        destination). Truncation is the caller's time limit.
    """
    before = state[0]
    after, reward, terminated = table_step(before, action, rng, params)
    if params[FICKLE_PASSENGER] != 0.0 and state[1] != 0:
        row_before, col_before, passenger_before, destination_before = decode(before)
        row, col, passenger, _ = decode(after)
        if passenger_before == IN_TAXI and (row != row_before or col != col_before):
            state[1] = 0
            # np_random.choice of [i for i in range(4) if i != destination_before]
            drawn = int(rng.integers(0, DESTINATIONS - 1))
            destination = drawn if drawn < destination_before else drawn + 1
            after = encode(row, col, passenger, destination)
    state[0] = after
    observation[0] = after
    return reward, terminated
