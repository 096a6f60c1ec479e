"""The racetrack (Sutton & Barto Exercise 5.12, Figure 5.5): drive a car round a turn, fast.

A track is rows of cells, the top row first: ``#`` outside, ``.`` track, ``S`` the start
line, ``F`` the finish line (``left`` and ``right`` are Figure 5.5's two tracks; a text file
of such rows gives another). The car is on a track cell with a velocity ``(up, right)``, each
component 0-4. Each step costs ``-1``. An action ``a = 0 .. 8`` adds ``(a // 3 - 1, a % 3 -
1)`` to the velocity, each component clipped to 0-4; with probability ``noise`` (0.1) both
increments are zero instead. A velocity of ``(0, 0)`` is kept only on the start line; elsewhere
the car keeps its old velocity instead. The car then moves ``m = max(up, right)`` cells' worth
along the projected path: for ``k = 1 .. m`` the cell ``(row - (2 k up + m) // (2 m), column +
(2 k right + m) // (2 m))`` (integer division: the rounded point of the segment); the first of
them outside the grid or on ``#`` is a **crash** (the car is put on a start cell drawn
uniformly, velocity ``(0, 0)``; the episode goes on), the first on ``F`` is the **finish**
(the episode ends), whichever comes first; else the car stops on the last.

**States** ``(cell * 5 + up) * 5 + right``, ``cell`` the index of the car's cell among the
track cells (``.`` and ``S``) in row-major order. **Outcomes** of ``P[s][a]``: the action's
result with probability ``1 - noise``, then the zero increment's with ``noise`` (one outcome
of probability 1.0 where the two are the same: ``a = 4``); a crash is one outcome per start
cell, in row-major order, each with its share ``/ n_starts``; outcomes with the same next
state are then merged, their probabilities added in that order, at the first one's place.
A finish is ``(p, s, -1.0, True)``. The reset draws a start cell uniformly.

>>> world = RacetrackEnv("left")
>>> len(world.P), len(world.starts), world.track_size
(7300, 6, (32, 17))
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from cartpole_q.families.tables.world import Outcome, Table, TableWorld

SPEEDS = 5
"""each velocity component is 0 .. SPEEDS - 1"""
ACTIONS = 9
NOISE = 0.1
"""the chance that both increments are zero, whatever the action"""

TRACKS = {
    "left": (
        "###.............F", "##..............F", "##..............F", "#...............F",
        "................F", "................F", "..........#######", ".........########",
        ".........########", ".........########", ".........########", ".........########",
        ".........########", ".........########", "#........########", "#........########",
        "#........########", "#........########", "#........########", "#........########",
        "#........########", "#........########", "##.......########", "##.......########",
        "##.......########", "##.......########", "##.......########", "##.......########",
        "##.......########", "###......########", "###......########", "###SSSSSS########",
    ),
    "right": (
        "################...............F", "#############..................F",
        "############...................F", "###########....................F",
        "###########....................F", "###########....................F",
        "###########....................F", "############...................F",
        "#############..................F", "##############................##",
        "##############.............#####", "##############............######",
        "##############..........########", "##############.........#########",
        "#############..........#########", "############...........#########",
        "###########............#########", "##########.............#########",
        "#########..............#########", "########...............#########",
        "#######................#########", "######.................#########",
        "#####..................#########", "####...................#########",
        "###....................#########", "##.....................#########",
        "#......................#########", ".......................#########",
        ".......................#########", "SSSSSSSSSSSSSSSSSSSSSSS#########",
    ),
}  # fmt: skip
"""Figure 5.5's tracks, the top row first"""
CELLS = "#.SF"


def read_track(track: str) -> tuple[str, ...]:
    """A named track's rows, or a text file's (blank lines and trailing spaces dropped).

    Raises:
        ValueError: an unknown name or unreadable file, rows of different lengths, a
            character other than ``# . S F``, or no start or no finish cell.
    """
    if track in TRACKS:
        return TRACKS[track]
    path = Path(track)
    if not path.is_file():
        raise ValueError(
            f"track {track!r} is neither {' nor '.join(TRACKS)} nor a readable text file"
        )
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as error:
        raise ValueError(f"track {track}: cannot be read ({error})") from None
    rows = tuple(line.rstrip() for line in text.splitlines() if line.strip())
    if not rows or len({len(row) for row in rows}) != 1:
        raise ValueError(f"track {track}: its rows must be of one length, and there must be some")
    if len(rows) * len(rows[0]) > 10_000:
        raise ValueError(f"track {track}: at most 10,000 cells, got {len(rows) * len(rows[0]):,}")
    odd = sorted({char for row in rows for char in row} - set(CELLS))
    if odd:
        raise ValueError(f"track {track}: cells are # . S F, not {' '.join(map(repr, odd))}")
    for char, name in (("S", "start line"), ("F", "finish line")):
        if not any(char in row for row in rows):
            raise ValueError(f"track {track}: has no {name} (no {char} cell)")
    return rows


def track_path(
    rows: tuple[str, ...], row: int, column: int, up: int, right: int
) -> tuple[str, int, int]:
    """Where a move ends: ``("crash" | "finish" | "moved", row, column)``."""
    most = max(up, right)
    for k in range(1, most + 1):
        r = row - (2 * k * up + most) // (2 * most)
        c = column + (2 * k * right + most) // (2 * most)
        if not (0 <= r < len(rows) and 0 <= c < len(rows[0])) or rows[r][c] == "#":
            return "crash", r, c
        if rows[r][c] == "F":
            return "finish", r, c
        if k == most:
            return "moved", r, c
    return "moved", row, column


def next_velocity(on_start: bool, up: int, right: int, increment: int) -> tuple[int, int]:
    """The velocity after ``increment`` (an action, 4 for none): clipped, ``(0, 0)`` only on the start line."""
    new_up = min(SPEEDS - 1, max(0, up + increment // 3 - 1))
    new_right = min(SPEEDS - 1, max(0, right + increment % 3 - 1))
    if new_up == new_right == 0 and not on_start:
        return up, right
    return new_up, new_right


def noiseless_path(
    world: RacetrackEnv, policy: np.ndarray, start: int, most: int = 200
) -> tuple[list[tuple[int, int]], str]:
    """The cells a policy drives through from a start cell when no increment fails.

    Returns the cells from the start and how it ended: ``finish``, ``crash`` (back at the
    start line: the path stops there) or ``stuck`` (``most`` steps without either).
    """
    cell, up, right = start, 0, 0
    row, column = world.cells[cell]
    cells = [(row, column)]
    for _ in range(most):
        state = (cell * SPEEDS + up) * SPEEDS + right
        on_start = world.track_rows[row][column] == "S"
        up, right = next_velocity(on_start, up, right, int(policy[state]))
        if up == right == 0:
            continue
        what, row, column = track_path(world.track_rows, row, column, up, right)
        cells.append((row, column))
        if what != "moved":
            return cells, what
        cell = world.cells.index((row, column))
    return cells, "stuck"


MOST_TABLES = 4
"""transition tables kept per process (see :data:`_TABLES`)"""
_TABLES: dict[tuple[tuple[str, ...], float], Table] = {}
"""each track's transition table by its rows and noise, shared by its worlds (read only)"""


class RacetrackEnv(TableWorld):
    """Exercise 5.12: a racetrack played from its table (see the module).

    Args:
        track: ``left`` or ``right`` (Figure 5.5), or a text file of ``# . S F`` rows.
        noise: the chance that both increments are zero, in ``[0, 1)``.
    """

    def __init__(self, track: str = "left", noise: float = NOISE) -> None:
        if not isinstance(track, str):
            raise ValueError(f"track must be left, right or a file, got {track!r}")
        if isinstance(noise, bool) or not 0.0 <= float(noise) < 1.0:
            raise ValueError(f"noise must be in [0, 1), got {noise!r}")
        rows = read_track(track)
        cells = [
            (r, c) for r, line in enumerate(rows) for c, char in enumerate(line) if char in ".S"
        ]
        index = {cell: i for i, cell in enumerate(cells)}
        starts = [index[(r, c)] for r, c in cells if rows[r][c] == "S"]
        n_states = len(cells) * SPEEDS * SPEEDS
        super().__init__(n_states=n_states, n_actions=ACTIONS, start=0)
        self.track_rows = rows
        self.track_size = (len(rows), len(rows[0]))
        self.cells = tuple(cells)
        self.starts = tuple(starts)
        self.noise = float(noise)
        self.initial_state_distrib = np.zeros(n_states)
        for cell in starts:
            self.initial_state_distrib[cell * SPEEDS * SPEEDS] = 1.0 / len(starts)
        # Built once per track and noise in a process (1.5 s for Figure 5.5's tracks; a
        # study makes its world several times while it checks its points) and shared: read only.
        key = (rows, self.noise)
        table = _TABLES.get(key)
        if table is None:
            table = {}
            for cell, (row, column) in enumerate(cells):
                for up in range(SPEEDS):
                    for right in range(SPEEDS):
                        state = (cell * SPEEDS + up) * SPEEDS + right
                        table[state] = {
                            action: self._outcomes(state, row, column, up, right, action, index)
                            for action in range(ACTIONS)
                        }
            if len(_TABLES) >= MOST_TABLES:
                _TABLES.clear()
            _TABLES[key] = table
        self.P = table

    def _outcomes(
        self, state: int, row: int, column: int, up: int, right: int, action: int,
        index: dict[tuple[int, int], int],
    ) -> list[Outcome]:  # fmt: skip
        """``P[state][action]``: the action's result, then the zero increment's, merged."""
        branches = [(action, 1.0 - self.noise), (4, self.noise)] if action != 4 else [(4, 1.0)]
        listed: list[Outcome] = []
        for chosen, chance in branches:
            if chance == 0.0:
                continue
            on_start = self.track_rows[row][column] == "S"
            new_up, new_right = next_velocity(on_start, up, right, chosen)
            if new_up == new_right == 0:
                listed.append((chance, (index[(row, column)] * SPEEDS) * SPEEDS, -1.0, False))
                continue
            what, r, c = track_path(self.track_rows, row, column, new_up, new_right)
            if what == "finish":
                listed.append((chance, state, -1.0, True))
            elif what == "crash":
                share = chance / len(self.starts)
                listed.extend(
                    (share, start * SPEEDS * SPEEDS, -1.0, False) for start in self.starts
                )
            else:
                following = (index[(r, c)] * SPEEDS + new_up) * SPEEDS + new_right
                listed.append((chance, following, -1.0, False))
        merged: dict[tuple[int, bool], float] = {}
        for chance, following, _, ended in listed:
            key = (following, ended)
            merged[key] = merged[key] + chance if key in merged else chance
        return [(chance, following, -1.0, ended) for (following, ended), chance in merged.items()]
