"""Sutton & Barto's gridworlds of chapters 3 and 4: Example 3.5's and Example 4.1's.

Both are :class:`~cartpole_q.families.tables.world.TableWorld` s: their transition table ``P`` is the
world, so dynamic programming (``cartpole-q dp``) and ``cartpole-q optimum`` solve exactly
what is played.

**States.** Cell ``(row, column)`` is state ``row * columns + column``, row 0 at the top, as
the book draws them. **Actions.** Up, down, left, right (the order of Zhang's scripts and of
:mod:`~cartpole_q.families.gridworlds.worlds`; the book fixes none). A move off the grid leaves the
agent where it is.

- ``cartpole_q/Gridworld-v0`` (Example 3.5, Figures 3.2 and 3.5): 5 x 5; every action in A
  ``(0, 1)`` moves to A' ``(4, 1)`` with reward +10, every action in B ``(0, 3)`` to B'
  ``(2, 3)`` with +5; a move off the grid earns -1, any other 0. A continuing task (the
  book discounts with gamma 0.9): nothing ends, so Gymnasium's time limit (1,000 steps) cuts
  its episodes; an episode starts in a cell drawn uniformly.
- ``cartpole_q/SmallGridworld-v0`` (Example 4.1, Figure 4.1): 4 x 4; the shaded corners
  ``(0, 0)`` and ``(3, 3)`` are one terminal state in the book, two absorbing cells here
  (as FrozenLake's goal: ``P`` stays there, terminated, reward 0; their value is 0); every
  step earns -1, the one entering a corner included; undiscounted. An episode starts in one
  of the 14 other cells, drawn uniformly.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from cartpole_q.families.gridworlds.worlds import COMPASS_MOVES, Cell
from cartpole_q.families.tables.world import Table, TableWorld

TELEPORTS: Mapping[Cell, tuple[Cell, float]] = {(0, 1): ((4, 1), 10.0), (0, 3): ((2, 3), 5.0)}
"""Example 3.5: A -> A' with +10, B -> B' with +5, whatever the action"""
SMALL_TERMINALS: tuple[Cell, ...] = ((0, 0), (3, 3))
"""Example 4.1: the two shaded corners"""


class PlanningGrid(TableWorld):
    """A grid of ``rows`` x ``columns`` cells, moved in by the four compass moves.

    Args:
        rows: the grid's height.
        columns: its width.
        step_reward: the reward of a move that stays on the grid.
        off_grid_reward: the reward of a move off the grid (the agent stays).
        terminals: absorbing cells, where an episode ends.
        teleports: cells whose every action moves to a cell with a reward.
    """

    def __init__(
        self,
        rows: int,
        columns: int,
        step_reward: float,
        off_grid_reward: float,
        terminals: tuple[Cell, ...] = (),
        teleports: Mapping[Cell, tuple[Cell, float]] | None = None,
    ) -> None:
        self.rows, self.columns = rows, columns
        self.moves = COMPASS_MOVES
        self.step_reward, self.off_grid_reward = step_reward, off_grid_reward
        self.terminals = terminals
        self.teleports = dict(teleports or {})
        super().__init__(rows * columns, len(self.moves), 0)
        ends = [self.state_of(cell) for cell in terminals]
        start = np.ones(rows * columns)
        start[ends] = 0.0
        self.initial_state_distrib = start / start.sum()
        self.P = self._table()
        self.labels: dict[int, str] = {}
        """names of some states, for figures (Example 3.5's A, A', B, B')"""
        for name, (cell, (target, _)) in zip("AB", self.teleports.items(), strict=False):
            self.labels[self.state_of(cell)] = name
            self.labels[self.state_of(target)] = f"{name}'"

    def state_of(self, cell: Cell) -> int:
        """The state of cell ``(row, column)``."""
        return cell[0] * self.columns + cell[1]

    def _table(self) -> Table:
        table: Table = {}
        for state in range(self.rows * self.columns):
            cell = divmod(state, self.columns)
            table[state] = {}
            for action, (row_step, column_step) in enumerate(self.moves):
                if cell in self.terminals:
                    table[state][action] = [(1.0, state, 0.0, True)]
                    continue
                if cell in self.teleports:
                    target, reward = self.teleports[cell]
                    table[state][action] = [(1.0, self.state_of(target), reward, False)]
                    continue
                row, column = cell[0] + row_step, cell[1] + column_step
                if 0 <= row < self.rows and 0 <= column < self.columns:
                    following, reward = self.state_of((row, column)), self.step_reward
                else:
                    following, reward = state, self.off_grid_reward
                ended = divmod(following, self.columns) in self.terminals
                table[state][action] = [(1.0, following, reward, ended)]
        return table


class GridworldEnv(PlanningGrid):
    """Example 3.5: the 5 x 5 gridworld with A -> A' (+10) and B -> B' (+5), off-grid -1."""

    def __init__(self) -> None:
        super().__init__(5, 5, 0.0, -1.0, teleports=TELEPORTS)


class SmallGridworldEnv(PlanningGrid):
    """Example 4.1: the 4 x 4 gridworld, terminal corners, -1 per step."""

    def __init__(self) -> None:
        super().__init__(4, 4, -1.0, -1.0, terminals=SMALL_TERMINALS)
