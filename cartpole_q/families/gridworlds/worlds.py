"""Sutton & Barto's grid worlds: the windy gridworlds and the Dyna mazes.

The windy gridworld (Example 6.5) with king's moves (Exercise 6.9) and a varying wind
(Exercise 6.10); the Dyna maze (Example 8.1, Figure 8.2), the blocking maze (Example 8.2,
Figure 8.4) and the shortcut maze (Example 8.3, Figure 8.5).

Every grid world here is a :class:`~cartpole_q.families.tables.world.TableWorld`: its transition
table ``P`` is the world, so ``cartpole-q optimum`` solves exactly what is played.

**States.** Cell ``(row, column)`` is state ``row * columns + column``, row 0 at the top
(as the book draws them and Shangtong Zhang's scripts number them). Walls are states too,
never entered; the goal is absorbing (``P[goal][a]`` stays there, terminated, reward 0, as
FrozenLake's holes and goal).

**Actions.** ``(row step, column step)`` per action, in the order of Zhang's scripts: up,
down, left, right (the book fixes no order); king's moves add up-left, up-right, down-left,
down-right, and ``stay=True`` a ninth, stay.

**Moves.** A move goes to ``(clip(row + row step - wind), clip(column + column step))``,
each coordinate clipped to the grid once, after the wind (as Zhang's scripts; the book does
not say whether the wind's push is clipped separately, and no optimum depends on it here). A
move into a wall leaves the agent where it was (Example 8.1: "blocked by an obstacle or the
edge of the maze").

**Wind.** The wind of the column the agent moves *from* pushes it up by that many cells
(Example 6.5's figure; Exercise 6.10's example, "one cell to the right of the goal and you
move left", uses the wind of the column left). Exercise 6.10: in a windy column the push is
the column's strength minus 1, the strength, or plus 1, each with probability 1/3; a calm
column stays calm ("the effect of the wind, if there is any, is stochastic").
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from typing import Any

import numpy as np

from cartpole_q.families.tables.world import Outcome, Table, TableWorld

Cell = tuple[int, int]
"""``(row, column)``, row 0 at the top"""
Move = tuple[int, int]
"""``(row step, column step)``"""

UP, DOWN, LEFT, RIGHT = (-1, 0), (1, 0), (0, -1), (0, 1)
UP_LEFT, UP_RIGHT, DOWN_LEFT, DOWN_RIGHT = (-1, -1), (-1, 1), (1, -1), (1, 1)
STAY = (0, 0)

COMPASS_MOVES: tuple[Move, ...] = (UP, DOWN, LEFT, RIGHT)
"""the four moves, in the order of Zhang's scripts"""
KING_MOVES: tuple[Move, ...] = (*COMPASS_MOVES, UP_LEFT, UP_RIGHT, DOWN_LEFT, DOWN_RIGHT)
"""Exercise 6.9's eight king's moves"""

WINDY_ROWS, WINDY_COLUMNS = 7, 10
WINDY_START: Cell = (3, 0)
WINDY_GOAL: Cell = (3, 7)
WIND: tuple[int, ...] = (0, 0, 0, 1, 1, 1, 2, 2, 1, 0)
"""Example 6.5: the upward push of each column, left to right"""

MAZE_ROWS, MAZE_COLUMNS = 6, 9
MAZE_GOAL: Cell = (0, 8)
DYNA_MAZE_START: Cell = (2, 0)
DYNA_MAZE_WALLS: frozenset[Cell] = frozenset(
    {(1, 2), (2, 2), (3, 2), (4, 5), (0, 7), (1, 7), (2, 7)}
)
"""Example 8.1 (Figure 8.2): the seven obstacles"""
CHANGING_MAZE_START: Cell = (5, 3)
"""Figures 8.4 and 8.5: the start, in the bottom row below the barrier"""
BARRIER_OPEN_RIGHT: frozenset[Cell] = frozenset((3, column) for column in range(0, 8))
"""row 3 walled but for its right end (the blocking maze's first layout)"""
BARRIER_OPEN_LEFT: frozenset[Cell] = frozenset((3, column) for column in range(1, 9))
"""row 3 walled but for its left end (the blocking maze's second, the shortcut maze's first)"""
BARRIER_OPEN_BOTH: frozenset[Cell] = frozenset((3, column) for column in range(1, 8))
"""row 3 walled but for both ends (the shortcut maze's second layout)"""


class GridWorld(TableWorld):
    """A grid of cells with a start, a goal, walls and an upward wind per column.

    Args:
        rows: the grid's height.
        columns: its width.
        start: the start cell.
        goal: the goal cell; entering it ends the episode.
        moves: ``(row step, column step)`` per action.
        step_reward: the reward of a step that does not enter the goal.
        goal_reward: the reward of the step that enters the goal.
        wind: the upward push of each column (empty: no wind).
        wind_varies: the push of a windy column is its strength -1, 0 or +1, each with
            probability 1/3.
        walls: the cells no move enters.
    """

    def __init__(
        self,
        rows: int,
        columns: int,
        start: Cell,
        goal: Cell,
        moves: Sequence[Move],
        step_reward: float,
        goal_reward: float,
        wind: Sequence[int] = (),
        wind_varies: bool = False,
        walls: Iterable[Cell] = (),
    ) -> None:
        self.rows, self.columns = rows, columns
        self.start, self.goal = start, goal
        self.moves = tuple(moves)
        self.step_reward, self.goal_reward = step_reward, goal_reward
        self.wind = tuple(wind) if wind else (0,) * columns
        self.wind_varies = wind_varies
        self.walls: frozenset[Cell] = frozenset()
        super().__init__(rows * columns, len(self.moves), self.state_of(start))
        self.set_walls(walls)

    def state_of(self, cell: Cell) -> int:
        """The state of cell ``(row, column)``."""
        return cell[0] * self.columns + cell[1]

    def cell_of(self, state: int) -> Cell:
        """The cell ``(row, column)`` of a state."""
        row, column = divmod(state, self.columns)
        return row, column

    def set_walls(self, walls: Iterable[Cell]) -> None:
        """Put the walls in ``walls`` (and nowhere else), and rebuild ``P`` for them."""
        self.walls = frozenset(walls)
        self.P = self._table()

    def pushes(self, column: int) -> list[tuple[float, int]]:
        """The wind's possible upward pushes in ``column``: ``(probability, cells)``."""
        strength = self.wind[column]
        if self.wind_varies and strength > 0:
            return [(1 / 3, strength - 1), (1 / 3, strength), (1 / 3, strength + 1)]
        return [(1.0, strength)]

    def landing(self, cell: Cell, move: Move, push: int) -> Cell:
        """Where ``move`` from ``cell`` ends with an upward push of ``push`` cells."""
        row = min(max(cell[0] + move[0] - push, 0), self.rows - 1)
        column = min(max(cell[1] + move[1], 0), self.columns - 1)
        return cell if (row, column) in self.walls else (row, column)

    def _table(self) -> Table:
        """``P`` for the current walls (a wall's own row is what leaving it would do)."""
        goal = self.state_of(self.goal)
        table: Table = {}
        for state in range(self.rows * self.columns):
            cell = self.cell_of(state)
            table[state] = {}
            for action, move in enumerate(self.moves):
                if state == goal:
                    table[state][action] = [(1.0, goal, 0.0, True)]
                    continue
                outcomes: list[Outcome] = []
                for probability, push in self.pushes(cell[1]):
                    following = self.state_of(self.landing(cell, move, push))
                    arrived = following == goal
                    reward = self.goal_reward if arrived else self.step_reward
                    outcomes.append((probability, following, reward, arrived))
                table[state][action] = outcomes
        return table


def _king_moves(stay: Any) -> tuple[Move, ...]:
    """The eight king's moves, and stay as a ninth when ``stay`` is true."""
    if not isinstance(stay, bool):
        raise ValueError(f"`stay` must be true or false, got {stay!r}")
    return (*KING_MOVES, STAY) if stay else KING_MOVES


class WindyGridworldEnv(GridWorld):
    """Example 6.5: a 7 x 10 grid, start (3, 0), goal (3, 7), an upward wind per column.

    Four moves (up, down, left, right); the wind of columns 0-9 is 0 0 0 1 1 1 2 2 1 0.
    Every step earns -1, the one entering the goal included (the book: "rewards of -1 until
    the goal state is reached"; its optimal episode takes 15 steps, a return of -15). An
    undiscounted episodic task.
    """

    def __init__(self) -> None:
        super().__init__(
            WINDY_ROWS, WINDY_COLUMNS, WINDY_START, WINDY_GOAL, COMPASS_MOVES,
            step_reward=-1.0, goal_reward=-1.0, wind=WIND,
        )  # fmt: skip


class KingsWindyGridworldEnv(GridWorld):
    """Exercise 6.9: the windy gridworld with king's moves (7 steps at best).

    Args:
        stay: add a ninth action that does not move (the wind still pushes). The exercise
            asks about it as a second question; the default is the eight king's moves.
    """

    def __init__(self, stay: bool = False) -> None:
        super().__init__(
            WINDY_ROWS, WINDY_COLUMNS, WINDY_START, WINDY_GOAL, _king_moves(stay),
            step_reward=-1.0, goal_reward=-1.0, wind=WIND,
        )  # fmt: skip


class StochasticWindyGridworldEnv(GridWorld):
    """Exercise 6.10: king's moves, and the push of a windy column varies by -1, 0 or +1.

    Each with probability 1/3, drawn from ``np_random`` by the step's one draw (see
    :class:`~cartpole_q.families.tables.world.TableWorld`); ``P`` lists the three outcomes.

    Args:
        stay: add a ninth action that does not move, as :class:`KingsWindyGridworldEnv`.
    """

    def __init__(self, stay: bool = False) -> None:
        super().__init__(
            WINDY_ROWS, WINDY_COLUMNS, WINDY_START, WINDY_GOAL, _king_moves(stay),
            step_reward=-1.0, goal_reward=-1.0, wind=WIND, wind_varies=True,
        )  # fmt: skip


Block = tuple[int, int]
"""``(rows, columns)``: the cells that replace one cell of a scaled maze"""


def scaled_cells(cells: Iterable[Cell], scale: int | Block) -> frozenset[Cell]:
    """Every cell of the blocks that replace ``cells``: ``scale`` x ``scale``, or ``(rows, columns)``.

    >>> sorted(scaled_cells({(0, 1)}, 2))
    [(0, 2), (0, 3), (1, 2), (1, 3)]
    >>> sorted(scaled_cells({(0, 1)}, (2, 1)))
    [(0, 1), (1, 1)]
    """
    down_by, across_by = (scale, scale) if isinstance(scale, int) else scale
    return frozenset(
        (row * down_by + down, column * across_by + across)
        for row, column in cells
        for down in range(down_by)
        for across in range(across_by)
    )


def maze_block(scale: Any) -> Block:
    """A maze scale as ``(rows, columns)``: a whole number ``k >= 1`` is ``(k, k)``, a pair is itself.

    Raises:
        ValueError: ``scale`` is neither.
    """

    def whole(value: Any) -> bool:
        return isinstance(value, int) and not isinstance(value, bool) and value >= 1

    if whole(scale):
        return scale, scale
    if isinstance(scale, list | tuple) and len(scale) == 2 and all(whole(v) for v in scale):
        return scale[0], scale[1]
    raise ValueError(
        f"`scale` must be a whole number >= 1 or a pair of them [rows, columns], got {scale!r}"
    )


def doubled_block(doublings: int) -> Block:
    """The block of the Dyna maze with ``47 * 2**doublings`` open cells, the book's sizes.

    Each doubling doubles the block's rows, then its columns, in turn (the rows first: the
    6 x 9 maze stays closest to its shape), so the sizes are Example 8.4's axis: 47, 94,
    188 (the book: 186), 376, 752, 1,504, 3,008, 6,016.

    >>> [doubled_block(j) for j in range(5)]
    [(1, 1), (2, 1), (2, 2), (4, 2), (4, 4)]
    """
    if isinstance(doublings, bool) or not isinstance(doublings, int) or doublings < 0:
        raise ValueError(f"`doublings` must be a whole number >= 0, got {doublings!r}")
    return 2 ** ((doublings + 1) // 2), 2 ** (doublings // 2)


class DynaMazeEnv(GridWorld):
    """Example 8.1 (Figure 8.2): a 6 x 9 maze, start (2, 0), goal (0, 8), seven obstacles.

    Four moves; reward 0 but +1 on the step that enters the goal. The book discounts with
    gamma 0.95 (a config's ``agent.gamma``); the shortest path takes 14 steps.

    Args:
        scale: Example 8.4's larger mazes: every cell becomes a ``scale`` x ``scale`` block
            of cells (a ``6 scale`` x ``9 scale`` grid, each obstacle a block of walls, so
            ``47 scale²`` open cells); the start and the goal are the top-left cells of
            their blocks, ``(2 scale, 0)`` and ``(0, 8 scale)`` (as Shangtong Zhang's
            ``extend_maze``). 1: the maze of Example 8.1. A pair ``[rows, columns]`` makes
            blocks of that many rows and columns (``47 rows columns`` open cells; the
            doubling sizes of the book's axis: :func:`doubled_block`).
    """

    def __init__(self, scale: int | Block = 1) -> None:
        self.scale = scale
        self.block = maze_block(scale)
        down_by, across_by = self.block
        start, goal = DYNA_MAZE_START, MAZE_GOAL
        super().__init__(
            MAZE_ROWS * down_by, MAZE_COLUMNS * across_by, (start[0] * down_by, start[1] * across_by),
            (goal[0] * down_by, goal[1] * across_by), COMPASS_MOVES, step_reward=0.0,
            goal_reward=1.0, walls=scaled_cells(DYNA_MAZE_WALLS, self.block),
        )  # fmt: skip

    def open_cells(self) -> int:
        """The cells not walls (47 at scale 1, ``47 scale²``): the book's number of states."""
        return self.rows * self.columns - len(self.walls)


def shortest_path(world: TableWorld, start: int | None = None) -> int:
    """The fewest steps from ``start`` (the world's start) to a terminal step, by BFS.

    For a deterministic world (one outcome per ``P[s][a]``); -1 when no path ends.

    >>> shortest_path(DynaMazeEnv())
    14
    """
    first = int(np.argmax(world.initial_state_distrib)) if start is None else start
    distance = {first: 0}
    frontier = [first]
    while frontier:
        following: list[int] = []
        for state in frontier:
            for outcomes in world.P[state].values():
                ((_, next_state, _, terminated),) = outcomes
                if terminated:
                    return distance[state] + 1
                if next_state not in distance:
                    distance[next_state] = distance[state] + 1
                    following.append(next_state)
        frontier = following
    return -1


class ChangingMaze(GridWorld):
    """A 6 x 9 maze whose barrier changes once, after ``change_at`` steps.

    The steps are counted from the making of the environment, across episodes (resets do not
    restart the count), as the book's x-axis counts them: steps 1 to ``change_at`` are
    taken in the first layout, every later step in the second. ``P`` describes the layout
    the next step is taken in, so an exact optimum is of the layout in effect when it is
    computed (a new environment: the first, unless ``change_at`` is 0). An agent standing
    where a wall appears walks out of it as from any cell.

    Args:
        before: the barrier's walls first.
        after: its walls after the change.
        change_at: the steps taken in the first layout (0: the second from the start).
    """

    plays_its_table = False  # P changes after change_at steps: a table baked once is wrong

    def __init__(self, before: frozenset[Cell], after: frozenset[Cell], change_at: Any) -> None:
        if isinstance(change_at, bool) or not isinstance(change_at, int) or change_at < 0:
            raise ValueError(f"`change_at` must be a whole number of steps >= 0, got {change_at!r}")
        self.before, self.after, self.change_at = before, after, change_at
        # Counted from the making, not the reset: the book's change is at a time step of
        # the whole experiment, whatever episode it falls in.
        self.steps_taken = 0
        super().__init__(
            MAZE_ROWS, MAZE_COLUMNS, CHANGING_MAZE_START, MAZE_GOAL, COMPASS_MOVES,
            step_reward=0.0, goal_reward=1.0, walls=after if change_at == 0 else before,
        )  # fmt: skip

    def step(self, action: int) -> tuple[int, float, bool, bool, dict[str, Any]]:
        """Take ``action`` in the current layout; the barrier changes after step ``change_at``."""
        result = super().step(action)
        self.steps_taken += 1
        if self.steps_taken == self.change_at:
            self.set_walls(self.after)
        return result


class BlockingMazeEnv(ChangingMaze):
    """Example 8.2 (Figure 8.4): the short way round the barrier closes, a long one opens.

    First the barrier (row 3) is open at its right end (a 10-step path); after ``change_at``
    steps (the book: 1000) it is open at its left end only (16 steps).

    Args:
        change_at: the steps taken before the change.
    """

    def __init__(self, change_at: int = 1000) -> None:
        super().__init__(BARRIER_OPEN_RIGHT, BARRIER_OPEN_LEFT, change_at)


class ShortcutMazeEnv(ChangingMaze):
    """Example 8.3 (Figure 8.5): a shortcut opens on the right of the barrier.

    First the barrier (row 3) is open at its left end (a 16-step path); after ``change_at``
    steps (the book: 3000) its right end opens too (10 steps), and the long way stays open.

    Args:
        change_at: the steps taken before the change.
    """

    def __init__(self, change_at: int = 3000) -> None:
        super().__init__(BARRIER_OPEN_LEFT, BARRIER_OPEN_BOTH, change_at)
