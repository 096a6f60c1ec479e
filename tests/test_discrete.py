"""Discrete and Tuple-of-Discrete observations: the observation is the Q-table's row.

Every run here is compared, byte for byte, with the plain re-derivation of the contract in
``tests/reference_tabular.py`` (which imports nothing from ``cartpole_q``).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import gymnasium
import numpy as np
import pytest
from gymnasium import spaces

from cartpole_q.config import ConfigError, load_config
from cartpole_q.envs.gym import inspect_env
from cartpole_q.store.rundir import metrics_csv
from cartpole_q.training import train
from tests.conftest import invoke, write_yaml
from tests.reference_tabular import constant, exponential, reference_train

ALGORITHMS = ("q_learning", "sarsa", "expected_sarsa", "double_q_learning")
TWINNED = ("FrozenLake-v1", "Blackjack-v1")
"""worlds with a compiled twin, which ``engine: auto`` trains on the numba engine"""


class ShiftedEnv(gymnasium.Env):  # type: ignore[type-arg]
    """A small random walk whose observations start away from 0.

    ``tuple_obs``: ``Tuple(Discrete(3, start=-1), Discrete(4, start=2))``, else
    ``Discrete(12, start=5)``; three actions, random rewards, random termination.
    """

    def __init__(self, tuple_obs: bool = False) -> None:
        self.tuple_obs = tuple_obs
        if tuple_obs:
            self.observation_space = spaces.Tuple(
                (spaces.Discrete(3, start=-1), spaces.Discrete(4, start=2))
            )
        else:
            self.observation_space = spaces.Discrete(12, start=5)
        self.action_space = spaces.Discrete(3)
        self.state = 0

    def _observation(self) -> Any:
        if self.tuple_obs:
            return (self.state // 4 - 1, self.state % 4 + 2)
        return self.state + 5

    def reset(self, *, seed: int | None = None, options: Any = None) -> Any:
        super().reset(seed=seed)
        self.state = int(self.np_random.integers(0, 12))
        return self._observation(), {}

    def step(self, action: int) -> Any:
        move = int(self.np_random.integers(-1, 2)) + action - 1
        self.state = (self.state + move) % 12
        reward = float(self.state == 11) - 0.1 * action
        terminated = bool(self.np_random.random() < 0.05)
        return self._observation(), reward, terminated, False, {}


class FarEnv(ShiftedEnv):
    """ShiftedEnv's walk numbered from 2**53 - 6: its last observations are not float64-exact."""

    def __init__(self) -> None:
        super().__init__()
        self.observation_space = spaces.Discrete(12, start=2**53 - 6)

    def _observation(self) -> Any:
        return self.state + 2**53 - 6


gymnasium.register("ShiftedDiscrete-v0", entry_point=ShiftedEnv, max_episode_steps=30)
gymnasium.register("FarDiscrete-v0", entry_point=FarEnv, max_episode_steps=30)
gymnasium.register(
    "ShiftedTuple-v0", entry_point=ShiftedEnv, max_episode_steps=30, kwargs={"tuple_obs": True}
)


CASES = {
    # env id, episodes, epsilon schedule, q_init
    "FrozenLake-v1": (150, (1.0, 0.99, 0.05), 0.5),
    "Blackjack-v1": (300, (1.0, 0.99, 0.05), 0.0),
    "ShiftedDiscrete-v0": (60, (0.5, 0.98, 0.0), 1.0),
    "ShiftedTuple-v0": (60, (1.0, 0.95, 0.0), 0.0),
}


def _config(env_id: str, algorithm: str, seed: int, engine: str = "auto") -> Any:
    episodes, (start, decay, end), q_init = CASES[env_id]
    return load_config(
        {
            "env": {"id": env_id},
            "engine": engine,
            "seed": seed,
            "agent": {
                "algorithm": algorithm,
                "gamma": 0.95,
                "alpha": 0.3,
                "epsilon": {"type": "exponential", "start": start, "decay": decay, "end": end},
                "q_init": q_init,
            },
            "train": {"episodes": episodes, "eval_every": 0, "checkpoint_every": 0},
        }
    )


# FrozenLake and Blackjack (on their twins) are re-derived in test_rederivation.py, for every
# algorithm on the gymnasium engine; here the ones that the twins miss: Discrete spaces
# that start away from 0 and engine: auto picking the engine.
@pytest.mark.parametrize(
    ("env_id", "algorithm"),
    [
        *((env_id, algorithm) for env_id in ("ShiftedDiscrete-v0", "ShiftedTuple-v0")
          for algorithm in ALGORITHMS),
        *((env_id, "q_learning") for env_id in TWINNED),
    ],
)  # fmt: skip
def test_training_equals_the_plain_re_derivation(env_id: str, algorithm: str) -> None:
    config = _config(env_id, algorithm, seed=3)
    result = train(config, final_eval=False)
    episodes, (start, decay, end), q_init = CASES[env_id]
    info = inspect_env(config)
    expected = reference_train(
        env_id, algorithm=algorithm, gamma=0.95, alpha=constant(0.3),
        epsilon=exponential(start, decay, end), q_init=q_init, episodes=episodes, seed=3,
        threshold=info.reward_threshold,
    )  # fmt: skip
    assert result.engine == ("numba" if env_id in TWINNED else "gymnasium")
    assert result.q_table.shape == expected.q_table.shape
    assert result.q_table.tobytes() == expected.q_table.tobytes()
    assert result.visits.tobytes() == expected.visits.tobytes()
    assert result.returns.tolist() == expected.returns
    assert result.lengths.tolist() == expected.lengths
    assert result.solved_episode == expected.solved_episode
    assert result.visits.sum() > 0


def test_q_table_shapes_follow_the_observation_space() -> None:
    shapes = {
        "FrozenLake-v1": (16, 4),
        "Taxi-v4": (500, 6),
        "CliffWalking-v1": (48, 4),
        "Blackjack-v1": (32, 11, 2, 2),
        "ShiftedDiscrete-v0": (12, 3),
        "ShiftedTuple-v0": (3, 4, 3),
    }
    for env_id, shape in shapes.items():
        config = load_config(overrides={"env.id": env_id, "train.episodes": 2})
        assert config.discretization is None
        info = inspect_env(config)
        assert (*info.state_shape, info.n_actions) == shape
        result = train(config, final_eval=False)
        assert result.q_table.shape == shape and result.visits.shape == shape


def test_a_grid_for_discrete_observations_is_refused_with_the_reason() -> None:
    config = load_config(
        overrides={
            "env.id": "FrozenLake-v1",
            "discretization": {"bins": [4], "low": [0], "high": [16]},
        }
    )
    with pytest.raises(
        ConfigError, match=r"discretization: .*Discrete\(16\).*leave discretization out"
    ):
        inspect_env(config)


def test_observations_beyond_float64_exact_integers_are_refused() -> None:
    """The gymnasium engine takes observations as float64 values: 2**53 - 6 + 11 is too far."""
    config = load_config(overrides={"env.id": "FarDiscrete-v0", "discretization": None})
    with pytest.raises(ConfigError, match=r"env\.id: 'FarDiscrete-v0' .* reach 9007199254740997"):
        inspect_env(config)


def test_a_box_observation_without_a_grid_is_refused() -> None:
    with pytest.raises(ConfigError, match=r"discretization: 'MountainCar-v0' .* needs a grid"):
        inspect_env(load_config(overrides={"env.id": "MountainCar-v0"}))


def test_the_default_grid_stays_with_cartpole_and_null_round_trips() -> None:
    assert load_config().discretization is not None
    lake = load_config(overrides={"env.id": "FrozenLake-v1"})
    assert lake.to_dict()["discretization"] is None
    assert load_config(lake.to_dict()) == lake
    explicit = load_config(overrides={"discretization": None, "env.id": "FrozenLake-v1"})
    assert explicit == lake


def test_numba_engine_is_refused_and_auto_falls_back(tmp_path: Path) -> None:
    from cartpole_q.engines import resolve_engine

    config = load_config(overrides={"env.id": "ShiftedDiscrete-v0", "engine": "numba"})
    with pytest.raises(ConfigError, match="no compiled twin"):
        resolve_engine(config, inspect_env(config))
    auto = load_config(overrides={"env.id": "ShiftedDiscrete-v0"})
    assert resolve_engine(auto, inspect_env(auto)) == "gymnasium"


def test_command_line_train_eval_plot_on_frozenlake(in_tmp: Path) -> None:
    path = write_yaml(in_tmp / "lake.yaml", {
        "env": {"id": "FrozenLake-v1"},
        "agent": {"epsilon": 0.5, "q_init": 0.0, "gamma": 0.99},
        "train": {"episodes": 200, "eval_every": 50, "eval_episodes": 5},
        "eval": {"episodes": 20},
    })  # fmt: skip
    result = invoke(
        "train", "-c", path, "--seeds", "0-1", "--workers", "1", "-q", "--out", "runs/lake"
    )
    assert result.exit_code == 0, result.output
    config_text = (in_tmp / "runs/lake/seed-000/config.yaml").read_text()
    assert "discretization: null" in config_text
    evaluated = invoke("eval", "runs/lake/seed-000", "--json", "--episodes", "10")
    assert evaluated.exit_code == 0, evaluated.output
    report = json.loads(evaluated.stdout)
    assert report["episodes"] == 10
    exact = report["exact"]
    assert exact["optimum"]["return"] == pytest.approx(0.7441902878, abs=1e-9)
    assert exact["gap"]["return"] == pytest.approx(
        exact["optimum"]["return"] - exact["greedy"]["return"]
    )
    text = invoke("eval", "runs/lake", "--workers", "1", "--episodes", "5")
    assert text.exit_code == 0 and "exact (success probability" in text.stdout
    policy = invoke("plot", "runs/lake/seed-001", "--policy")
    assert policy.exit_code == 0, policy.output
    assert (in_tmp / "runs/lake/seed-001/policy_map.png").stat().st_size > 0
    assert invoke("plot", "runs/lake").exit_code == 0


def test_greedy_play_stops_at_the_cap_without_a_time_limit() -> None:
    from cartpole_q.evaluation import evaluate

    config = load_config(overrides={"env.id": "CliffWalking-v1"})
    q = np.zeros((48, 4))  # greedy: always up, never reaching the goal
    report = evaluate(q, config, episodes=1)
    assert report.returns == (-10_000.0,)


def test_metrics_have_one_row_per_episode() -> None:
    result = train(_config("Blackjack-v1", "q_learning", 0), final_eval=False)
    assert len(metrics_csv(result.metrics).splitlines()) == 1 + result.episodes


@pytest.mark.slow
def test_shipped_cliffwalking_config_learns_the_shortest_path() -> None:
    from cartpole_q.evaluation import exact_report

    config = load_config("cliffwalking", {"seed": 1})
    result = train(config, final_eval=False)
    exact = exact_report(config, result.q_table)
    assert not isinstance(exact, str)
    assert exact.greedy == exact.optimum == -13.0


@pytest.mark.slow
def test_q_learning_finds_the_way_across_a_frozen_lake_that_does_not_slip() -> None:
    from cartpole_q.evaluation import exact_report

    # Optimistic values (q_init 1, the most an episode pays) explore without any randomness:
    # every untried action looks best until tried. (With q_init 0 and random exploration
    # the agent often never finds the goal before epsilon has decayed.)
    config = load_config({
        "env": {"id": "FrozenLake-v1", "kwargs": {"is_slippery": False}},
        "agent": {"gamma": 0.9, "alpha": 0.5, "q_init": 1.0, "epsilon": 0.0},
        "train": {"episodes": 200, "eval_every": 0, "reward_threshold": 2.0},
    })  # fmt: skip
    result = train(config, final_eval=False)
    assert result.returns[-100:].sum() == 100.0  # every one of the last 100 episodes succeeds
    exact = exact_report(config, result.q_table)
    assert not isinstance(exact, str) and exact.greedy == 1.0
