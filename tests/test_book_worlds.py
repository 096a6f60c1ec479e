"""Sutton & Barto's worlds (cartpole_q/worlds): registered, checked, faithful to the book.

Each world is a registered Gymnasium environment that passes ``check_env``, whose
transition table ``P`` is what ``step`` plays, whose exact optimum is the book's where the
book gives one, and which trains, resumes and draws its policy map through the tool.
"""

from __future__ import annotations

import collections
import json
import math
import subprocess
import sys
import warnings
from pathlib import Path
from typing import Any

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

from cartpole_q.config import ConfigError, load_config
from cartpole_q.envs.gym import make_env
from cartpole_q.envs.models import grid_layout
from cartpole_q.families import book_mdps, gridworlds, profile_for, walks
from cartpole_q.families.book_mdps.bias import END, A, B, MaximizationBiasEnv
from cartpole_q.families.gridworlds.worlds import (
    BARRIER_OPEN_BOTH,
    BARRIER_OPEN_LEFT,
    BARRIER_OPEN_RIGHT,
)
from cartpole_q.store.checkpoint import load_checkpoint, write_checkpoint
from cartpole_q.training import Checkpoint, train
from tests.conftest import invoke, write_yaml

WORLDS = (*gridworlds.WORLDS, *book_mdps.WORLDS, *walks.WORLDS)
IDS = [world.id for world in WORLDS]
DETERMINISTIC = [
    "cartpole_q/WindyGridworld-v0", "cartpole_q/KingsWindyGridworld-v0", "cartpole_q/DynaMaze-v0",
    "cartpole_q/BlockingMaze-v0", "cartpole_q/ShortcutMaze-v0", "cartpole_q/RandomWalk-v0",
    "cartpole_q/RandomWalk5-v0", "cartpole_q/ShortCorridor-v0",
]  # fmt: skip


def _make(env_id: str, **kwargs: Any) -> Any:
    return gymnasium.make(env_id, **kwargs)


def _optimum(env_id: str, *options: object) -> dict[str, Any]:
    result = invoke("optimum", env_id, "--json", *options)
    assert result.exit_code == 0, result.output
    found: dict[str, Any] = json.loads(result.stdout)
    return found


# -- registration and Gymnasium's checks ----------------------------------------------------------


@pytest.mark.parametrize("env_id", IDS)
def test_each_world_is_registered_and_passes_check_env(env_id: str) -> None:
    env = _make(env_id)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # any warning of the checker fails the test
        check_env(env.unwrapped)
    assert isinstance(env.observation_space, gymnasium.spaces.Discrete)
    assert isinstance(env.action_space, gymnasium.spaces.Discrete)
    assert profile_for(env_id).model == "transition_table"
    assert len(env.unwrapped.P) == env.observation_space.n


def test_time_limits_and_spaces_are_as_documented() -> None:
    expected = {
        "cartpole_q/WindyGridworld-v0": (70, 4, 10_000),
        "cartpole_q/KingsWindyGridworld-v0": (70, 8, 10_000),
        "cartpole_q/StochasticWindyGridworld-v0": (70, 8, 10_000),
        "cartpole_q/DynaMaze-v0": (54, 4, 10_000),
        "cartpole_q/BlockingMaze-v0": (54, 4, 10_000),
        "cartpole_q/ShortcutMaze-v0": (54, 4, 10_000),
        "cartpole_q/MaximizationBias-v0": (3, 10, None),
        "cartpole_q/OneState-v0": (2, 2, 1_000),
        "cartpole_q/RandomWalk5-v0": (7, 2, 1_000),
        "cartpole_q/RandomWalk-v0": (21, 2, 1_000),
        "cartpole_q/RandomWalk1000-v0": (1002, 2, 10_000),
        "cartpole_q/Baird-v0": (7, 2, None),  # continuing: no time limit, nothing ends
        "cartpole_q/ShortCorridor-v0": (4, 2, None),  # the engines cut at 10,000 steps
        "cartpole_q/AccessControl-v0": (44, 2, None),  # continuing: nothing ends
        "cartpole_q/Racetrack-v0": (7300, 9, 100_000),  # the left track
        "cartpole_q/DrivingHome-v0": (6, 1, None),  # every drive ends after five steps
    }
    assert set(expected) == set(IDS)
    for env_id, (states, actions, limit) in expected.items():
        env = _make(env_id)
        assert (env.observation_space.n, env.action_space.n) == (states, actions), env_id
        assert env.spec.max_episode_steps == limit, env_id
    assert _make("cartpole_q/KingsWindyGridworld-v0", stay=True).action_space.n == 9
    assert _make("cartpole_q/MaximizationBias-v0", b_actions=4).action_space.n == 4


def test_importing_the_package_registers_the_ids_in_a_fresh_interpreter() -> None:
    code = (
        "import sys, cartpole_q\n"
        "assert 'gymnasium' not in sys.modules  # the finder waits for Gymnasium's import\n"
        "import gymnasium\n"
        "print(gymnasium.make('cartpole_q/WindyGridworld-v0').unwrapped.__class__.__name__)\n"
    )
    after = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert after.returncode == 0, after.stderr
    assert after.stdout.split() == ["WindyGridworldEnv"]
    code = (
        "import gymnasium\n"
        "gymnasium.make('cartpole_q.worlds:cartpole_q/DynaMaze-v0')  # Gymnasium imports it\n"
        "import cartpole_q  # Gymnasium imported first: registered at once\n"
        "print(gymnasium.make('cartpole_q/RandomWalk-v0').spec.max_episode_steps)\n"
    )
    before = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert before.returncode == 0, before.stderr
    assert before.stdout.split() == ["1000"]


def test_reset_with_a_seed_is_deterministic() -> None:
    for env_id in ("cartpole_q/StochasticWindyGridworld-v0", "cartpole_q/MaximizationBias-v0"):
        trajectories = []
        for _ in range(2):
            env = _make(env_id)
            observation, _ = env.reset(seed=7)
            actions = np.random.default_rng(0).integers(0, env.action_space.n, 400)
            steps: list[Any] = [observation]
            for action in actions:
                observation, reward, terminated, truncated, _ = env.step(int(action))
                steps.append((observation, reward, terminated, truncated))
                if terminated or truncated:
                    steps.append(env.reset()[0])
            trajectories.append(steps)
        assert trajectories[0] == trajectories[1], env_id


# -- the transition table is what step plays ------------------------------------------------------


@pytest.mark.parametrize("env_id", DETERMINISTIC)
def test_a_deterministic_world_steps_as_its_table_says(env_id: str) -> None:
    world = _make(env_id).unwrapped
    world.reset(seed=0)
    table = world.P  # a changing maze rebuilds P at its change; this test stays far before it
    for state, actions in table.items():
        for action, outcomes in actions.items():
            ((probability, following, reward, terminated),) = outcomes
            assert probability == 1.0
            world.s = state
            observation, got_reward, got_terminated, truncated, _ = world.step(action)
            assert (observation, got_reward, got_terminated, truncated) == (
                following, reward, terminated, False,
            ), (state, action)  # fmt: skip


def test_the_varying_wind_is_drawn_as_its_table_says() -> None:
    world = _make("cartpole_q/StochasticWindyGridworld-v0").unwrapped
    world.reset(seed=3)
    draws = 3000
    for cell, action in (((3, 6), 3), ((4, 4), 0), ((2, 8), 2), ((6, 3), 7), ((5, 1), 3)):
        state = world.state_of(cell)
        expected: dict[int, float] = collections.defaultdict(float)
        for probability, following, _, _ in world.P[state][action]:
            expected[following] += probability
        counts: collections.Counter[int] = collections.Counter()
        for _ in range(draws):
            world.s = state
            counts[world.step(action)[0]] += 1
        assert set(counts) == set(expected), cell
        for following, probability in expected.items():
            assert abs(counts[following] / draws - probability) < 0.04, (cell, following)


def test_the_maximization_bias_world_steps_as_its_table_says_with_a_noisy_b() -> None:
    world = MaximizationBiasEnv()
    world.reset(seed=11)
    assert [world.goes_left(action) for action in range(10)] == [True] * 5 + [False] * 5
    for action in range(10):
        world.s = A
        following, reward, terminated, _, info = world.step(action)
        ((_, expected, expected_reward, expected_end),) = world.P[A][action]
        assert (following, reward, terminated) == (expected, expected_reward, expected_end)
        assert info["left_from_a"] == (following == B)
    rewards = []
    for draw in range(20_000):
        world.s = B
        following, reward, terminated, _, info = world.step(draw % 10)
        assert (following, terminated, info["left_from_a"]) == (END, True, False)
        rewards.append(reward)
    # P gives B its mean reward; the draws are Normal(-0.1, 1)
    assert {outcome[0][2] for outcome in world.P[B].values()} == {-0.1}
    assert abs(np.mean(rewards) + 0.1) < 0.03 and abs(np.std(rewards) - 1.0) < 0.03
    for bad in (3, 0, 2.0, True):
        with pytest.raises(ValueError, match="b_actions"):
            MaximizationBiasEnv(b_actions=bad)  # type: ignore[arg-type]


# -- the book's facts -----------------------------------------------------------------------------


def test_the_wind_of_each_column_is_the_books() -> None:
    world = _make("cartpole_q/WindyGridworld-v0").unwrapped
    right = world.moves.index((0, 1))
    pushes = []
    for column in range(10):
        ((_, following, _, _),) = world.P[world.state_of((5, column))][right]
        pushes.append(5 - world.cell_of(following)[0])
    assert pushes == [0, 0, 0, 1, 1, 1, 2, 2, 1, 0]
    assert (world.start, world.goal, world.rows, world.columns) == ((3, 0), (3, 7), 7, 10)
    # Exercise 6.10's example: one cell right of the goal, moving left, the wind varying
    stochastic = _make("cartpole_q/StochasticWindyGridworld-v0").unwrapped
    left = stochastic.moves.index((0, -1))
    landings = [
        stochastic.cell_of(following)
        for _, following, _, _ in stochastic.P[stochastic.state_of((3, 8))][left]
    ]
    assert landings == [(3, 7), (2, 7), (1, 7)]  # the goal, one above it, two above it


def test_the_maze_layouts_are_the_books() -> None:
    dyna = _make("cartpole_q/DynaMaze-v0").unwrapped
    assert dyna.walls == {(1, 2), (2, 2), (3, 2), (4, 5), (0, 7), (1, 7), (2, 7)}
    assert (dyna.start, dyna.goal, dyna.rows, dyna.columns) == ((2, 0), (0, 8), 6, 9)
    assert {(3, column) for column in range(8)} == BARRIER_OPEN_RIGHT
    assert {(3, column) for column in range(1, 9)} == BARRIER_OPEN_LEFT
    assert {(3, column) for column in range(1, 8)} == BARRIER_OPEN_BOTH
    for env_id, before, after, change_at in (
        ("cartpole_q/BlockingMaze-v0", BARRIER_OPEN_RIGHT, BARRIER_OPEN_LEFT, 1000),
        ("cartpole_q/ShortcutMaze-v0", BARRIER_OPEN_LEFT, BARRIER_OPEN_BOTH, 3000),
    ):
        maze = _make(env_id).unwrapped
        assert (maze.start, maze.goal, maze.change_at) == ((5, 3), (0, 8), change_at)
        assert maze.walls == before
        assert _make(env_id, change_at=0).unwrapped.walls == after


def test_a_maze_changes_after_its_step_count_across_episodes() -> None:
    env = _make("cartpole_q/BlockingMaze-v0", change_at=25)
    maze = env.unwrapped
    env.reset(seed=0)
    first_table = maze.P
    taken = 0
    while taken < 25:
        assert maze.walls == BARRIER_OPEN_RIGHT and maze.P is first_table
        _, _, terminated, truncated, _ = env.step(taken % 4)
        taken += 1
        if taken % 10 == 0 or terminated or truncated:
            env.reset()  # a reset does not restart the count
    assert maze.steps_taken == 25 and maze.walls == BARRIER_OPEN_LEFT
    # P now describes the new layout: from below the right end, up is blocked
    below_gap = maze.state_of((4, 8))
    assert maze.P[below_gap][0] == [(1.0, below_gap, 0.0, False)]
    assert first_table[below_gap][0] == [(1.0, maze.state_of((3, 8)), 0.0, False)]
    env.reset(seed=0)
    assert maze.walls == BARRIER_OPEN_LEFT
    with pytest.raises(ConfigError, match=r"env\.kwargs\.change_at"):
        make_env(load_config(overrides={"env.id": "cartpole_q/ShortcutMaze-v0",
                                        "env.kwargs.change_at": -1}).env)  # fmt: skip


def test_the_optima_are_the_books() -> None:
    # Example 6.5: 15 steps at best, -1 each
    assert _optimum("cartpole_q/WindyGridworld-v0")["optimum"]["return"] == -15.0
    # Exercise 6.9: king's moves take 7 steps, with or without staying put
    assert _optimum("cartpole_q/KingsWindyGridworld-v0")["optimum"]["return"] == -7.0
    stay = _optimum("cartpole_q/KingsWindyGridworld-v0", "--set", "env.kwargs.stay=true")
    assert stay["optimum"]["return"] == -7.0
    # Exercise 6.10: a varying wind costs steps on average
    assert -15.0 < _optimum("cartpole_q/StochasticWindyGridworld-v0")["optimum"]["return"] < -7.0
    # the mazes: +1 at the goal, so the discounted optimum gamma ** (steps - 1) gives the path
    for env_id, options, steps in (
        ("cartpole_q/DynaMaze-v0", (), 14),
        ("cartpole_q/BlockingMaze-v0", (), 10),
        ("cartpole_q/BlockingMaze-v0", ("--set", "env.kwargs.change_at=0"), 16),
        ("cartpole_q/ShortcutMaze-v0", (), 16),
        ("cartpole_q/ShortcutMaze-v0", ("--set", "env.kwargs.change_at=0"), 10),
    ):
        found = _optimum(env_id, "--gamma", 0.95, *options)
        assert found["optimum"]["return"] == 1.0
        assert math.isclose(found["optimum"]["discounted"], 0.95 ** (steps - 1)), (env_id, steps)
    # Example 6.7: right is best (0); Example 7.1: the right end pays +1
    assert _optimum("cartpole_q/MaximizationBias-v0")["optimum"]["return"] == 0.0
    assert _optimum("cartpole_q/RandomWalk-v0")["optimum"]["return"] == 1.0


def test_the_random_walk_is_the_books() -> None:
    world = _make("cartpole_q/RandomWalk-v0").unwrapped
    assert world.reset(seed=0)[0] == 10
    assert world.P[1][0] == [(1.0, 0, -1.0, True)] and world.P[19][1] == [(1.0, 20, 1.0, True)]
    assert world.P[10][0] == [(1.0, 9, 0.0, False)] and world.P[10][1] == [(1.0, 11, 0.0, False)]


def test_the_five_state_walk_is_example_6_2s() -> None:
    """States A-E are 1-5, started in C; the left end pays 0, the right end +1."""
    world = _make("cartpole_q/RandomWalk5-v0").unwrapped
    assert world.reset(seed=0)[0] == 3
    assert world.P[1][0] == [(1.0, 0, 0.0, True)] and world.P[5][1] == [(1.0, 6, 1.0, True)]
    assert world.P[3][0] == [(1.0, 2, 0.0, False)] and world.P[0][1] == [(1.0, 0, 0.0, True)]
    with pytest.raises(ValueError, match="odd number of states"):
        _make("cartpole_q/RandomWalk5-v0", states=4)


# -- the tool: maps, training, resuming -----------------------------------------------------------


def test_the_grid_maps_show_start_goal_walls_and_kings_moves() -> None:
    def layout(env_id: str, **kwargs: Any) -> Any:
        overrides = {"env.id": env_id, **{f"env.kwargs.{k}": v for k, v in kwargs.items()}}
        found = grid_layout(load_config(overrides=overrides).env)
        assert found is not None
        return found

    windy = layout("cartpole_q/WindyGridworld-v0")
    assert (windy.rows, windy.columns, windy.arrows()) == (7, 10, "^v<>")
    assert windy.cells[30] == "S" and windy.cells[37] == "G" and windy.cells.count("F") == 68
    assert layout("cartpole_q/KingsWindyGridworld-v0", stay=True).arrows() == "^v<>↖↗↙↘o"
    maze = layout("cartpole_q/DynaMaze-v0")
    assert "".join(maze.cells[:9]) == "FFFFFFF#G" and maze.cells.count("#") == 7
    assert "".join(layout("cartpole_q/BlockingMaze-v0").cells[27:36]) == "########F"
    walk = layout("cartpole_q/RandomWalk-v0")
    assert (walk.rows, walk.columns, walk.cells[0], walk.cells[10], walk.cells[20]) == (
        1, 21, "E", "S", "G",
    )  # fmt: skip
    assert profile_for("cartpole_q/MaximizationBias-v0").grid is None


WINDY = {"env": {"id": "cartpole_q/WindyGridworld-v0"}, "engine": "gymnasium",
         "agent": {"algorithm": "sarsa", "alpha": 0.5, "epsilon": 0.1, "gamma": 1.0,
                   "q_init": 0.0},
         "train": {"episodes": 40, "stop_when_solved": False, "checkpoint_every": 20,
                   "eval_every": 0},
         "eval": {"episodes": 1}}  # fmt: skip


def test_the_windy_gridworld_trains_and_resumes(tmp_path: Path) -> None:
    config = load_config(WINDY)
    assert config.discretization is None

    def keep_the_first(checkpoint: Checkpoint) -> None:
        if checkpoint.episode == 20:
            write_checkpoint(tmp_path, checkpoint)

    whole = train(config, on_checkpoint=keep_the_first, final_eval=False)
    assert whole.engine == "gymnasium" and whole.q_table.shape == (70, 4)
    assert whole.metrics.returns[0] == -whole.metrics.lengths[0]  # -1 per step
    resumed = train(config, resume=load_checkpoint(tmp_path), final_eval=False)
    assert resumed.q_table.tobytes() == whole.q_table.tobytes()
    assert resumed.visits.tobytes() == whole.visits.tobytes()


def test_the_command_line_trains_a_world_and_draws_its_policy_map(tmp_path: Path) -> None:
    result = invoke(
        "train", "--set", "env.id=cartpole_q/KingsWindyGridworld-v0", "--set",
        "env.kwargs.stay=true", "--set", "agent.algorithm=sarsa", "--set", "eval.episodes=1",
        "--episodes", 30, "--engine", "gymnasium", "--out", tmp_path / "run", "-q",
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    assert "cartpole_q/KingsWindyGridworld-v0" in (tmp_path / "run" / "config.yaml").read_text()
    assert np.load(tmp_path / "run" / "q_table.npy").shape == (70, 9)
    result = invoke("plot", tmp_path / "run", "--policy")
    assert result.exit_code == 0, result.output
    assert (tmp_path / "run" / "policy_map.png").stat().st_size > 0


def test_the_shipped_config_is_example_6_5(tmp_path: Path) -> None:
    config = load_config("windy_gridworld")
    assert (config.env.id, config.agent.algorithm) == ("cartpole_q/WindyGridworld-v0", "sarsa")
    agent = config.to_dict()["agent"]
    assert (agent["alpha"], agent["epsilon"], agent["gamma"], agent["q_init"]) == (0.5, 0.1, 1, 0)
    path = write_yaml(tmp_path / "short.yaml", {**WINDY, "train": {"episodes": 5}})
    result = invoke("train", "-c", path, "--out", tmp_path / "run", "-q")
    assert result.exit_code == 0, result.output


def test_the_maze_walls_are_drawn(tmp_path: Path) -> None:
    maze = {**WINDY, "env": {"id": "cartpole_q/DynaMaze-v0"},
            "agent": {"algorithm": "q_learning", "q_init": 0.01, "gamma": 0.95},
            "train": {"episodes": 5}}  # fmt: skip
    config = write_yaml(tmp_path / "maze.yaml", maze)
    assert invoke("train", "-c", config, "--out", tmp_path / "run", "-q").exit_code == 0
    result = invoke("plot", tmp_path / "run", "--policy")
    assert result.exit_code == 0, result.output
    text = invoke("optimum", "cartpole_q/DynaMaze-v0").stdout
    assert "# wall" in text and "F" not in text.split("\n", 3)[3]
