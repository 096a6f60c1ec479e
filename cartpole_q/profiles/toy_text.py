"""Gymnasium's tabular worlds: FrozenLake, Taxi, CliffWalking and Blackjack.

Each has an exact model, so ``cartpole-q optimum`` and ``eval`` compute the best return:
FrozenLake, Taxi and CliffWalking from their transition table (``env.unwrapped.P``),
Blackjack from its rules. Each has a compiled twin: FrozenLake and CliffWalking the one of
any world that moves by its transition table, Taxi that one with its fickle passenger,
Blackjack its own.
"""

from __future__ import annotations

from types import MappingProxyType
from typing import Any

from cartpole_q.profiles.base import EnvProfile, GridCells


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


FROZENLAKE = EnvProfile(
    name="FrozenLake",
    description="cross a frozen lake to the goal without falling in a hole (slippery or not)",
    ids=("FrozenLake-v1", "FrozenLake8x8-v1"),
    entry_points=("gymnasium.envs.toy_text.frozen_lake:FrozenLakeEnv",),
    action_names=("left", "down", "right", "up"),
    policy_map="grid",
    grid=frozenlake_grid,
    model="transition_table",
    twin="cartpole_q.envs.twins.transition_table",
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
    twin="cartpole_q.envs.twins.taxi",
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
    twin="cartpole_q.envs.twins.transition_table",
)


def stick_on_20(state_shape: tuple[int, ...]) -> list[int]:
    """Sutton & Barto's Example 5.1 policy: stick (0) on a player sum of 20 or 21, else hit (1).

    >>> actions = stick_on_20((32, 11, 2))
    >>> actions[(19 * 11 + 5) * 2 + 1], actions[(20 * 11 + 5) * 2 + 0], len(actions)
    (1, 0, 704)
    """
    per_sum = state_shape[1] * state_shape[2]
    return [0 if row // per_sum >= 20 else 1 for row in range(state_shape[0] * per_sum)]


BLACKJACK = EnvProfile(
    name="Blackjack",
    description="hit or stick against the dealer (Sutton & Barto's Example 5.1)",
    ids=("Blackjack-v1",),
    entry_points=("gymnasium.envs.toy_text.blackjack:BlackjackEnv",),
    observation_names=("player sum", "dealer card", "usable ace"),
    action_names=("stick", "hit"),
    policy_map="blackjack",
    model="blackjack",
    twin="cartpole_q.envs.twins.blackjack",
    policies=MappingProxyType({"stick_20": stick_on_20}),
)

BLACKJACK_DEALT = EnvProfile(
    name="BlackjackDealt",
    description="Blackjack dealt one hand every episode, 13 with a usable ace against a 2 "
    "(Sutton & Barto's Example 5.4)",
    ids=("cartpole_q/BlackjackDealt-v0",),
    entry_points=("cartpole_q.worlds.blackjack_dealt:BlackjackDealtEnv",),
    observation_names=("player sum", "dealer card", "usable ace"),
    action_names=("stick", "hit"),
    policy_map="blackjack",
    model="blackjack",
    policies=MappingProxyType({"stick_20": stick_on_20}),
)

BLACKJACK_ES = EnvProfile(
    name="BlackjackES",
    description="Blackjack dealt a uniformly random one of its 200 states every episode "
    "(exploring starts, Sutton & Barto's Example 5.3)",
    ids=("cartpole_q/BlackjackES-v0",),
    entry_points=("cartpole_q.worlds.blackjack_dealt:BlackjackExploringStartsEnv",),
    observation_names=("player sum", "dealer card", "usable ace"),
    action_names=("stick", "hit"),
    policy_map="blackjack",
    model="blackjack",
    twin="cartpole_q.envs.twins.blackjack_es",
    policies=MappingProxyType({"stick_20": stick_on_20}),
)
