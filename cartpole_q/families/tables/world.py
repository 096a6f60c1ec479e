"""A world stepped from its transition table, as Gymnasium's toy-text worlds are.

``P[s][a] = [(probability, next_state, reward, terminated), ...]`` is the world: ``reset``
draws the start from ``initial_state_distrib`` and ``step`` draws an outcome of
``P[s][a]``, each with one ``np_random.random()`` (Gymnasium's ``categorical_sample``,
exactly as FrozenLake, CliffWalking and Taxi do, deterministic outcomes included). So the
table that ``cartpole-q optimum`` solves is the world that is played, and a compiled twin
of one toy-text world reproduces these draws too.
"""

from __future__ import annotations

from typing import Any

import gymnasium
import numpy as np
from gymnasium import spaces
from gymnasium.envs.toy_text.utils import categorical_sample

Outcome = tuple[float, int, float, bool]
"""``(probability, next_state, reward, terminated)``"""

Table = dict[int, dict[int, list[Outcome]]]
"""``P[state][action]``: the outcomes of taking ``action`` in ``state``"""


class TableWorld(gymnasium.Env[Any, Any]):
    """A world of ``n_states`` states and ``n_actions`` actions played from its table ``P``.

    Observations and actions are plain integers. Subclasses build ``P``; ``step`` reports the outcome's
    probability in ``info["prob"]``, as the toy-text worlds do. The observation is the state,
    unless the world sets :attr:`observation_of_state` (state aggregation: the observation
    is a group of states).
    """

    metadata = {"render_modes": [], "render_fps": 4}  # noqa: RUF012 - gymnasium.Env declares it
    plays_its_table = True
    """every step is one draw of ``P`` as it was when the environment was made; a compiled
    twin baked from ``P`` then plays it exactly (see ``families/tables/twin.py``)"""
    observation_of_state: np.ndarray | None = None
    """int64, one per state of ``P``: the observation a state is seen as (``None``: the state
    itself); a world that sets it aggregates states, and its compiled twin is
    ``families/tables/aggregated_twin.py``"""

    point_of_state: np.ndarray | None = None
    """float32 ``(n_states, d)``: a world observed as points (a Box) rather than integers
    gives each state's observation here (``None``: it observes integers); tile coding then
    measures the true values on each state's tiles"""

    features_of_state: np.ndarray | None = None
    """float64 ``(n_states, d)``: linear features the world declares for its states (Baird's
    counterexample), which a ``linear`` study's ``features: {kind: declared}`` takes
    (``None``: none)"""

    features_of_action: np.ndarray | None = None
    """float64 ``(n_states, n_actions, d)``: the features of each state-action pair the world
    declares for a policy's preferences (the short corridor), which a ``policy_gradient``
    study's ``policy_features: declared`` takes (``None``: none)"""

    def __init__(self, n_states: int, n_actions: int, start: int) -> None:
        self.observation_space = spaces.Discrete(n_states)
        self.action_space = spaces.Discrete(n_actions)
        self.initial_state_distrib = np.zeros(n_states)
        self.initial_state_distrib[start] = 1.0
        self.P: Table = {}
        self.s = start

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[Any, dict[str, Any]]:
        """Start an episode: the start state, drawn as the toy-text worlds draw it."""
        super().reset(seed=seed)
        self.s = int(categorical_sample(self.initial_state_distrib, self.np_random))
        return self.observe(self.s), {"prob": 1.0}

    def step(self, action: int) -> tuple[Any, float, bool, bool, dict[str, Any]]:
        """Take ``action``: one outcome of ``P[s][action]``, drawn with ``np_random``."""
        outcomes = self.P[self.s][int(action)]
        chosen = int(categorical_sample([outcome[0] for outcome in outcomes], self.np_random))
        probability, following, reward, terminated = outcomes[chosen]
        self.s = following
        return self.observe(following), reward, terminated, False, {"prob": probability}

    def observe(self, state: int) -> Any:
        """The observation of ``state``: the state, its group, or its point (a Box world)."""
        if self.point_of_state is not None:
            return self.point_of_state[state].copy()
        if self.observation_of_state is None:
            return state
        return int(self.observation_of_state[state])
