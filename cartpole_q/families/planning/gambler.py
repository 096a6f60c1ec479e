"""Sutton & Barto's gambler's problem (Example 4.3, Figure 4.3).

A gambler with capital ``s`` (1 to ``goal - 1``) stakes some of it on a coin flip: heads
(probability ``p_h``) wins the stake, tails loses it. The episode ends when the capital
reaches ``goal`` (reward +1, the only reward) or 0. Undiscounted.

**States.** The capital, ``0 .. goal`` (0 and ``goal`` absorbing, as FrozenLake's holes and
goal). An episode starts with ``start`` (default ``goal // 2``).

**Actions.** Action ``a`` is a stake of ``a`` (``Discrete(goal // 2 + 1)``). The book's
stakes in ``s`` are ``0 .. min(s, goal - s)``; here a stake outside ``1 .. min(s, goal - s)``
plays the nearest of them, and :meth:`GamblerEnv.allowed_actions` leaves it out of dynamic
programming. That leaves out the book's stake 0, which only waits: undiscounted, its value
is ``v(s)`` itself, which no sweep of value iteration from zero exceeds (the values only
grow), so it changes no value, but it would tie with the best stake everywhere at the
optimum; Zhang's script leaves it out of its policy as well.
"""

from __future__ import annotations

import numpy as np

from cartpole_q.families.tables.world import Table, TableWorld

GOAL = 100
"""the book's goal"""
HEADS = 0.4
"""the book's probability of heads (Figure 4.3)"""


class GamblerEnv(TableWorld):
    """The gambler's problem: stake on coin flips until the capital is ``goal`` or 0.

    Args:
        p_h: the probability of heads, in (0, 1).
        goal: the capital that wins (at least 2).
        start: the capital an episode starts with (default ``goal // 2``).
    """

    def __init__(self, p_h: float = HEADS, goal: int = GOAL, start: int | None = None) -> None:
        if isinstance(goal, bool) or not isinstance(goal, int) or goal < 2:
            raise ValueError(f"`goal` must be a whole number of at least 2, got {goal!r}")
        if isinstance(p_h, bool) or not isinstance(p_h, (int, float)) or not 0 < p_h < 1:
            raise ValueError(f"`p_h` must be a probability in (0, 1), got {p_h!r}")
        first = goal // 2 if start is None else start
        if isinstance(first, bool) or not isinstance(first, int) or not 0 < first < goal:
            raise ValueError(f"`start` must be a capital from 1 to {goal - 1}, got {start!r}")
        super().__init__(n_states=goal + 1, n_actions=goal // 2 + 1, start=first)
        self.p_h, self.goal = float(p_h), goal
        self.action_values = tuple(range(goal // 2 + 1))
        """the stake of each action"""
        self.P = self._table()

    def stake(self, capital: int, action: int) -> int:
        """The stake ``action`` plays with ``capital``: the nearest of ``1 .. min(s, goal - s)``."""
        return min(max(int(action), 1), min(capital, self.goal - capital))

    def allowed_actions(self) -> np.ndarray:
        """bool, ``(states, actions)``: the stakes ``1 .. min(s, goal - s)`` (every one at 0, goal)."""
        capital = np.arange(self.goal + 1)[:, None]
        stakes = np.arange(self.goal // 2 + 1)[None, :]
        allowed = (stakes >= 1) & (stakes <= np.minimum(capital, self.goal - capital))
        allowed[[0, self.goal]] = True
        return allowed

    def _table(self) -> Table:
        table: Table = {}
        for capital in range(self.goal + 1):
            table[capital] = {}
            for action in range(self.goal // 2 + 1):
                if capital in (0, self.goal):
                    table[capital][action] = [(1.0, capital, 0.0, True)]
                    continue
                stake = self.stake(capital, action)
                won, lost = capital + stake, capital - stake
                table[capital][action] = [
                    (self.p_h, won, float(won == self.goal), won == self.goal),
                    (1.0 - self.p_h, lost, 0.0, lost == 0),
                ]
        return table
