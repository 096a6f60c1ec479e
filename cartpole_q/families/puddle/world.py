"""The puddle world (Sutton 1996; Sutton & Barto Figure 12.14): a point to drive to a corner past two puddles.

The state is a point ``(x, y)`` of the unit square, float64. Each of the four actions (up,
down, left, right) moves it :data:`MOVE` (0.05) that way, plus a normal noise of standard
deviation :data:`NOISE` (0.01) on each coordinate, the result clipped to ``[0, 1]``. The
episode ends when ``x + y >= 1.9`` (the goal, the upper right corner). Every step costs 1,
and more inside a puddle: each of the two puddles, the points within :data:`RADIUS` (0.1)
of a segment, from ``(0.1, 0.75)`` to ``(0.45, 0.75)`` and from ``(0.45, 0.4)`` to
``(0.45, 0.8)``, adds ``-400 * (0.1 - d)`` at a point ``d`` from its segment. An episode
starts at a uniformly random point that is not a goal. The observation is the point rounded
to float32.

The book and Sutton (1996) leave the draws open; here (docs/algorithms.md, "Worlds"): the
start is ``(np_random.random(), np_random.random())``, ``x`` drawn first, drawn again
while it is a goal; a step draws ``np_random.normal(0.0, 0.01)`` for ``x``, then for ``y``.

>>> world = PuddleWorldEnv()
>>> [round(world.puddle_cost(x, y), 6) for x, y in ((0.3, 0.75), (0.3, 0.8), (0.9, 0.1))]
[-40.0, -20.0, 0.0]
"""

from __future__ import annotations

import math
from typing import Any

import gymnasium
import numpy as np
from gymnasium import spaces

MOVE = 0.05
"""how far an action moves the point (before the noise)"""
NOISE = 0.01
"""the standard deviation of each coordinate's noise"""
RADIUS = 0.1
"""a puddle's reach around its segment"""
DEPTH_COST = 400.0
"""the cost per unit of distance into a puddle"""
GOAL_SUM = 1.9
"""the goal: ``x + y`` at least this"""
MOVES = ((0.0, MOVE), (0.0, -MOVE), (-MOVE, 0.0), (MOVE, 0.0))
"""per action (up, down, left, right): the move in ``x`` and in ``y``"""
HORIZONTAL = (0.1, 0.45, 0.75)
"""the first puddle's segment: ``x`` from 0.1 to 0.45 at ``y`` 0.75"""
VERTICAL = (0.4, 0.8, 0.45)
"""the second puddle's segment: ``y`` from 0.4 to 0.8 at ``x`` 0.45"""


def puddle_cost(x: float, y: float) -> float:
    """The puddles' cost at ``(x, y)``: 0.0, or ``-400 * (0.1 - d)`` summed over the puddles.

    ``d`` is the distance to a puddle's segment, ``math.sqrt(dx * dx + dy * dy)`` with
    ``dx``, ``dy`` the offsets to its nearest point (the first puddle's then the second's).
    """
    cost = 0.0
    low, high, level = HORIZONTAL
    dx = x - min(max(x, low), high)
    dy = y - level
    distance = math.sqrt(dx * dx + dy * dy)
    if distance < RADIUS:
        cost = cost - DEPTH_COST * (RADIUS - distance)
    low, high, level = VERTICAL
    dx = x - level
    dy = y - min(max(y, low), high)
    distance = math.sqrt(dx * dx + dy * dy)
    if distance < RADIUS:
        cost = cost - DEPTH_COST * (RADIUS - distance)
    return cost


class PuddleWorldEnv(gymnasium.Env[np.ndarray, np.int64]):
    """The puddle world: a float32 point of the unit square, four moves, -1 a step plus puddles."""

    metadata = {"render_modes": [], "render_fps": 30}  # noqa: RUF012 - gymnasium.Env declares it

    def __init__(self) -> None:
        self.observation_space = spaces.Box(0.0, 1.0, shape=(2,), dtype=np.float32)
        self.action_space = spaces.Discrete(len(MOVES))
        self.state = np.zeros(2, dtype=np.float64)

    puddle_cost = staticmethod(puddle_cost)

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        """Start at a uniformly random point that is not a goal."""
        super().reset(seed=seed)
        while True:
            x = float(self.np_random.random())
            y = float(self.np_random.random())
            if not x + y >= GOAL_SUM:
                break
        self.state[0], self.state[1] = x, y
        return self.state.astype(np.float32), {}

    def step(self, action: np.int64) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        """Move, add the noise, clip; -1 plus the puddles' cost; ended at the goal."""
        move_x, move_y = MOVES[int(action)]
        x = self.state[0] + move_x + float(self.np_random.normal(0.0, NOISE))
        y = self.state[1] + move_y + float(self.np_random.normal(0.0, NOISE))
        x = min(max(x, 0.0), 1.0)
        y = min(max(y, 0.0), 1.0)
        self.state[0], self.state[1] = x, y
        reward = -1.0 + puddle_cost(x, y)
        return self.state.astype(np.float32), reward, x + y >= GOAL_SUM, False, {}
