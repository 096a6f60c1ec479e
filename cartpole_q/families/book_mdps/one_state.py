"""Sutton & Barto's one-state MDP (Example 5.5, Figure 5.4): infinite variance of ordinary IS.

One non-terminal state ``s`` (0) and its end (1). ``left`` (0) comes back to ``s`` with
probability 0.9, reward 0, or ends with probability 0.1, reward +1; ``right`` (1) ends at
once, reward 0. The target policy always goes left (``agent.policy: left``), worth
``v(s) = 1`` undiscounted; a uniform behaviour policy's episodes estimate it by importance
sampling, and ordinary importance sampling's estimates never settle (their variance is
infinite).
"""

from __future__ import annotations

from cartpole_q.families.tables.world import Table, TableWorld

LEFT, RIGHT = 0, 1
"""the actions"""
STAY = 0.9
"""the probability that left comes back to s"""


class OneStateEnv(TableWorld):
    """Example 5.5's MDP: one state, left (back with 0.9, else +1 and the end) or right (the end)."""

    def __init__(self) -> None:
        super().__init__(n_states=2, n_actions=2, start=0)
        end = 1
        self.P: Table = {
            0: {
                LEFT: [(STAY, 0, 0.0, False), (1.0 - STAY, end, 1.0, True)],
                RIGHT: [(1.0, end, 0.0, True)],
            },
            end: {LEFT: [(1.0, end, 0.0, True)], RIGHT: [(1.0, end, 0.0, True)]},
        }
