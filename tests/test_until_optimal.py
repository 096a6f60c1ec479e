"""Example 8.4's figure: the scaled Dyna maze, the updates counted, the study of updates until optimal."""

from __future__ import annotations

import csv
import math
from pathlib import Path
from typing import Any

import gymnasium
import numpy as np
import pytest

import cartpole_q  # noqa: F401  (registers the worlds)
from cartpole_q.config import ConfigError
from cartpole_q.engines import until_optimal as loop
from cartpole_q.engines.until_optimal import Settings, greedy_path_length, maze_arrays
from cartpole_q.experiments import updates
from cartpole_q.families.gridworlds.worlds import (
    DynaMazeEnv,
    doubled_block,
    scaled_cells,
    shortest_path,
)
from cartpole_q.rl.algorithms import prioritized_sweeping
from tests.conftest import invoke, write_yaml

STUDY = Path(__file__).resolve().parents[1] / "examples/book/example8_4_prioritized_sweeping.yaml"


def settings(algorithm: str, **changed: Any) -> Settings:
    base: dict[str, Any] = {
        "algorithm": algorithm, "alpha": 0.5, "gamma": 0.95, "epsilon": 0.1,
        "planning_steps": 5, "theta": 0.0001, "tie_break": "random", "limit": 10**9,
        "max_updates": 10**7,
    }  # fmt: skip
    return Settings(**{**base, **changed})


@pytest.mark.parametrize("scale", [1, 2, 3, 4])
def test_the_scaled_maze_has_47_k2_open_cells_and_a_shortest_path_of_14_k(scale: int) -> None:
    world = DynaMazeEnv(scale)
    assert (world.rows, world.columns) == (6 * scale, 9 * scale)
    assert world.open_cells() == 47 * scale * scale
    assert len(world.walls) == 7 * scale * scale
    assert world.start == (2 * scale, 0) and world.goal == (0, 8 * scale)
    assert shortest_path(world) == 14 * scale


def test_scale_1_is_example_8_1s_maze_and_the_blocks_are_whole() -> None:
    assert DynaMazeEnv(1).P == DynaMazeEnv().P
    assert scaled_cells({(1, 2)}, 3) == {(r, c) for r in range(3, 6) for c in range(6, 9)}


@pytest.mark.parametrize("scale", [0, -1, 1.5, True, "2"])
def test_a_scale_that_is_not_a_whole_number_from_1_is_refused(scale: Any) -> None:
    with pytest.raises(ValueError, match="scale"):
        DynaMazeEnv(scale)


def test_the_registered_world_takes_the_scale() -> None:
    env = gymnasium.make("cartpole_q/DynaMaze-v0", scale=2)
    try:
        assert env.observation_space.n == 216  # type: ignore[attr-defined]
        state, _ = env.reset(seed=0)
        assert state == 4 * 18  # cell (4, 0)
    finally:
        env.close()


def test_a_run_trains_on_the_scaled_maze() -> None:
    from cartpole_q import load_config, train

    config = load_config({
        "env": {"id": "cartpole_q/DynaMaze-v0", "kwargs": {"scale": 2}},
        "agent": {"algorithm": "prioritized_sweeping", "gamma": 0.95, "alpha": 0.5,
                  "epsilon": 0.1, "q_init": 0.0, "planning_steps": 5, "tie_break": "random"},
        "train": {"episodes": 3, "stop_when_solved": False, "eval_every": 0,
                  "checkpoint_every": 0},
        "eval": {"episodes": 1},
        "seed": 0,
    })  # fmt: skip
    result = train(config)
    assert result.q_table.shape == (216, 4)
    assert result.lengths[0] < 10_000 and result.returns[0] == 1.0  # reached the goal
    assert (result.q_table != 0.0).any()


def test_the_greedy_path_of_the_optimal_values_is_the_shortest() -> None:
    world = DynaMazeEnv(2)
    maze = maze_arrays(world)
    # Q(s, a) = gamma ** (steps from s' to the goal) on the maze's own outcomes: optimal.
    q = np.zeros((maze.n_states, maze.n_actions))
    for state in range(maze.n_states):
        for action in range(maze.n_actions):
            flat = state * maze.n_actions + action
            if maze.terminals[flat]:
                q[state, action] = 1.0
            elif (world.cell_of(state) != world.goal) and world.cell_of(state) not in world.walls:
                q[state, action] = 0.95 ** shortest_path(world, int(maze.next_states[flat]))
    assert greedy_path_length(q, maze.next_states, maze.terminals, maze.start, 28) == 28
    assert greedy_path_length(q, maze.next_states, maze.terminals, maze.start, 27) == -1
    # All zeros: always up (the lowest action), stuck against the top edge.
    zeros = np.zeros_like(q)
    assert greedy_path_length(zeros, maze.next_states, maze.terminals, maze.start, 1000) == -1


def test_the_sweeping_count_is_the_number_of_updates_made(monkeypatch: Any) -> None:
    made = []
    original = prioritized_sweeping.update

    def counted(*args: Any) -> None:
        made.append(1)
        original(*args)

    monkeypatch.setattr(prioritized_sweeping, "update", counted)
    maze = maze_arrays(DynaMazeEnv(1))
    result = loop.until_optimal(maze, settings("prioritized_sweeping"), 0, compiled=False)
    assert result.reached
    assert result.updates == len(made) > 0
    assert result.updates < 5 * result.steps  # the queue empties: fewer than n per step


def test_dyna_q_makes_1_plus_n_updates_per_step() -> None:
    maze = maze_arrays(DynaMazeEnv(1))
    result = loop.until_optimal(maze, settings("dyna_q", planning_steps=3), 0)
    assert result.reached
    assert result.updates == 4 * result.steps


@pytest.mark.parametrize("algorithm", ["prioritized_sweeping", "dyna_q"])
def test_the_compiled_loop_is_the_plain_python_one(algorithm: str) -> None:
    maze = maze_arrays(DynaMazeEnv(1))
    for seed in (0, 1):
        compiled = loop.until_optimal(maze, settings(algorithm), seed)
        plain = loop.until_optimal(maze, settings(algorithm), seed, compiled=False)
        assert compiled == plain


def test_known_counts_on_example_8_1s_maze() -> None:
    # Regression values (numpy's PCG64 draws): seed 0, alpha 0.5, 5 planning steps.
    maze = maze_arrays(DynaMazeEnv(1))
    sweeping = loop.until_optimal(maze, settings("prioritized_sweeping"), 0)
    dyna = loop.until_optimal(maze, settings("dyna_q"), 0)
    assert (sweeping.updates, sweeping.episodes) == (820, 6)
    assert (dyna.updates, dyna.episodes) == (16338, 40)


def test_a_run_that_does_not_get_there_stops_at_max_updates() -> None:
    maze = maze_arrays(DynaMazeEnv(2))
    result = loop.until_optimal(maze, settings("dyna_q", max_updates=100), 0)
    assert not result.reached
    assert result.episodes == 1 and result.updates >= 100


@pytest.mark.parametrize("doublings", range(8))
def test_the_doubled_mazes_have_the_books_sizes(doublings: int) -> None:
    world = DynaMazeEnv(doubled_block(doublings))
    rows, columns = doubled_block(doublings)
    assert world.open_cells() == 47 * 2**doublings
    assert (world.rows, world.columns) == (6 * rows, 9 * columns)
    assert world.start == (2 * rows, 0) and world.goal == (0, 8 * columns)
    assert shortest_path(world) == [14, 20, 28, 40, 56, 80, 112, 160][doublings]


def test_a_pair_scale_of_equal_sides_is_the_whole_number_scale() -> None:
    assert DynaMazeEnv((3, 3)).P == DynaMazeEnv(3).P
    assert DynaMazeEnv([2, 1]).block == (2, 1)  # as YAML gives it
    for bad in ([2], [0, 1], [1, 2, 3], (1.0, 2)):
        with pytest.raises(ValueError, match="scale"):
            DynaMazeEnv(bad)  # type: ignore[arg-type]


# Q-learning's Python run (10 s: thousands of episodes without planning) adds no path the
# planning methods' Python runs do not take: it is checked compiled.
@pytest.mark.parametrize(
    ("algorithm", "compiled"),
    [
        *[
            (name, compiled)
            for name in ("prioritized_sweeping", "dyna_q")
            for compiled in (True, False)
        ],
        ("q_learning", True),
    ],
)
def test_a_run_in_small_chunks_is_the_run_in_one(
    monkeypatch: Any, algorithm: str, compiled: bool
) -> None:
    maze = maze_arrays(DynaMazeEnv(2 if compiled else 1))
    whole = loop.until_optimal(maze, settings(algorithm), 1, compiled=compiled)
    seen: list[int] = []
    monkeypatch.setattr(loop, "CHUNK_UPDATES", 7)  # one real step per chunk and more
    chunked = loop.until_optimal(maze, settings(algorithm), 1, compiled=compiled,
                                 progress=seen.append)  # fmt: skip
    assert chunked == whole
    assert whole is not None and len(seen) > whole.episodes  # paused inside episodes
    assert seen == sorted(seen) and seen[-1] == whole.updates


def test_a_stop_between_chunks_returns_none_at_once() -> None:
    maze = maze_arrays(DynaMazeEnv(doubled_block(4)))
    asked: list[int] = []

    def stop() -> bool:
        asked.append(1)
        return len(asked) > 2

    made: list[int] = []
    result = loop.until_optimal(
        maze, settings("prioritized_sweeping"), 0, should_stop=stop, progress=made.append
    )
    assert result is None
    assert len(asked) == 3 and len(made) == 2  # two chunks, then nothing more
    assert 0 < made[-1] <= 2 * loop.CHUNK_UPDATES
    assert loop.until_optimal(maze, settings("dyna_q"), 0, should_stop=lambda: True) is None


def test_the_relaxed_criterion_stops_no_later_than_the_exact_one() -> None:
    # The same draws until the greedy path is within 1.2 x shortest, which a shortest path is.
    maze = maze_arrays(DynaMazeEnv(2))
    for algorithm in ("prioritized_sweeping", "dyna_q"):
        exact = loop.until_optimal(maze, settings(algorithm), 0)
        relaxed = loop.until_optimal(maze, settings(algorithm, optimal_within=1.2), 0)
        assert exact is not None and relaxed is not None and relaxed.reached
        assert relaxed.episodes <= exact.episodes and relaxed.updates <= exact.updates


@pytest.mark.parametrize("within", [0.9, math.nan, math.inf])
def test_a_criterion_below_the_shortest_path_is_refused(within: float) -> None:
    with pytest.raises(ValueError, match="optimal_within"):
        settings("dyna_q", optimal_within=within)


def test_a_run_whose_updates_stop_growing_gives_up_at_max_steps() -> None:
    # theta above every priority: nothing is ever queued, no update is ever made.
    maze = maze_arrays(DynaMazeEnv(1))
    result = loop.until_optimal(
        maze, settings("prioritized_sweeping", theta=2.0, max_steps=5_000), 0
    )
    assert result is not None and not result.reached
    assert result.updates == 0 and result.steps >= 5_000


def test_the_shipped_study_loads() -> None:
    study = updates.load_study(STUDY)
    assert study.kind == "until_optimal"
    assert study.methods == ("prioritized_sweeping", "dyna_q")
    assert (study.alpha, study.planning_steps, study.theta) == (0.5, 5, 0.00001)
    # the book's axis: 47 x 2^j states, 47 to 6,016, both criteria, 10 runs each
    assert [updates.maze_states(block) for block in study.scales] == [47 * 2**j for j in range(8)]
    assert study.optimal_within == (1.0, 1.2) and len(study.seeds) == 10


@pytest.mark.parametrize(
    ("change", "key"),
    [
        ("scales: [0, 1]", "scales"),
        ("scales: [1, 1]", "scales"),
        ("methods: [sarsa]", "methods"),
        ("alpha: 0", "alpha"),
        ("theta: -1", "theta"),
        ("planning_steps: -1", "planning_steps"),
        ("branching: [2]", "branching"),
    ],
)
def test_a_bad_study_is_refused_naming_the_key(tmp_path: Path, change: str, key: str) -> None:
    text = STUDY.read_text()
    name = change.partition(":")[0]
    lines = [line for line in text.splitlines() if not line.startswith(f"{name}:")]
    path = tmp_path / "study.yaml"
    path.write_text("\n".join([*lines, change]) + "\n")
    with pytest.raises(ConfigError, match=key):
        updates.load_study(path)


def test_the_command_draws_the_figure_and_its_numbers(tmp_path: Path) -> None:
    study = write_yaml(tmp_path / "study.yaml", {
        "kind": "updates", "name": "example8_4_prioritized_sweeping", "seeds": "0-1",
        "scales": [1], "theta": 0.0001, "figure": {"kind": "until_optimal"},
    })  # fmt: skip
    out = tmp_path / "study"
    result = invoke("updates", study, "--out", out)
    assert result.exit_code == 0, result.output
    assert "1 x 1 blocks (47 states, shortest path 14 steps)" in result.output
    with (out / "example8_4_prioritized_sweeping.csv").open() as handle:
        rows = list(csv.DictReader(handle))
    assert [(row["series"], row["x"]) for row in rows] == [
        ("Prioritized sweeping", "47.0"),
        ("Dyna-Q", "47.0"),
    ]
    assert float(rows[0]["y"]) == (820 + 905) / 2  # seeds 0 and 1


def test_blocks_and_criteria_are_axes_of_the_study(tmp_path: Path) -> None:
    study = write_yaml(tmp_path / "study.yaml", {
        "kind": "updates", "name": "u", "seeds": "0", "scales": [[2, 1]],
        "optimal_within": [1, 1.2], "methods": ["prioritized_sweeping"],
        "figure": {"kind": "until_optimal"},
    })  # fmt: skip
    result = invoke("study", study, "--out", tmp_path / "out", "-q")
    assert result.exit_code == 0, result.output
    with (tmp_path / "out" / "u.csv").open() as handle:
        rows = list(csv.DictReader(handle))
    assert [(row["series"], row["x"]) for row in rows] == [
        ("Prioritized sweeping (shortest path)", "94.0"),
        ("Prioritized sweeping (within 1.2x)", "94.0"),
    ]
    assert float(rows[1]["y"]) <= float(rows[0]["y"])  # a longer path is found no later
