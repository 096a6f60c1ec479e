"""A user's environment, in one file outside the package: a corridor, and its profile.

A 1 x 6 corridor: start in the leftmost cell, the goal at the right end pays 1; actions
left and right; 20 steps at most. It is a real Gymnasium environment (registered under
``cartpole_q_tests/Corridor-v0``) with a transition table, so ``cartpole-q optimum`` solves
it, and its profile names its actions and draws it as a grid. Nothing in the package
names it.
"""

from __future__ import annotations

from typing import Any, ClassVar

import gymnasium
import numpy as np
from gymnasium import spaces

from cartpole_q.families import EnvProfile, register_profile
from cartpole_q.families.base import GridCells

ENV_ID = "cartpole_q_tests/Corridor-v0"
LENGTH = 6


class CorridorEnv(gymnasium.Env[int, int]):
    """Walk right to the goal; a transition table ``P`` as toy-text environments have."""

    metadata: ClassVar[dict[str, Any]] = {"render_modes": [], "render_fps": 4}

    def __init__(self) -> None:
        self.observation_space = spaces.Discrete(LENGTH)
        self.action_space = spaces.Discrete(2)
        self.initial_state_distrib = np.eye(LENGTH)[0]
        self.P: dict[int, dict[int, list[tuple[float, int, float, bool]]]] = {}
        for state in range(LENGTH):
            self.P[state] = {}
            for action, move in ((0, -1), (1, 1)):
                following = min(LENGTH - 1, max(0, state + move))
                done = following == LENGTH - 1
                self.P[state][action] = [(1.0, following, float(done), done)]
        self.state = 0

    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None) -> tuple[int, dict[str, Any]]:  # fmt: skip
        super().reset(seed=seed)
        self.state = 0
        return self.state, {}

    def step(self, action: int) -> tuple[int, float, bool, bool, dict[str, Any]]:
        ((_, following, reward, done),) = self.P[self.state][int(action)]
        self.state = following
        return following, reward, done, False, {}


def corridor_grid(world: Any) -> GridCells:
    """One row: the start, free cells, the goal; actions left and right."""
    cells = ("S", *("F",) * (LENGTH - 2), "G")
    return 1, LENGTH, cells, ((0, -1), (0, 1))


if ENV_ID not in gymnasium.registry:
    gymnasium.register(ENV_ID, entry_point=CorridorEnv, max_episode_steps=20, reward_threshold=0.9)

PROFILE = register_profile(
    EnvProfile(
        name="Corridor",
        description="walk right to the goal (a test's own world)",
        ids=(ENV_ID,),
        action_names=("left", "right"),
        policy_map="grid",
        grid=corridor_grid,
    )
)
