"""Exact models of environments whose dynamics are known: the input of value iteration.

- Environments with a transition table, ``env.unwrapped.P`` (Gymnasium's FrozenLake, Taxi,
  CliffWalking, any ``gymnasium.make`` arguments they take), are read from it; their states
  are their observations, so a Q-table row is a model state.
- Blackjack has no table, but its rules define one exactly: its family builds it
  (:mod:`cartpole_q.families.blackjack.model`).

:func:`env_model` returns the model with the horizon its episodes have (the time limit, or
``GREEDY_STEP_CAP`` where the environment has none, as greedy evaluation plays it), or
says why there is none.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from cartpole_q.config import EnvConfig
from cartpole_q.families import profile_for
from cartpole_q.families.blackjack.model import MODEL_KWARGS, blackjack_model
from cartpole_q.rl.mdp import FiniteMDP

GREEDY_STEP_CAP = 10_000
"""where a greedy episode stops in an environment without a time limit (CliffWalking,
Blackjack): a deterministic policy can walk in circles forever there"""


@dataclass(frozen=True)
class EnvModel:
    """An environment's exact model and how Q-table rows map onto its states."""

    model: FiniteMDP
    row_of_state: np.ndarray
    """int64, one per model state: the Q-table row whose greedy action is played there"""
    horizon: int
    """steps an episode may take: the time limit, or the greedy cap where there is none"""
    time_limit: int | None
    """the environment's time limit (``None``: it has none)"""
    source: str
    """where the model comes from, in a few words"""
    success_probability: bool
    """the return is 1 on success and 0 otherwise (FrozenLake): the value is a probability"""
    aggregates: bool = False
    """the world observes groups of states (its ``observation_of_state``: state aggregation),
    so several states share a row by design"""
    measured: np.ndarray | None = None
    """int64: the only model states a prediction run's error is measured on, where the world
    says so (its ``measured_states``: Blackjack dealt one hand); ``None``: every reachable
    non-terminal state"""


def env_model(env: EnvConfig, spec_max_steps: int | None = None) -> EnvModel | str:
    """The exact model of ``gymnasium.make(env.id, **env.kwargs)``, or why there is none.

    Args:
        env: the environment's config.
        spec_max_steps: the registered time limit, when the caller knows it.
    """
    from cartpole_q.envs.gym import make_env

    made = make_env(env)
    try:
        unwrapped = made.unwrapped
        spec = made.spec
        limit = env.kwargs.get("max_episode_steps", spec.max_episode_steps if spec else None)
        limit = limit if limit is not None else spec_max_steps
        horizon = int(limit) if limit else GREEDY_STEP_CAP
        # Any environment with a transition table has that model, profiled or not.
        kind = profile_for(env.id).model or "transition_table"
        if kind == "blackjack":
            unsupported = [key for key in env.kwargs if key not in MODEL_KWARGS]
            if unsupported:
                return f"env.kwargs key {unsupported[0]!r} is not in the Blackjack model"
            model, rows = blackjack_model(bool(unwrapped.sab), bool(unwrapped.natural))
            measured = getattr(unwrapped, "measured_states", None)
            if measured is not None:  # dealt one hand (Example 5.4): it starts there
                dealt = np.zeros(model.n_states)
                dealt[list(measured)] = 1.0 / len(measured)
                model = replace(model, initial=dealt)
                measured = np.asarray(measured, dtype=np.int64)
            return EnvModel(
                model, rows, horizon, limit, "the rules of Blackjack", False, measured=measured
            )
        transitions = getattr(unwrapped, "P", None)
        initial = getattr(unwrapped, "initial_state_distrib", None)
        if not isinstance(transitions, Mapping) or initial is None:
            return f"{env.id!r} has no transition table (env.unwrapped.P)"
        if getattr(unwrapped, "fickle_passenger", False):
            return "Taxi's fickle_passenger changes destinations outside its transition table"
        space = made.observation_space
        observed = getattr(unwrapped, "observation_of_state", None)
        if observed is not None:
            rows = np.asarray(observed)
            n = getattr(space, "n", None)
            if (
                rows.shape != (len(transitions),) or rows.dtype.kind not in "iu" or n is None
                or getattr(space, "start", 0) != 0 or rows.min() < 0 or rows.max() >= n
            ):  # fmt: skip
                return f"{env.id!r}: its observation_of_state does not map its states onto its observations"
        elif getattr(space, "n", None) != len(transitions) or getattr(space, "start", 0) != 0:
            return f"{env.id!r}: its observations are not the states of its transition table"
        model = FiniteMDP.from_transitions(transitions, initial, int(made.action_space.n))
        success = _pays_only_success(model)
        if observed is not None:
            where = "env.unwrapped.P, observed in groups of states (observation_of_state)"
            return EnvModel(
                model, rows.astype(np.int64), horizon, limit, where, success, aggregates=True
            )
        return EnvModel(
            model, np.arange(model.n_states), horizon, limit, "env.unwrapped.P", success
        )
    finally:
        made.close()


def point_model(env: EnvConfig) -> tuple[FiniteMDP, np.ndarray] | None:
    """The model of a world observed as points, and each state's point, or ``None``.

    A world with a transition table that observes its states as points of a Box (its
    ``point_of_state``, float32 ``(n_states, d)``: the 1000-state walk with ``position``)
    has no table rows a policy could be read from, so :func:`env_model` gives it none; its
    model still gives the true values of a prediction run on tiles.
    """
    from cartpole_q.envs.gym import make_env

    made = make_env(env)
    try:
        unwrapped = made.unwrapped
        points = getattr(unwrapped, "point_of_state", None)
        transitions = getattr(unwrapped, "P", None)
        initial = getattr(unwrapped, "initial_state_distrib", None)
        if points is None or not isinstance(transitions, Mapping) or initial is None:
            return None
        model = FiniteMDP.from_transitions(transitions, initial, int(made.action_space.n))
        return model, np.asarray(points, dtype=np.float32)
    finally:
        made.close()


def _pays_only_success(model: FiniteMDP) -> bool:
    """Whether the only rewards are 1 on a terminating step and 0 otherwise."""
    paid = model.reward != 0
    return bool(np.all(model.reward[paid] == 1.0) and np.all(model.terminated[paid]))


def optimum_note(env_model_or_reason: Any) -> str:
    """A few words on what the exact values mean for this model."""
    if isinstance(env_model_or_reason, str):
        return env_model_or_reason
    limit = env_model_or_reason.time_limit
    within = f"within its time limit of {limit} steps" if limit else (
        f"within {env_model_or_reason.horizon:,} steps (no time limit; greedy episodes stop there)"
    )  # fmt: skip
    kind = "success probability" if env_model_or_reason.success_probability else "expected return"
    return f"{kind}, undiscounted, {within}"


@dataclass(frozen=True)
class GridLayout:
    """A grid world's map: what each cell (state ``row * columns + column``) is, how actions move."""

    rows: int
    columns: int
    cells: tuple[str, ...]
    """per state: ``S`` start, ``F`` free, ``H`` hole, ``C`` cliff, ``G`` goal, ``#`` wall,
    ``E`` an end that is not the goal"""
    moves: tuple[tuple[int, int], ...]
    """per action: ``(row step, column step)``"""

    def arrows(self) -> str:
        """One arrow character per action (king's moves' diagonals, ``o`` for staying)."""
        return "".join(_ARROWS[move] for move in self.moves)


_ARROWS = {
    (0, -1): "<", (1, 0): "v", (0, 1): ">", (-1, 0): "^",
    (-1, -1): "↖", (-1, 1): "↗", (1, 1): "↘", (1, -1): "↙", (0, 0): "o",
}  # fmt: skip
"""the text arrow of each move (a king's diagonal moves have theirs)"""


def state_labels(env: EnvConfig) -> dict[int, str]:
    """The names a world gives some of its states (its ``labels``: Example 6.2's A-E)."""
    from cartpole_q.envs.gym import make_env

    made = make_env(env)
    try:
        return {
            int(state): str(name) for state, name in getattr(made.unwrapped, "labels", {}).items()
        }
    finally:
        made.close()


def grid_layout(env: EnvConfig) -> GridLayout | None:
    """A grid world's map, as its profile says to read it; ``None`` for other environments.

    FrozenLake's from its ``desc``, CliffWalking's from its cliff, Sutton & Barto's worlds'
    from their layout.
    """
    from cartpole_q.envs.gym import make_env

    reader = profile_for(env.id).grid
    if reader is None:
        return None
    made = make_env(env)
    try:
        rows, columns, cells, moves = reader(made.unwrapped)
        return GridLayout(rows, columns, tuple(cells), tuple(moves))
    finally:
        made.close()


@dataclass(frozen=True)
class PlanningModel:
    """A world's exact model as dynamic programming takes it, and what figures need of it."""

    model: FiniteMDP
    action_values: tuple[float, ...]
    """what each action means as a number (a stake, cars moved), else its index"""
    source: str
    """where the model comes from, in a few words"""
    shape: tuple[int, int] | None
    """a grid world's ``(rows, columns)`` (state ``row * columns + column``), else ``None``"""
    moves: tuple[tuple[int, int], ...]
    """a grid world's ``(row step, column step)`` per action, else empty"""
    labels: Mapping[int, str]
    """names of some states, for figures (the world's ``labels``; Example 3.5's A, B)"""


def planning_model(env: EnvConfig, source: str = "config") -> PlanningModel | str:
    """The dense model of ``gymnasium.make(env.id, **env.kwargs)``, or why there is none.

    A world with a ``dense_model()`` method (Jack's car rental) gives its arrays; any other
    with a transition table ``env.unwrapped.P`` (the book's gridworlds, the gambler,
    FrozenLake, Taxi, CliffWalking) is read from it. ``allowed_actions()``, where the world
    has it, says which actions each state offers (else all).

    Raises:
        ConfigError: the environment cannot be made (as :func:`~cartpole_q.envs.gym.make_env`).
    """
    from cartpole_q.envs.gym import make_env

    made = make_env(env, source=source)
    try:
        unwrapped = made.unwrapped
        n_actions = int(made.action_space.n)
        allowed_of = getattr(unwrapped, "allowed_actions", None)
        allowed = None if allowed_of is None else np.asarray(allowed_of(), dtype=bool)
        dense = getattr(unwrapped, "dense_model", None)
        if dense is not None:
            transition, reward = dense()
            model = FiniteMDP.from_dense(transition, reward, allowed)
            where = f"{type(unwrapped).__name__}.dense_model()"
        else:
            found = env_model(env)
            if isinstance(found, str):
                return found
            model = found.model if allowed is None else replace(found.model, allowed=allowed)
            where = found.source
        values = getattr(unwrapped, "action_values", None)
        action_values = (
            tuple(float(v) for v in values) if values else tuple(map(float, range(n_actions)))
        )
        rows, columns = getattr(unwrapped, "rows", None), getattr(unwrapped, "columns", None)
        moves = tuple(getattr(unwrapped, "moves", ()))
        shape = (rows, columns) if isinstance(rows, int) and isinstance(columns, int) else None
        labels = dict(getattr(unwrapped, "labels", {}))
        if shape is None:  # a world its profile reads as a grid (FrozenLake, CliffWalking)
            layout = grid_layout(env)
            if layout is not None:
                shape, moves = (layout.rows, layout.columns), layout.moves
        if shape is None or shape[0] * shape[1] != model.n_states:
            return PlanningModel(model, action_values, where, None, (), labels)
        return PlanningModel(model, action_values, where, shape, moves, labels)
    finally:
        made.close()
