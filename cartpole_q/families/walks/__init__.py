"""The book's random walks: 5 and 19 states (Examples 6.2, 7.1) and 1000 states (9.1).

The worlds (:mod:`~cartpole_q.families.walks.worlds`): 5 states from a 0 end, 19 from a -1
end, and the walk of 1000 states that jumps up to 100 states either way.

Each has a transition table, so the true values are computed exactly; the 5- and 19-state
walks play on the compiled twin of any table world, the 1000-state walk on the one that
observes groups of states (:mod:`cartpole_q.families.tables`). A random walk lasts 100 steps
on average and more than 1,000 about once in 170,000 episodes, so :data:`WALK_TIME_LIMIT`
cuts practically none; the 1000-state walk takes 83 steps on average and more than 1,000
about once in 2.3 million episodes, more than 2,000 about once in 7 * 10^12 (Figure 9.1
plays 100,000 episodes: :data:`JUMPING_WALK_TIME_LIMIT`).
"""

from __future__ import annotations

from types import MappingProxyType
from typing import Any

from cartpole_q.families.base import NAMESPACE, EnvProfile, GridCells, World
from cartpole_q.families.tables import load_aggregated_twin
from cartpole_q.families.tables import load_twin as load_table_twin

_WALKS = "cartpole_q.families.walks.worlds"
WALK_TIME_LIMIT = 1_000
"""steps before a random walk's episode is truncated"""
JUMPING_WALK_TIME_LIMIT = 10_000
"""steps before an episode of the 1000-state walk is truncated"""


def random_walk_grid(world: Any) -> GridCells:
    """The walk as one row: its left end (``E``), the start, its right end (``G``, +1)."""
    states = int(world.observation_space.n)
    start = int(world.initial_state_distrib.argmax())
    cells = ["E" if state == 0 else "G" if state == states - 1 else "F" for state in range(states)]
    cells[start] = "S"
    return 1, states, tuple(cells), ((0, -1), (0, 1))


RANDOM_WALK = EnvProfile(
    name="RandomWalk",
    description="a walk between two ends, +1 on the right: 5 states from a 0 end (Sutton & "
    "Barto's Example 6.2), 19 from a -1 end (Example 7.1)",
    ids=("cartpole_q/RandomWalk5-v0", "cartpole_q/RandomWalk-v0"),
    entry_points=(f"{_WALKS}:RandomWalkEnv",),
    action_names=("left", "right"),
    policy_map="grid",
    grid=random_walk_grid,
    model="transition_table",
    twin=load_table_twin,
)

RANDOM_WALK_1000 = EnvProfile(
    name="RandomWalk1000",
    description="Example 9.1's walk of 1000 states, jumps of up to 100 either way, -1 and +1 "
    "ends; env.kwargs.groups aggregates the states (Figures 9.1, 9.2)",
    ids=("cartpole_q/RandomWalk1000-v0",),
    entry_points=(f"{_WALKS}:JumpingWalkEnv",),
    action_names=("left", "right"),
    model="transition_table",
    twin=load_aggregated_twin,
)

PROFILES = (RANDOM_WALK, RANDOM_WALK_1000)
"""the family's profiles"""
WORLDS: tuple[World, ...] = (
    World(
        f"{NAMESPACE}/RandomWalk5-v0",
        f"{_WALKS}:RandomWalkEnv",
        WALK_TIME_LIMIT,
        MappingProxyType({"states": 5, "left_reward": 0.0}),
    ),
    World(f"{NAMESPACE}/RandomWalk-v0", f"{_WALKS}:RandomWalkEnv", WALK_TIME_LIMIT),
    World(f"{NAMESPACE}/RandomWalk1000-v0", f"{_WALKS}:JumpingWalkEnv", JUMPING_WALK_TIME_LIMIT),
)
"""the worlds it registers"""
