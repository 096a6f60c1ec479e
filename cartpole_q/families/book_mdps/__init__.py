"""The book's small MDPs: the one-state MDP (5.5), driving home (6.1), the maximization bias (6.7), Baird's (11.1), access control (10.2), the short corridor (13.1).

Their worlds are :mod:`~cartpole_q.families.book_mdps.one_state`,
:mod:`~cartpole_q.families.book_mdps.bias` and :mod:`~cartpole_q.families.book_mdps.baird`
(a continuing world: nothing ends, and it has no time limit; its linear features are its
own, ``features_of_state``, for the ``linear`` studies).

Both have a transition table, so ``cartpole-q optimum`` and ``eval`` compute the best return
exactly. The one-state MDP plays on the compiled twin of any table world; the
maximization-bias world draws a normal reward, which no twin reproduces, so it plays on the
gymnasium engine, and needs no time limit (every episode ends within two steps).
"""

from __future__ import annotations

from types import MappingProxyType

from cartpole_q.families.base import NAMESPACE, EnvProfile, World
from cartpole_q.families.tables import load_twin as load_table_twin

_BAIRD = "cartpole_q.families.book_mdps.baird"
_BIAS = "cartpole_q.families.book_mdps.bias"
_ONE_STATE = "cartpole_q.families.book_mdps.one_state"
_CORRIDOR = "cartpole_q.families.book_mdps.short_corridor"
_ACCESS = "cartpole_q.families.book_mdps.access_control"
_RACETRACK = "cartpole_q.families.book_mdps.racetrack"
_DRIVING = "cartpole_q.families.book_mdps.driving_home"
ONE_STATE_TIME_LIMIT = 1_000
"""steps before an episode of the one-state MDP is truncated (left comes back with
probability 0.9: ten steps on average)"""
RACETRACK_TIME_LIMIT = 100_000
"""steps before a racetrack episode is truncated: far beyond what an exploring behaviour
needs, a bound on a greedy policy that crashes for ever"""


MAXIMIZATION_BIAS = EnvProfile(
    name="MaximizationBias",
    description="left from A to B's noisy rewards (mean -0.1) or right to 0 "
    "(Sutton & Barto's Example 6.7)",
    ids=("cartpole_q/MaximizationBias-v0",),
    entry_points=(f"{_BIAS}:MaximizationBiasEnv",),
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
    entry_points=(f"{_ONE_STATE}:OneStateEnv",),
    action_names=("left", "right"),
    model="transition_table",
    twin=load_table_twin,
    policies=MappingProxyType({"left": always_left}),
)

BAIRD = EnvProfile(
    name="Baird",
    description="Baird's counterexample: seven states, dashed to an upper state, solid to the "
    "lower one, reward 0, no end; eight linear features (Sutton & Barto's Example 11.1)",
    ids=("cartpole_q/Baird-v0",),
    entry_points=(f"{_BAIRD}:BairdEnv",),
    action_names=("dashed", "solid"),
    model="transition_table",
    twin=load_table_twin,
)

SHORT_CORRIDOR = EnvProfile(
    name="ShortCorridor",
    description="the short corridor with switched actions: three states that look alike, "
    "the middle one switching left and right, -1 per step (Sutton & Barto's Example 13.1)",
    ids=("cartpole_q/ShortCorridor-v0",),
    entry_points=(f"{_CORRIDOR}:ShortCorridorEnv",),
    action_names=("left", "right"),
    model="transition_table",
    twin=load_table_twin,
)

ACCESS_CONTROL = EnvProfile(
    name="AccessControl",
    description="the access-control queuing task: accept or reject the customer of priority "
    "1, 2, 4 or 8 at the head of the queue for one of 10 servers, each busy one freeing with "
    "probability 0.06 a step; continuing, average reward (Sutton & Barto's Example 10.2)",
    ids=("cartpole_q/AccessControl-v0",),
    entry_points=(f"{_ACCESS}:AccessControlEnv",),
    action_names=("reject", "accept"),
    model="transition_table",
    twin=load_table_twin,
    policy_map="components",
    state_components=(4, 11),
    component_names=("priority", "free servers"),
    component_values=(("1", "2", "4", "8"), tuple(str(free) for free in range(11))),
    average_reward=True,
)

RACETRACK = EnvProfile(
    name="Racetrack",
    description="the racetrack: a car with a velocity of 0-4 cells a step up and right, nine "
    "actions of -1, 0, +1 to each component (none, with probability 0.1), -1 a step, back "
    "to the start line after a crash (Sutton & Barto's Exercise 5.12, Figure 5.5)",
    ids=("cartpole_q/Racetrack-v0",),
    entry_points=(f"{_RACETRACK}:RacetrackEnv",),
    action_names=tuple(
        f"up {up:+d}, right {right:+d}" for up in (-1, 0, 1) for right in (-1, 0, 1)
    ),
    model="transition_table",
    twin=load_table_twin,
    policy_map="racetrack",
)

DRIVING_HOME = EnvProfile(
    name="DrivingHome",
    description="driving home: six situations from the office to home in a row, each step's "
    "reward the minutes it took, undiscounted (Sutton & Barto's Example 6.1)",
    ids=("cartpole_q/DrivingHome-v0",),
    entry_points=(f"{_DRIVING}:DrivingHomeEnv",),
    action_names=("drive",),
    model="transition_table",
    twin=load_table_twin,
)

PROFILES = (
    MAXIMIZATION_BIAS, ONE_STATE, BAIRD, SHORT_CORRIDOR, ACCESS_CONTROL, RACETRACK, DRIVING_HOME,
)  # fmt: skip
"""the family's profiles"""
WORLDS: tuple[World, ...] = (
    World(f"{NAMESPACE}/MaximizationBias-v0", f"{_BIAS}:MaximizationBiasEnv", None),
    World(f"{NAMESPACE}/OneState-v0", f"{_ONE_STATE}:OneStateEnv", ONE_STATE_TIME_LIMIT),
    World(f"{NAMESPACE}/Baird-v0", f"{_BAIRD}:BairdEnv", None),
    World(f"{NAMESPACE}/ShortCorridor-v0", f"{_CORRIDOR}:ShortCorridorEnv", None),
    World(f"{NAMESPACE}/AccessControl-v0", f"{_ACCESS}:AccessControlEnv", None),
    World(f"{NAMESPACE}/Racetrack-v0", f"{_RACETRACK}:RacetrackEnv", RACETRACK_TIME_LIMIT),
    World(f"{NAMESPACE}/DrivingHome-v0", f"{_DRIVING}:DrivingHomeEnv", None),
)
"""the worlds it registers"""
