"""The worlds of Sutton & Barto's chapters 3-4, the worlds of dynamic programming.

``cartpole-q dp`` solves them: the gridworlds of Examples 3.5 and 4.1
(:mod:`~cartpole_q.families.planning.grids`), Jack's car rental
(:mod:`~cartpole_q.families.planning.car_rental`) and the gambler
(:mod:`~cartpole_q.families.planning.gambler`).

The two gridworlds draw their policy maps as grids (the 4x4 gridworld's terminal corners
as ends, ``E``), Jack's car rental over the cars at its two locations; each has a
transition table (the car rental: a ``dense_model()``) for ``cartpole-q dp``.
"""

from __future__ import annotations

from typing import Any

from cartpole_q.families.base import NAMESPACE, EnvProfile, GridCells, World

_GRIDS = "cartpole_q.families.planning.grids"
_GAMBLER = "cartpole_q.families.planning.gambler"
_CAR_RENTAL = "cartpole_q.families.planning.car_rental"
PLANNING_TIME_LIMIT = 1_000
"""steps before an episode of the gridworlds or the car rental is truncated (Example 3.5's
gridworld and the car rental never end; the 4 x 4 gridworld's random episodes take some
twenty steps on average)"""
GAMBLER_TIME_LIMIT = 10_000
"""steps before a gambler's episode is truncated (with stakes of 1 an episode can be long)"""


def planning_grid(world: Any) -> GridCells:
    """A gridworld of chapters 3-4: its terminal cells ``E``, every other cell free."""
    cells = tuple(
        "E" if (row, column) in world.terminals else "F"
        for row in range(world.rows)
        for column in range(world.columns)
    )
    return world.rows, world.columns, cells, tuple(world.moves)


GRIDWORLDS = EnvProfile(
    name="PlanningGridworld",
    description="the gridworld of Example 3.5 (A -> A' +10, B -> B' +5) and the 4x4 "
    "gridworld of Example 4.1 (Sutton & Barto's Figures 3.2, 3.5, 4.1)",
    ids=("cartpole_q/Gridworld-v0", "cartpole_q/SmallGridworld-v0"),
    entry_points=(f"{_GRIDS}:GridworldEnv", f"{_GRIDS}:SmallGridworldEnv"),
    action_names=("up", "down", "left", "right"),
    policy_map="grid",
    grid=planning_grid,
    model="transition_table",
)

GAMBLER = EnvProfile(
    name="Gambler",
    description="stake on coin flips until the capital is 100 or 0 (Sutton & Barto's "
    "Example 4.3, Figure 4.3)",
    ids=("cartpole_q/Gambler-v0",),
    entry_points=(f"{_GAMBLER}:GamblerEnv",),
    model="transition_table",
)

CAR_RENTAL = EnvProfile(
    name="CarRental",
    description="move cars between two rental locations overnight (Sutton & Barto's "
    "Example 4.2, Figure 4.2)",
    ids=("cartpole_q/CarRental-v0",),
    entry_points=(f"{_CAR_RENTAL}:CarRentalEnv",),
    action_names=tuple(f"move {move}" for move in range(-5, 6)),
    policy_map="components",
    state_components=(21, 21),
    component_names=("cars at the first location", "cars at the second location"),
)

PROFILES = (GRIDWORLDS, GAMBLER, CAR_RENTAL)
"""the family's profiles"""
WORLDS: tuple[World, ...] = (
    World(f"{NAMESPACE}/Gridworld-v0", f"{_GRIDS}:GridworldEnv", PLANNING_TIME_LIMIT),
    World(f"{NAMESPACE}/SmallGridworld-v0", f"{_GRIDS}:SmallGridworldEnv", PLANNING_TIME_LIMIT),
    World(f"{NAMESPACE}/CarRental-v0", f"{_CAR_RENTAL}:CarRentalEnv", PLANNING_TIME_LIMIT),
    World(f"{NAMESPACE}/Gambler-v0", f"{_GAMBLER}:GamblerEnv", GAMBLER_TIME_LIMIT),
)
"""the worlds of dynamic programming, their models exact"""
