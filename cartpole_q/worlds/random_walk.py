"""Sutton & Barto's random walks: 5 states (Example 6.2) and 19 states (Example 7.1).

A walk's states ``1 .. states`` are numbered left to right; ``0`` and ``states + 1`` are its
two ends (absorbing, as FrozenLake's goal). Episodes start in the middle. Stepping into
the right end earns +1, into the left end ``left_reward``, any other step 0:

- ``cartpole_q/RandomWalk5-v0``: Example 6.2's walk, states A-E (1-5) between a 0 end and a
  +1 end, started in C; the random policy's values are 1/6, 2/6, ..., 5/6 (undiscounted).
- ``cartpole_q/RandomWalk-v0``: Example 7.1's 19 states between a -1 end and a +1 end
  (Figure 7.2, chapter 12), started in state 10; true values -0.9, -0.8, ..., 0.9.

The book's walks have no actions: a step goes left or right with equal probability. Here
the walk has two actions, left (0) and right (1), so that it can be trained as well as
evaluated: the prediction algorithms (``agent.policy: random``) learn the book's ``v(s)``;
a uniformly random policy is the book's walk. The optimal policy goes right (+1).
"""

from __future__ import annotations

from cartpole_q.worlds.table import Table, TableWorld

WALK_STATES = 19
"""the non-terminal states of Example 7.1's walk"""
MOVES = (-1, 1)
"""per action: the step along the walk (left, right)"""


class RandomWalkEnv(TableWorld):
    """A walk of ``states`` states between a ``left_reward`` end and a +1 end, started in the middle.

    Args:
        states: the non-terminal states (an odd number, so that there is a middle).
        left_reward: the reward of stepping into the left end.
    """

    def __init__(self, states: int = WALK_STATES, left_reward: float = -1.0) -> None:
        if states < 1 or states % 2 == 0:
            raise ValueError(f"a random walk needs an odd number of states, got {states}")
        super().__init__(n_states=states + 2, n_actions=len(MOVES), start=(states + 1) // 2)
        self.states = states
        self.left_reward = float(left_reward)
        self.P = self._table()

    def _table(self) -> Table:
        """``P``: a step moves one state; the ends are absorbing."""
        left_end, right_end = 0, self.states + 1
        rewards = {left_end: self.left_reward, right_end: 1.0}
        table: Table = {}
        for state in range(self.states + 2):
            table[state] = {}
            for action, move in enumerate(MOVES):
                if state in (left_end, right_end):
                    table[state][action] = [(1.0, state, 0.0, True)]
                    continue
                following = state + move
                ended = following in (left_end, right_end)
                table[state][action] = [(1.0, following, rewards.get(following, 0.0), ended)]
        return table
