"""The racetrack (issue 50, Exercise 5.12, Figure 5.5): the world, its optimum, bad tracks.

The optimum of value iteration on the world's model is checked against a brute-force search
on small tracks without noise, whose dynamics this file writes out again from the module's
docstring (a breadth-first search over positions and velocities); the table against the
rules; a track file without a start or finish line is refused naming the key.
"""

from __future__ import annotations

from collections import deque
from pathlib import Path
from typing import Any

import gymnasium
import numpy as np
import pytest

from cartpole_q.families.book_mdps.racetrack import RacetrackEnv, noiseless_path
from cartpole_q.rl.mdp import FiniteMDP
from cartpole_q.rl.solvers import value_iteration
from tests.conftest import invoke
from tests.test_cli import assert_refused

SMALL = ("....F", "....F", ".####", "S####")
TURN = ("#......F", "#......F", "#..#####", "#..#####", "#..#####", "#SS#####")


def write_track(tmp_path: Path, rows: tuple[str, ...], name: str = "track.txt") -> Path:
    path = tmp_path / name
    path.write_text("\n".join(rows) + "\n", encoding="utf-8")
    return path


def shortest_finish(rows: tuple[str, ...], start: tuple[int, int]) -> int:
    """Breadth-first search: the fewest steps from ``start`` at rest to the finish, no noise.

    Written from the rules, not the module: a velocity ``(up, right)`` of 0-4 each, nine
    increments, ``(0, 0)`` only on the start line (else the old velocity is kept); the
    rounded points of the path, the first outside or on ``#`` a crash (back to the start at
    rest: with one start cell, never shorter), the first on ``F`` the finish.
    """
    height, width = len(rows), len(rows[0])
    begin = (start[0], start[1], 0, 0)
    seen = {begin}
    queue = deque([(begin, 0)])
    while queue:
        (row, column, up, right), steps = queue.popleft()
        for dy in (-1, 0, 1):
            for dx in (-1, 0, 1):
                new_up, new_right = min(4, max(0, up + dy)), min(4, max(0, right + dx))
                if new_up == new_right == 0 and rows[row][column] != "S":
                    new_up, new_right = up, right
                most = max(new_up, new_right)
                where: tuple[int, int, int, int] | None = (row, column, 0, 0)
                for k in range(1, most + 1):
                    r = row - (2 * k * new_up + most) // (2 * most)
                    c = column + (2 * k * new_right + most) // (2 * most)
                    if not (0 <= r < height and 0 <= c < width) or rows[r][c] == "#":
                        where = begin
                        break
                    if rows[r][c] == "F":
                        return steps + 1
                    where = (r, c, new_up, new_right)
                if where is not None and where not in seen:
                    seen.add(where)
                    queue.append((where, steps + 1))
    raise AssertionError("no way to the finish")


@pytest.mark.parametrize("rows", [SMALL, (*TURN[:5], "#S######")], ids=["small", "turn"])
def test_the_optimum_is_the_brute_force_shortest_time_without_noise(
    tmp_path: Path, rows: tuple[str, ...]
) -> None:
    world = RacetrackEnv(str(write_track(tmp_path, rows)), noise=0.0)
    model = FiniteMDP.from_transitions(world.P, world.initial_state_distrib, 9)
    found = value_iteration(model, 1.0)
    (start,) = world.starts
    best = shortest_finish(rows, world.cells[start])
    assert found.values[start * 25] == -best
    cells, how = noiseless_path(world, found.policy, start)
    assert how == "finish" and len(cells) == best + 1


def test_with_noise_the_optimum_satisfies_the_optimality_equation_and_costs_more(
    tmp_path: Path,
) -> None:
    path = str(write_track(tmp_path, TURN))
    noisy = RacetrackEnv(path, noise=0.1)
    model = FiniteMDP.from_transitions(noisy.P, noisy.initial_state_distrib, 9)
    found = value_iteration(model, 1.0)
    assert np.allclose(model.backup(found.values, 1.0).max(axis=1), found.values, atol=1e-9)
    calm = RacetrackEnv(path, noise=0.0)
    calm_model = FiniteMDP.from_transitions(calm.P, calm.initial_state_distrib, 9)
    assert found.start_value < value_iteration(calm_model, 1.0).start_value


def test_figure_5_5s_tracks_are_the_books_and_their_table_follows_the_rules() -> None:
    left = gymnasium.make("cartpole_q/Racetrack-v0").unwrapped
    right = gymnasium.make("cartpole_q/Racetrack-v0", track="right").unwrapped
    assert (len(left.P), len(left.starts), left.track_size) == (7300, 6, (32, 17))
    assert (len(right.P), len(right.starts), right.track_size) == (12650, 23, (30, 32))
    for world in (left, right):
        for state in range(0, len(world.P), 97):
            for action in range(9):
                outcomes = world.P[state][action]
                assert sum(p for p, *_ in outcomes) == pytest.approx(1.0, abs=1e-12)
                assert {r for _, _, r, _ in outcomes} == {-1.0}
    # at rest on the start line, "no change" stays put, and so does (-1, -1) (clipped to
    # (0, 0)); (+1, +1) moves a cell up and right, but 1 time in 10 its increments fail
    start = left.starts[0] * 25
    assert left.P[start][4] == left.P[start][0] == [(1.0, start, -1.0, False)]
    row, column = left.cells[left.starts[0]]
    diagonal = (left.cells.index((row - 1, column + 1)) * 5 + 1) * 5 + 1
    assert left.P[start][8] == [(0.9, diagonal, -1.0, False), (0.1, start, -1.0, False)]
    # the optimum from the start line, exactly (value iteration on the model)
    model = FiniteMDP.from_transitions(left.P, left.initial_state_distrib, 9)
    assert value_iteration(model, 1.0).start_value == pytest.approx(-11.6946, abs=1e-4)


@pytest.mark.parametrize(
    ("rows", "words"),
    [
        (("....", "....", "S###"), "has no finish line (no F cell)"),
        (("...F", "...F", "####"), "has no start line (no S cell)"),
        (("...F", "..F", "S##"), "rows must be of one length"),
        (("..xF", "S..F"), "cells are # . S F, not 'x'"),
    ],
)
def test_a_bad_track_file_is_refused_naming_the_key(
    tmp_path: Path, rows: tuple[str, ...], words: str
) -> None:
    path = write_track(tmp_path, rows)
    refused = invoke("optimum", "cartpole_q/Racetrack-v0", "--set", f"env.kwargs.track={path}")
    assert_refused(refused, "env.kwargs.track", str(path), words)


def test_figure_5_5_drives_each_tracks_learned_and_optimal_policy(tmp_path: Path) -> None:
    import yaml

    from tests.conftest import write_yaml

    book = Path(__file__).resolve().parents[1] / "examples/book/fig5_5_racetrack.yaml"
    study = yaml.safe_load(book.read_text(encoding="utf-8"))
    study["base"]["train"]["episodes"] = 300  # the figure, not the learning
    path = write_yaml(tmp_path / "f55.yaml", study)
    result = invoke("study", path, "--out", tmp_path / "out", "--workers", 1, "-q")
    assert result.exit_code == 0, result.output
    rows = (tmp_path / "out" / "fig5_5_racetrack.csv").read_text(encoding="utf-8").splitlines()
    panels = {row.split('",', 1)[0].strip('"') for row in rows[1:]}
    assert len(panels) == 4
    assert "32x17 track, optimal policy (value iteration), expected return -11.69" in panels
    assert "30x32 track, optimal policy (value iteration), expected return -8.90" in panels
    optimal = [row for row in rows if row.startswith('"32x17 track')]
    series = {row.split('",', 1)[1].split(",", 1)[0] for row in optimal}
    # six start cells; from the right end of the start line the optimum crashes at once
    assert series == {f"from column {c} (finish)" for c in range(3, 8)} | {"from column 8 (crash)"}


def test_off_policy_monte_carlo_trains_alike_on_the_twin_and_gymnasium_make() -> None:
    from cartpole_q import load_config, train

    def trained(engine: str) -> Any:
        config = load_config({
            "env": {"id": "cartpole_q/Racetrack-v0", "kwargs": {"track": "left"}},
            "discretization": None, "engine": engine, "seed": 3,
            "agent": {"algorithm": "off_policy_monte_carlo", "update": "constant_alpha",
                      "alpha": 0.1, "gamma": 1.0, "epsilon": 0.1, "q_init": -200.0,
                      "tie_break": "random"},
            "train": {"episodes": 40, "eval_every": 0, "checkpoint_every": 0,
                      "reward_threshold": None},
            "eval": {"episodes": 1},
        })  # fmt: skip
        return train(config, quiet=True)

    numba, gym = trained("numba"), trained("gymnasium")
    assert (numba.engine, gym.engine) == ("numba", "gymnasium")
    assert numba.q_table.tobytes() == gym.q_table.tobytes()
    assert numba.visits.tobytes() == gym.visits.tobytes() and numba.env_steps > 1000
