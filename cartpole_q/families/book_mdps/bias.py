"""Sutton & Barto's Example 6.7 (Figure 6.5): the small MDP that shows maximization bias.

The episode starts in A. From A, "right" ends the episode with reward 0 and "left" goes to
B with reward 0; from B every action ends the episode with a reward drawn from a normal
distribution of mean -0.1 and variance 1. Going left is worse in expectation (-0.1), but
Q-learning's maximum over B's noisy estimates makes it look better for a long time.

**States.** 0 = A (the start), 1 = B, 2 = the end (absorbing, as FrozenLake's goal).

**Actions.** Gymnasium gives every state the same actions, ``Discrete(b_actions)``. In B
they are the book's "many" actions (``b_actions``, 10 by default as in Shangtong Zhang's
script). In A, the first half of them go left and the second half right, so a uniformly
random action goes left with probability 1/2, as with the book's two actions: an
epsilon-greedy agent that has learnt to go right still goes left epsilon / 2 of the time
(5% at epsilon 0.1, the book's "optimal" line). Each of A's actions has its own Q-value.

**Draws.** ``reset`` draws as every :class:`~cartpole_q.families.tables.world.TableWorld`; a step
from A draws nothing; a step from B draws its reward, one ``np_random.normal(-0.1, 1.0)``.
``info["left_from_a"]`` says whether the step went left from A (so a study can count the
episodes that did: the "% left actions from A" of Figure 6.5).

**Model.** A normal reward cannot be tabulated: ``P`` gives B's actions their mean reward,
-0.1. The expected return of every policy, and so the exact optimum (0: go right), is
exact all the same.
"""

from __future__ import annotations

from typing import Any

from cartpole_q.families.tables.world import Table, TableWorld

A, B, END = 0, 1, 2
REWARD_MEAN = -0.1
"""the mean of the reward of B's actions (the book: -0.1)"""
REWARD_STD = 1.0
"""its standard deviation (the book: variance 1.0)"""


class MaximizationBiasEnv(TableWorld):
    """Example 6.7: from A, left to B (then a noisy reward of mean -0.1) or right to the end.

    Args:
        b_actions: the number of actions (B's "many" actions); even, so that A's split
            evenly between left and right.
    """

    plays_its_table = False  # P holds B's mean reward; a step draws a normal one

    def __init__(self, b_actions: int = 10) -> None:
        if isinstance(b_actions, bool) or not isinstance(b_actions, int):
            raise ValueError(f"`b_actions` must be an even whole number, got {b_actions!r}")
        if b_actions < 2 or b_actions % 2:
            raise ValueError(
                f"`b_actions` must be even and at least 2 (half of A's actions go left, "
                f"half right), got {b_actions}"
            )
        super().__init__(n_states=3, n_actions=b_actions, start=A)
        self.b_actions = b_actions
        self.P = self._table()

    def goes_left(self, action: int) -> bool:
        """Whether ``action`` taken in A goes left (to B)."""
        return action < self.b_actions // 2

    def _table(self) -> Table:
        """``P``, with B's mean reward in place of its normal draw."""
        table: Table = {A: {}, B: {}, END: {}}
        for action in range(self.b_actions):
            table[A][action] = (
                [(1.0, B, 0.0, False)] if self.goes_left(action) else [(1.0, END, 0.0, True)]
            )
            table[B][action] = [(1.0, END, REWARD_MEAN, True)]
            table[END][action] = [(1.0, END, 0.0, True)]
        return table

    def step(self, action: int) -> tuple[int, float, bool, bool, dict[str, Any]]:
        """Take ``action``: B's reward drawn from ``np_random``, the rest as ``P`` says."""
        action = int(action)
        left = self.s == A and self.goes_left(action)
        if self.s == B:
            reward = float(self.np_random.normal(REWARD_MEAN, REWARD_STD))
            self.s = END
            return END, reward, True, False, {"left_from_a": False}
        ((_, following, reward, terminated),) = self.P[self.s][action]
        self.s = following
        return following, reward, terminated, False, {"left_from_a": left}
