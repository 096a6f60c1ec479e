"""Sutton & Barto's 19-state random walk (Example 7.1, Figure 7.2).

States 1-19 are the walk, numbered left to right; 0 and 20 are its two ends (absorbing, as
FrozenLake's goal). Episodes start in the middle, state 10. Stepping into the left end
earns -1, into the right end +1, any other step 0.

The book's walk has no actions: Figure 7.2 is n-step TD *prediction* of the random policy's
state values (true values -0.9, -0.8, ..., 0.9), which this tool, a control tool, does not
do. Here the walk has two actions, left (0) and right (1), so it can be trained; a uniformly
random policy is the book's walk (``agent.epsilon: 1``), and with Expected SARSA at epsilon 1
the learnt ``(Q(s, left) + Q(s, right)) / 2`` estimates the book's ``v(s)`` (undiscounted).
The optimal policy goes right (+1).
"""

from __future__ import annotations

from cartpole_q.worlds.table import Table, TableWorld

WALK_STATES = 19
"""the non-terminal states (Example 7.1: 19)"""
LEFT_END, START, RIGHT_END = 0, (WALK_STATES + 1) // 2, WALK_STATES + 1
MOVES = (-1, 1)
"""per action: the step along the walk (left, right)"""


class RandomWalkEnv(TableWorld):
    """Example 7.1: a walk of 19 states between a -1 end and a +1 end, started in the middle."""

    def __init__(self) -> None:
        super().__init__(n_states=WALK_STATES + 2, n_actions=len(MOVES), start=START)
        self.P = self._table()

    def _table(self) -> Table:
        """``P``: a step moves one state; the ends are absorbing."""
        table: Table = {}
        for state in range(WALK_STATES + 2):
            table[state] = {}
            for action, move in enumerate(MOVES):
                if state in (LEFT_END, RIGHT_END):
                    table[state][action] = [(1.0, state, 0.0, True)]
                    continue
                following = state + move
                reward = {LEFT_END: -1.0, RIGHT_END: 1.0}.get(following, 0.0)
                ended = following in (LEFT_END, RIGHT_END)
                table[state][action] = [(1.0, following, reward, ended)]
        return table
