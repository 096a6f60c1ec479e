"""Driving home (Sutton & Barto Example 6.1, Figure 6.1): one evening's drive as a chain.

The example's table, one row per situation: the minutes elapsed when it is reached and
the predicted minutes still to go then.

======================  =======  =====================
situation               elapsed  predicted time to go
======================  =======  =====================
leaving office          0        30
reach car               5        35
exiting highway         20       15
2ndary road             30       10
home street             40       3
arrive home             43       0
======================  =======  =====================

The world is that drive: states 0-5 in this order, one action (``drive``), each step to
the next situation with the minutes it took as its reward (5, 15, 10, 10, 3), undiscounted;
arriving home (5) ends the episode. So a state's return is the time still to go, and
:data:`PREDICTIONS` started as ``V`` (``agent.initial_values``) are the example's
predictions: one episode of constant-alpha Monte Carlo with alpha 1 moves each to the actual time
to go (43, 38, 23, 13, 3), one of TD(0) to the reward plus the next prediction (40, 30, 20,
13, 3): the changes Figure 6.1 draws, there as predicted total times (elapsed + to go).

>>> world = DrivingHomeEnv()
>>> [world.P[state][DRIVE][0][1:] for state in (0, 4)]
[(1, 5.0, False), (5, 3.0, True)]
>>> world.labels[2]
'exiting highway'
"""

from __future__ import annotations

from cartpole_q.families.tables.world import Table, TableWorld

SITUATIONS = (
    "leaving office", "reach car", "exiting highway", "2ndary road", "home street",
    "arrive home",
)  # fmt: skip
"""the example's situations, the world's states 0-5 in order"""
ELAPSED = (0.0, 5.0, 20.0, 30.0, 40.0, 43.0)
"""minutes elapsed when each situation is reached"""
PREDICTIONS = (30.0, 35.0, 15.0, 10.0, 3.0, 0.0)
"""the example's predicted minutes to go in each situation (home: 0)"""
DRIVE = 0
"""the one action"""
HOME = len(SITUATIONS) - 1


class DrivingHomeEnv(TableWorld):
    """Example 6.1's drive: six situations in a row, each step's reward the minutes it took.

    ``P[s][drive]`` is one certain outcome; home (5) is absorbing with reward 0, as
    FrozenLake's goal.
    """

    def __init__(self) -> None:
        super().__init__(n_states=len(SITUATIONS), n_actions=1, start=0)
        table: Table = {}
        for state in range(HOME):
            minutes = ELAPSED[state + 1] - ELAPSED[state]
            table[state] = {DRIVE: [(1.0, state + 1, minutes, state + 1 == HOME)]}
        table[HOME] = {DRIVE: [(1.0, HOME, 0.0, True)]}
        self.P = table
        self.labels = dict(enumerate(SITUATIONS))
