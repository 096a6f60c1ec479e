"""Gymnasium's toy-text grid worlds: FrozenLake, Taxi and CliffWalking.

Each has an exact model, its transition table (``env.unwrapped.P``), so ``cartpole-q
optimum`` and ``eval`` compute the best return. Each has a compiled twin: FrozenLake and
CliffWalking the one of any world that moves by its transition table
(:mod:`cartpole_q.families.tables`), Taxi that one with its fickle passenger
(:mod:`~cartpole_q.families.toy_text.taxi_twin`). Blackjack is a family of its own
(:mod:`cartpole_q.families.blackjack`).
"""

from __future__ import annotations

from typing import Any

from cartpole_q.families.base import EnvProfile, GridCells, TwinModule, World
from cartpole_q.families.tables import load_twin as load_table_twin


def frozenlake_grid(lake: Any) -> GridCells:
    """FrozenLake's map, from its ``desc``; actions left, down, right, up."""
    desc = [[cell.decode() for cell in row] for row in lake.desc]
    rows, columns = len(desc), len(desc[0])
    cells = tuple(desc[r][c] for r in range(rows) for c in range(columns))
    return rows, columns, cells, ((0, -1), (1, 0), (0, 1), (-1, 0))


def cliffwalking_grid(world: Any) -> GridCells:
    """CliffWalking's map, from its cliff; actions up, right, down, left."""
    rows, columns = (int(n) for n in world.shape)
    start = int(world.start_state_index)
    cells = []
    for state in range(rows * columns):
        r, c = divmod(state, columns)
        goal = (r, c) == (rows - 1, columns - 1)
        cliff = bool(world._cliff[r][c])
        cells.append("S" if state == start else "G" if goal else "C" if cliff else "F")
    return rows, columns, tuple(cells), ((-1, 0), (0, 1), (1, 0), (0, -1))


def load_taxi_twin() -> TwinModule:
    """Taxi's compiled twin (its passenger's moods), imported when first used."""
    from cartpole_q.families.toy_text import taxi_twin

    return taxi_twin


FROZENLAKE = EnvProfile(
    name="FrozenLake",
    description="cross a frozen lake to the goal without falling in a hole (slippery or not)",
    ids=("FrozenLake-v1", "FrozenLake8x8-v1"),
    entry_points=("gymnasium.envs.toy_text.frozen_lake:FrozenLakeEnv",),
    action_names=("left", "down", "right", "up"),
    policy_map="grid",
    grid=frozenlake_grid,
    model="transition_table",
    twin=load_table_twin,
)

TAXI = EnvProfile(
    name="Taxi",
    description="pick a passenger up and drop them at their destination on a 5x5 grid",
    ids=("Taxi-v4", "Taxi-v3"),
    entry_points=("gymnasium.envs.toy_text.taxi:TaxiEnv",),
    action_names=("south", "north", "east", "west", "pickup", "drop off"),
    policy_map="components",
    state_components=(5, 5, 5, 4),
    component_names=("taxi row", "taxi column", "passenger", "destination"),
    rows_down=True,
    model="transition_table",
    twin=load_taxi_twin,
)

CLIFFWALKING = EnvProfile(
    name="CliffWalking",
    description="walk along a cliff to the goal (Sutton & Barto's Example 6.6)",
    ids=("CliffWalking-v1", "CliffWalking-v0"),
    entry_points=("gymnasium.envs.toy_text.cliffwalking:CliffWalkingEnv",),
    action_names=("up", "right", "down", "left"),
    policy_map="grid",
    grid=cliffwalking_grid,
    model="transition_table",
    twin=load_table_twin,
)

PROFILES = (FROZENLAKE, TAXI, CLIFFWALKING)
"""the family's profiles"""
WORLDS: tuple[World, ...] = ()
"""the worlds it registers (none: Gymnasium registers them)"""
