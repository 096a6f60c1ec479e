"""Baird's counterexample (Sutton & Barto Example 11.1, Figures 11.2, 11.5, 11.6).

Seven states, the upper six (``0 .. 5``) and the lower one (``6``), and two actions:
**dashed** (0) goes to one of the six upper states, each with probability 1/6; **solid** (1)
goes to the lower state. Every reward is 0 and nothing ever ends: a continuing world, run
for a number of steps, not episodes. The start is one of the seven states, uniformly.

The book's behaviour policy takes dashed with probability 6/7 and solid with 1/7 (so the
next state is uniform over the seven, and so is the behaviour's stationary distribution);
its target policy always takes solid. Its linear features (:attr:`BairdEnv.features_of_state`)
give the upper state ``i`` the value ``2 w_i + w_8`` and the lower one ``w_7 + 2 w_8`` (the
book's 1-based weights; here columns ``0 .. 7``): eight weights for seven states, yet
semi-gradient off-policy TD and DP drive them to infinity from ``w = (1, 1, 1, 1, 1, 1, 10, 1)``.
"""

from __future__ import annotations

import numpy as np

from cartpole_q.families.tables.world import Table, TableWorld

UPPER_STATES = 6
"""the upper states ``0 .. 5``; the lower state is ``6``"""
LOWER = UPPER_STATES
DASHED, SOLID = 0, 1
"""the actions"""
WEIGHTS = 8
"""the features' length"""


def baird_features() -> np.ndarray:
    """float64 ``(7, 8)``: upper state ``i`` is ``2 e_i + e_7``, the lower ``e_6 + 2 e_7``.

    >>> baird_features()[[0, 6]].tolist()
    [[2.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0], [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 2.0]]
    """
    features = np.zeros((UPPER_STATES + 1, WEIGHTS))
    for state in range(UPPER_STATES):
        features[state, state] = 2.0
        features[state, WEIGHTS - 1] = 1.0
    features[LOWER, WEIGHTS - 2] = 1.0
    features[LOWER, WEIGHTS - 1] = 2.0
    return features


class BairdEnv(TableWorld):
    """Example 11.1: dashed to a uniform upper state, solid to the lower one; reward 0, no end.

    ``P[s][dashed]`` lists the six upper states in order, each ``1.0 / 6.0``; ``P[s][solid]``
    is ``[(1.0, 6, 0.0, False)]``. The start distribution is ``1.0 / 7.0`` per state.

    >>> world = BairdEnv()
    >>> world.P[3][1], len(world.P[3][0]), world.P[3][0][0]
    ([(1.0, 6, 0.0, False)], 6, (0.16666666666666666, 0, 0.0, False))
    """

    def __init__(self) -> None:
        super().__init__(n_states=UPPER_STATES + 1, n_actions=2, start=0)
        self.initial_state_distrib = np.full(UPPER_STATES + 1, 1.0 / (UPPER_STATES + 1))
        upper = [(1.0 / UPPER_STATES, state, 0.0, False) for state in range(UPPER_STATES)]
        self.P: Table = {
            state: {DASHED: list(upper), SOLID: [(1.0, LOWER, 0.0, False)]}
            for state in range(UPPER_STATES + 1)
        }
        self.features_of_state = baird_features()
