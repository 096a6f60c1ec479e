"""The worlds of Sutton & Barto's chapters 3-4 (:data:`cartpole_q.worlds.PLANNING_WORLDS`).

The two gridworlds draw their policy maps as grids (the 4x4 gridworld's terminal corners
as ends, ``E``), Jack's car rental over the cars at its two locations; each has a
transition table (the car rental: a ``dense_model()``) for ``cartpole-q dp``.
"""

from __future__ import annotations

from typing import Any

from cartpole_q.profiles.base import EnvProfile, GridCells

_GRIDS = "cartpole_q.worlds.planning_grids"


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
    entry_points=("cartpole_q.worlds.gambler:GamblerEnv",),
    model="transition_table",
)

CAR_RENTAL = EnvProfile(
    name="CarRental",
    description="move cars between two rental locations overnight (Sutton & Barto's "
    "Example 4.2, Figure 4.2)",
    ids=("cartpole_q/CarRental-v0",),
    entry_points=("cartpole_q.worlds.car_rental:CarRentalEnv",),
    action_names=tuple(f"move {move}" for move in range(-5, 6)),
    policy_map="components",
    state_components=(21, 21),
    component_names=("cars at the first location", "cars at the second location"),
)
