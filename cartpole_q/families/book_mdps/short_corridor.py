"""The short corridor with switched actions (Sutton & Barto Example 13.1, Figures 13.1, 13.2).

Three states and the goal: from the start (0) left stays and right goes to state 1; in
state 1 the actions are **switched** (right goes back to 0, left on to 2); from state 2 left
goes back to 1 and right reaches the goal (3), which ends the episode. Every step gives
-1. The policy's features are the same in every state (:attr:`ShortCorridorEnv.features_of_action`:
``x(s, right) = (1, 0)``, ``x(s, left) = (0, 1)``), so a policy cannot tell the states
apart: the best one goes right with probability ``2 - √2 ≈ 0.59`` (value of the start
about -11.6), where an ε-greedy choice between the two deterministic policies is far
worse. No time limit (the engines cut an episode at 10,000 steps).

>>> world = ShortCorridorEnv()
>>> world.P[1][RIGHT], world.P[1][LEFT], world.P[2][RIGHT]
([(1.0, 0, -1.0, False)], [(1.0, 2, -1.0, False)], [(1.0, 3, -1.0, True)])
"""

from __future__ import annotations

import numpy as np

from cartpole_q.families.tables.world import Table, TableWorld

LEFT, RIGHT = 0, 1
"""the actions"""
GOAL = 3
SWITCHED = 1
"""the state whose actions are switched"""


def corridor_action_features() -> np.ndarray:
    """float64 ``(4, 2, 2)``: ``x(s, right) = (1, 0)`` and ``x(s, left) = (0, 1)`` in every state.

    >>> corridor_action_features()[0].tolist()
    [[0.0, 1.0], [1.0, 0.0]]
    """
    features = np.zeros((GOAL + 1, 2, 2))
    features[:, RIGHT, 0] = 1.0
    features[:, LEFT, 1] = 1.0
    return features


class ShortCorridorEnv(TableWorld):
    """Example 13.1: a corridor of three states whose middle one switches left and right.

    ``P[s][a]`` is one certain outcome, reward ``-1.0``; the goal (3) is absorbing, as
    FrozenLake's goal, with reward 0.
    """

    def __init__(self) -> None:
        super().__init__(n_states=GOAL + 1, n_actions=2, start=0)
        moves = {0: (0, 1), 1: (2, 0), 2: (1, GOAL)}  # state: (after left, after right)
        table: Table = {}
        for state, (left, right) in moves.items():
            table[state] = {
                LEFT: [(1.0, left, -1.0, left == GOAL)],
                RIGHT: [(1.0, right, -1.0, right == GOAL)],
            }
        table[GOAL] = {action: [(1.0, GOAL, 0.0, True)] for action in (LEFT, RIGHT)}
        self.P = table
        self.features_of_action = corridor_action_features()
