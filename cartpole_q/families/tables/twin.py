"""A compiled twin of any environment that moves by its transition table ``P``.

Gymnasium's FrozenLake and CliffWalking (and Taxi, see :mod:`cartpole_q.families.toy_text.taxi_twin`)
step and reset with ``gymnasium.envs.toy_text.utils.categorical_sample``::

    step:  transitions = P[s][a]; i = categorical_sample([p for p, *_ in transitions], np_random)
           p, s, r, terminated = transitions[i]
    reset: s = categorical_sample(initial_state_distrib, np_random)

and ``categorical_sample(probabilities, np_random)`` is
``np.argmax(np.cumsum(probabilities) > np_random.random())``: one ``random()`` per step and
per reset, also when a transition is certain, and the first outcome when no cumulative
probability exceeds the draw. The twin bakes ``P`` into arrays once (:func:`twin_params`:
the cumulative sums computed by ``np.cumsum`` as Gymnasium computes them, outcome by
outcome) and repeats the draw and the search in compiled code, so it makes the same draws
from the same generator and lands in the same state, bit for bit.

Any ``gymnasium.make`` argument that only changes ``P`` or ``initial_state_distrib`` is
reproduced, because the twin reads them from the environment those arguments build:
FrozenLake's ``map_name``, ``desc``, ``is_slippery``, ``success_rate``, ``reward_schedule``;
CliffWalking's ``is_slippery``. ``max_episode_steps`` is the caller's time limit;
``render_mode`` is refused (the twin draws nothing).

A world of its own gets this twin with one line in its profile
(``twin=load_twin``, from :mod:`cartpole_q.families.tables`) when it keeps these promises: its
observation is its state, ``Discrete(len(P))`` from 0; ``step`` draws the outcome from
``P[s][a]`` with ``categorical_sample`` and nothing else; ``reset`` draws the start state
from ``initial_state_distrib`` the same way and nothing else; each outcome is
``(probability, next state, reward, terminated)`` with a number as the reward.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Mapping
from typing import Any, TypeVar

import numpy as np
from numba import njit

from cartpole_q.numba_cache import configure as configure_numba_cache

configure_numba_cache()  # before any cache=True function is defined

STATE_SIZE = 1
STATE_DTYPE = np.int64
"""the state ``s``"""
OBSERVATION_SIZE = 1
OBSERVATION_DTYPE = np.int64
OBSERVATION_KIND = "discrete"
READS_ENVIRONMENT = True
PARAM_NAMES = (
    "initial_cumulative",
    "cumulative",
    "outcomes",
    "next_states",
    "rewards",
    "terminations",
)
"""what ``params`` holds, in order: ``np.cumsum(initial_state_distrib)`` (float64, one per
state); per ``(state, action, outcome)`` the cumulative probability (float64), the next
state (int64), the reward (float64) and whether it terminates (bool), padded to the largest
number of outcomes; and per ``(state, action)`` the number of outcomes (int64)"""
INITIAL_CUMULATIVE, CUMULATIVE, OUTCOMES, NEXT_STATES, REWARDS, TERMINATIONS = range(6)
REFUSED_KWARGS = ("render_mode",)
"""``gymnasium.make`` arguments the twin does not reproduce"""

_BAKED: dict[tuple[str, str], tuple[np.ndarray, ...] | str] = {}
"""the tables already baked, by id and arguments: a run asks for them several times"""


def twin_params(kwargs: Mapping[str, Any], env_id: str) -> tuple[np.ndarray, ...] | str:
    """Return ``params`` for ``gymnasium.make(env_id, **kwargs)``, read from its ``P``.

    Returns:
        The arrays of :data:`PARAM_NAMES`, or a sentence saying why the twin cannot
        reproduce the environment.
    """
    for key in REFUSED_KWARGS:
        if key in kwargs:
            return f"env.kwargs key {key!r} is not reproduced by the compiled twin"
    return read_environment(env_id, kwargs, repeatable_table, _BAKED)


def repeatable_table(env: Any) -> tuple[np.ndarray, ...] | str:
    """:func:`table_params`, refused when a second environment made alike has another table.

    An environment built at random (FrozenLake with neither ``desc`` nor ``map_name``
    draws its map from an unseeded generator) would give the twin one table and the
    gymnasium engine another.
    """
    import gymnasium

    table = table_params(env)
    if isinstance(table, str) or env.spec is None:
        return table
    again = gymnasium.make(env.spec)
    try:
        made: Any = again.unwrapped
        if getattr(made, "P", None) is env.P and np.array_equal(
            made.initial_state_distrib, env.initial_state_distrib
        ):
            return table  # one table shared by the worlds made alike (the racetrack's)
        other = table_params(again.unwrapped)
    finally:
        again.close()
    same = not isinstance(other, str) and all(
        a.shape == b.shape and a.dtype == b.dtype and a.tobytes() == b.tobytes()
        for a, b in zip(table, other, strict=True)
    )
    if not same:
        return (
            "the environment builds another transition table each time it is made (a "
            "random map? give FrozenLake's desc or map_name)"
        )
    return table


Read = TypeVar("Read")


def read_environment(
    env_id: str,
    kwargs: Mapping[str, Any],
    read: Callable[[Any], Read | str],
    cache: dict[tuple[str, str], Read | str],
) -> Read | str:
    """``read(gymnasium.make(env_id, **kwargs).unwrapped)``, once per id and arguments.

    Args:
        env_id: the Gymnasium id.
        kwargs: the ``gymnasium.make`` arguments.
        read: what to read from the unwrapped environment (or why it cannot be read).
        cache: where results are kept, by id and arguments (as JSON; arguments JSON
            cannot write are read afresh every time).

    Returns:
        What ``read`` returns, or a sentence saying why the environment cannot be made.
    """
    import gymnasium

    try:
        key: tuple[str, str] | None = (env_id, json.dumps(dict(kwargs), sort_keys=True))
    except (TypeError, ValueError):
        key = None
    if key is not None and key in cache:
        return cache[key]
    try:
        made = gymnasium.make(env_id, **kwargs)
    except Exception as error:  # the config check reports it in full; here, a reason
        return f"{env_id!r} cannot be made with these env.kwargs ({error})"
    try:
        found = read(made.unwrapped)
    finally:
        made.close()
    if key is not None:
        cache[key] = found
    return found


def table_params(env: Any, aggregated: bool = False) -> tuple[np.ndarray, ...] | str:
    """The arrays of :data:`PARAM_NAMES` of an unwrapped environment, or why there are none.

    Args:
        env: the unwrapped environment.
        aggregated: its observations are groups of states (``observation_of_state``), which
            the caller checks (:mod:`~cartpole_q.families.tables.aggregated_twin`); else they
            must be the states.
    """
    if not getattr(env, "plays_its_table", True):
        return (
            "the environment does not play its transition table as made (its table changes "
            "while it is played, or its rewards are drawn rather than tabulated)"
        )
    transitions = getattr(env, "P", None)
    initial = getattr(env, "initial_state_distrib", None)
    if not isinstance(transitions, Mapping) or initial is None:
        return "the environment has no transition table (P and initial_state_distrib)"
    n_states = len(transitions)
    space = env.observation_space
    if not aggregated and getattr(env, "observation_of_state", None) is not None:
        return "the environment observes groups of states (observation_of_state)"
    if not aggregated and (
        getattr(space, "n", None) != n_states or getattr(space, "start", None) != 0
    ):
        return "the environment's observations are not the states of its transition table"
    if sorted(transitions) != list(range(n_states)):
        return "the transition table's states are not 0, 1, ..., n - 1"
    n_actions = int(env.action_space.n)
    if any(sorted(transitions[s]) != list(range(n_actions)) for s in range(n_states)):
        return "the transition table does not give every action of every state"
    width = max(len(transitions[s][a]) for s in range(n_states) for a in range(n_actions))
    outcomes = np.zeros((n_states, n_actions), dtype=np.int64)
    cumulative = np.zeros((n_states, n_actions, width), dtype=np.float64)
    next_states = np.zeros((n_states, n_actions, width), dtype=np.int64)
    rewards = np.zeros((n_states, n_actions, width), dtype=np.float64)
    terminations = np.zeros((n_states, n_actions, width), dtype=np.bool_)
    for s in range(n_states):
        for a in range(n_actions):
            listed = transitions[s][a]
            if not listed or any(len(outcome) != 4 for outcome in listed):
                return f"P[{s}][{a}] is not a list of (probability, state, reward, terminated)"
            outcomes[s, a] = len(listed)
            # Exactly categorical_sample's cumulative sums: np.cumsum of np.asarray(probabilities).
            sums = np.cumsum(np.asarray([outcome[0] for outcome in listed]))
            for i, (_, next_state, reward, terminated) in enumerate(listed):
                if isinstance(reward, bool) or not isinstance(reward, int | float | np.integer):
                    return f"P[{s}][{a}] has a reward that is not a number: {reward!r}"
                if not 0 <= int(next_state) < n_states:
                    return f"P[{s}][{a}] leads to state {next_state!r}, outside the table"
                cumulative[s, a, i] = sums[i]
                next_states[s, a, i] = int(next_state)
                rewards[s, a, i] = float(reward)
                terminations[s, a, i] = bool(terminated)
    initial_cumulative = np.cumsum(np.asarray(initial)).astype(np.float64)
    if initial_cumulative.shape != (n_states,):
        return "initial_state_distrib does not hold one probability per state"
    return (initial_cumulative, cumulative, outcomes, next_states, rewards, terminations)


@njit(cache=True, nogil=True, inline="always")
def first_above(cumulative: np.ndarray, count: int, draw: float) -> int:
    """``np.argmax(cumulative[:count] > draw)``: the first entry above, 0 when none is."""
    for i in range(count):
        if cumulative[i] > draw:
            return i
    return 0


@njit(cache=True, nogil=True, inline="always")
def sampled_outcome(
    cumulative: np.ndarray, state: int, action: int, count: int, rng: np.random.Generator
) -> int:
    """``categorical_sample`` over ``P[state][action]``: one ``rng.random()``, then the search."""
    draw = rng.random()
    for i in range(count):
        if cumulative[state, action, i] > draw:
            return i
    return 0


@njit(cache=True, nogil=True, inline="always")
def initial_state(params: Any, rng: np.random.Generator) -> int:
    """``categorical_sample(initial_state_distrib, rng)``."""
    initial_cumulative = params[INITIAL_CUMULATIVE]
    return first_above(initial_cumulative, initial_cumulative.size, rng.random())


@njit(cache=True, nogil=True, inline="always")
def table_step(
    state: int, action: int, rng: np.random.Generator, params: Any
) -> tuple[int, float, bool]:
    """One step of the table from ``state``: ``(next state, reward, terminated)``."""
    outcome = sampled_outcome(
        params[CUMULATIVE], state, action, params[OUTCOMES][state, action], rng
    )
    return (
        params[NEXT_STATES][state, action, outcome],
        params[REWARDS][state, action, outcome],
        params[TERMINATIONS][state, action, outcome],
    )


@njit(cache=True, nogil=True, inline="always")
def reset(
    state: np.ndarray, observation: np.ndarray, rng: np.random.Generator, params: Any
) -> None:
    """Draw the start state as Gymnasium's ``reset`` does; the observation is the state."""
    state[0] = initial_state(params, rng)
    observation[0] = state[0]


@njit(cache=True, nogil=True, inline="always")
def step(
    state: np.ndarray,
    action: int,
    observation: np.ndarray,
    rng: np.random.Generator,
    params: Any,
) -> tuple[float, bool]:
    """Draw the outcome of ``action`` as Gymnasium's ``step`` does; move there.

    Returns:
        The outcome's reward and whether it terminates the episode. Truncation is the
        caller's time limit.
    """
    next_state, reward, terminated = table_step(state[0], action, rng, params)
    state[0] = next_state
    observation[0] = next_state
    return reward, terminated
