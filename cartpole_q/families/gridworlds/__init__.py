"""The book's grid worlds: the windy gridworlds (Example 6.5) and the Dyna mazes (8.1-8.3).

Their worlds, the king's-moves windy gridworlds of Exercises 6.9 and 6.10 among them, are
in :mod:`~cartpole_q.families.gridworlds.worlds`.

Each has a transition table, so ``cartpole-q optimum`` and ``eval`` compute the best return
exactly, and the compiled twin of any world played from its table
(:mod:`cartpole_q.families.tables`). Their policy maps are drawn as grids, read from the
environment (``env.unwrapped``), so a changed argument (``stay``, ``change_at``) shows. The
book gives no time limit; the tool needs episodes to end (a greedy policy can walk in
circles), so each has a generous one, :data:`GRID_TIME_LIMIT`.
"""

from __future__ import annotations

from typing import Any

from cartpole_q.families.base import NAMESPACE, EnvProfile, GridCells, World
from cartpole_q.families.tables import load_twin as load_table_twin

_GRIDS = "cartpole_q.families.gridworlds.worlds"
_COMPASS = ("up", "down", "left", "right")
GRID_TIME_LIMIT = 10_000
"""steps before a grid world's episode is truncated"""


def gridworld_grid(world: Any) -> GridCells:
    """A grid world's map: its start, goal and walls (``#``), from the world's attributes."""
    cells = []
    for row in range(world.rows):
        for column in range(world.columns):
            cell = (row, column)
            letter = "S" if cell == world.start else "G" if cell == world.goal else "F"
            cells.append("#" if cell in world.walls else letter)
    return world.rows, world.columns, tuple(cells), tuple(world.moves)


WINDY_GRIDWORLD = EnvProfile(
    name="WindyGridworld",
    description="reach the goal against an upward wind, -1 per step (Sutton & Barto's Example 6.5)",
    ids=("cartpole_q/WindyGridworld-v0",),
    entry_points=(f"{_GRIDS}:WindyGridworldEnv",),
    action_names=_COMPASS,
    policy_map="grid",
    grid=gridworld_grid,
    model="transition_table",
    twin=load_table_twin,
)

KINGS_WINDY_GRIDWORLD = EnvProfile(
    name="KingsWindyGridworld",
    description="the windy gridworld with king's moves, its wind steady or varying "
    "(Exercises 6.9 and 6.10)",
    ids=("cartpole_q/KingsWindyGridworld-v0", "cartpole_q/StochasticWindyGridworld-v0"),
    entry_points=(f"{_GRIDS}:KingsWindyGridworldEnv", f"{_GRIDS}:StochasticWindyGridworldEnv"),
    action_names=(*_COMPASS, "up-left", "up-right", "down-left", "down-right"),
    policy_map="grid",
    grid=gridworld_grid,
    model="transition_table",
    twin=load_table_twin,
)

DYNA_MAZE = EnvProfile(
    name="DynaMaze",
    description="find the way through a maze, +1 at the goal; the blocking and shortcut "
    "mazes change after 1000 and 3000 steps (Examples 8.1-8.3)",
    ids=("cartpole_q/DynaMaze-v0", "cartpole_q/BlockingMaze-v0", "cartpole_q/ShortcutMaze-v0"),
    entry_points=tuple(
        f"{_GRIDS}:{name}" for name in ("DynaMazeEnv", "BlockingMazeEnv", "ShortcutMazeEnv")
    ),
    action_names=_COMPASS,
    policy_map="grid",
    grid=gridworld_grid,
    model="transition_table",
    twin=load_table_twin,
)

PROFILES = (WINDY_GRIDWORLD, KINGS_WINDY_GRIDWORLD, DYNA_MAZE)
"""the family's profiles"""
WORLDS: tuple[World, ...] = (
    World(f"{NAMESPACE}/WindyGridworld-v0", f"{_GRIDS}:WindyGridworldEnv", GRID_TIME_LIMIT),
    World(
        f"{NAMESPACE}/KingsWindyGridworld-v0", f"{_GRIDS}:KingsWindyGridworldEnv", GRID_TIME_LIMIT
    ),
    World(
        f"{NAMESPACE}/StochasticWindyGridworld-v0",
        f"{_GRIDS}:StochasticWindyGridworldEnv",
        GRID_TIME_LIMIT,
    ),
    World(f"{NAMESPACE}/DynaMaze-v0", f"{_GRIDS}:DynaMazeEnv", GRID_TIME_LIMIT),
    World(f"{NAMESPACE}/BlockingMaze-v0", f"{_GRIDS}:BlockingMazeEnv", GRID_TIME_LIMIT),
    World(f"{NAMESPACE}/ShortcutMaze-v0", f"{_GRIDS}:ShortcutMazeEnv", GRID_TIME_LIMIT),
)
"""the worlds it registers"""
