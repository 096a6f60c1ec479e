"""Sutton & Barto's worlds (:mod:`cartpole_q.worlds`).

The windy gridworlds, the Dyna mazes, the maximization-bias MDP, the 5- and 19-state
random walks and the 1000-state walk (Example 9.1; observed in groups of states with
``env.kwargs.groups``, its policy has no map). Each has a transition table, so ``cartpole-q optimum`` and ``eval`` compute the best return
exactly; the grid worlds and the walk draw their policy maps as grids. The maps are read
from the environment (``env.unwrapped``), so a changed argument (``stay``, ``change_at``)
shows.
"""

from __future__ import annotations

from types import MappingProxyType
from typing import Any

from cartpole_q.profiles.base import EnvProfile, GridCells

_GRIDS = "cartpole_q.worlds.gridworlds"
_COMPASS = ("up", "down", "left", "right")


def gridworld_grid(world: Any) -> GridCells:
    """A grid world's map: its start, goal and walls (``#``), from the world's attributes."""
    cells = []
    for row in range(world.rows):
        for column in range(world.columns):
            cell = (row, column)
            letter = "S" if cell == world.start else "G" if cell == world.goal else "F"
            cells.append("#" if cell in world.walls else letter)
    return world.rows, world.columns, tuple(cells), tuple(world.moves)


def random_walk_grid(world: Any) -> GridCells:
    """The walk as one row: its left end (``E``), the start, its right end (``G``, +1)."""
    states = int(world.observation_space.n)
    start = int(world.initial_state_distrib.argmax())
    cells = ["E" if state == 0 else "G" if state == states - 1 else "F" for state in range(states)]
    cells[start] = "S"
    return 1, states, tuple(cells), ((0, -1), (0, 1))


WINDY_GRIDWORLD = EnvProfile(
    name="WindyGridworld",
    description="reach the goal against an upward wind, -1 per step (Sutton & Barto's Example 6.5)",
    ids=("cartpole_q/WindyGridworld-v0",),
    entry_points=(f"{_GRIDS}:WindyGridworldEnv",),
    action_names=_COMPASS,
    policy_map="grid",
    grid=gridworld_grid,
    model="transition_table",
    twin="cartpole_q.envs.twins.transition_table",
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
    twin="cartpole_q.envs.twins.transition_table",
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
    twin="cartpole_q.envs.twins.transition_table",
)

MAXIMIZATION_BIAS = EnvProfile(
    name="MaximizationBias",
    description="left from A to B's noisy rewards (mean -0.1) or right to 0 "
    "(Sutton & Barto's Example 6.7)",
    ids=("cartpole_q/MaximizationBias-v0",),
    entry_points=("cartpole_q.worlds.bias:MaximizationBiasEnv",),
    model="transition_table",
)


def always_left(state_shape: tuple[int, ...]) -> list[int]:
    """The one-state MDP's target policy (Example 5.5): left (0) in every state.

    >>> always_left((2,))
    [0, 0]
    """
    return [0] * state_shape[0]


ONE_STATE = EnvProfile(
    name="OneState",
    description="left comes back (0.9) or ends with +1, right ends with 0 (Sutton & Barto's "
    "Example 5.5)",
    ids=("cartpole_q/OneState-v0",),
    entry_points=("cartpole_q.worlds.one_state:OneStateEnv",),
    action_names=("left", "right"),
    model="transition_table",
    twin="cartpole_q.envs.twins.transition_table",
    policies=MappingProxyType({"left": always_left}),
)

RANDOM_WALK = EnvProfile(
    name="RandomWalk",
    description="a walk between two ends, +1 on the right: 5 states from a 0 end (Sutton & "
    "Barto's Example 6.2), 19 from a -1 end (Example 7.1)",
    ids=("cartpole_q/RandomWalk5-v0", "cartpole_q/RandomWalk-v0"),
    entry_points=("cartpole_q.worlds.random_walk:RandomWalkEnv",),
    action_names=("left", "right"),
    policy_map="grid",
    grid=random_walk_grid,
    model="transition_table",
    twin="cartpole_q.envs.twins.transition_table",
)

RANDOM_WALK_1000 = EnvProfile(
    name="RandomWalk1000",
    description="Example 9.1's walk of 1000 states, jumps of up to 100 either way, -1 and +1 "
    "ends; env.kwargs.groups aggregates the states (Figures 9.1, 9.2)",
    ids=("cartpole_q/RandomWalk1000-v0",),
    entry_points=("cartpole_q.worlds.random_walk:JumpingWalkEnv",),
    action_names=("left", "right"),
    model="transition_table",
    twin="cartpole_q.envs.twins.aggregated_table",
)
