"""The compiled twin and the numba engine against real Gymnasium, by exact equality."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils import seeding

from cartpole_q.config import ConfigError, load_config
from cartpole_q.engines import make_engine, resolve_engine
from cartpole_q.envs.gym import inspect_env
from cartpole_q.envs.registry import TwinSettings, twin_settings
from cartpole_q.families.cartpole import twin
from cartpole_q.store.rundir import atomic_save_npy, metrics_csv
from cartpole_q.training import derive_generators, train
from tests.conftest import CONFIGS


def _compare_trajectory(env_kwargs: dict, seed: int, steps: int, choose) -> int:  # type: ignore[no-untyped-def]
    """Step Gymnasium and the twin side by side; return how many steps were compared."""
    env = gym.make("CartPole-v1", **env_kwargs)
    settings = twin_settings("CartPole-v1", env_kwargs, 500)
    assert isinstance(settings, TwinSettings)
    rng = seeding.np_random(seed)[0]
    state, observation = np.empty(4), np.empty(4, dtype=np.float32)
    gym_observation, _ = env.reset(seed=seed)
    twin.reset(state, observation, rng, settings.params)
    length = 0
    for step in range(steps):
        assert np.array_equal(state, env.unwrapped.state), f"state differs at step {step}"
        assert observation.tobytes() == gym_observation.tobytes(), (
            f"observation differs at step {step}"
        )
        action = choose(step, gym_observation)
        gym_observation, gym_reward, gym_terminated, gym_truncated, _ = env.step(action)
        reward, terminated = twin.step(state, action, observation, rng, settings.params)
        length += 1
        truncated = length >= settings.max_episode_steps
        assert (reward, terminated, truncated) == (gym_reward, gym_terminated, gym_truncated), step
        assert state.dtype == np.float64 and observation.dtype == np.float32
        if terminated or truncated:
            gym_observation, _ = env.reset()
            twin.reset(state, observation, rng, settings.params)
            length = 0
    return steps


@pytest.mark.parametrize(
    "env_kwargs", [{}, {"sutton_barto_reward": True}, {"max_episode_steps": 120}]
)
def test_twin_follows_fixed_action_sequences_exactly(env_kwargs: dict) -> None:
    actions = np.random.default_rng(5).integers(0, 2, size=12_000)
    sequence = np.concatenate(
        [actions[:4000], np.tile([0, 0, 1, 1, 1, 0], 1000), np.ones(2000, int)]
    )
    compared = _compare_trajectory(
        env_kwargs, 11, len(sequence), lambda step, _: int(sequence[step])
    )
    assert compared >= 12_000


def test_twin_follows_closed_loop_play_exactly() -> None:
    # A controller that reacts to the observation keeps episodes long (up to truncation).
    def controller(step: int, observation: np.ndarray) -> int:
        return int(observation[2] + 0.5 * observation[3] + 0.01 * observation[1] > 0)

    assert _compare_trajectory({}, 3, 15_000, controller) >= 15_000


def test_twin_refuses_what_it_cannot_reproduce() -> None:
    assert "no compiled twin" in twin_settings("LunarLander-v3", {}, 1000)  # type: ignore[operator]
    assert "'render_mode'" in twin_settings("CartPole-v1", {"render_mode": "human"}, 500)  # type: ignore[operator]
    assert "positive integer" in twin_settings("CartPole-v1", {"max_episode_steps": 0}, 500)  # type: ignore[operator]
    unsupported = {"disable_env_checker": True}
    config = load_config(overrides={"engine": "numba", "env.kwargs": unsupported})
    with pytest.raises(
        ConfigError,
        match=r"engine: numba cannot run this config: env\.kwargs key 'disable_env_checker'",
    ):
        resolve_engine(config, inspect_env(config))
    auto = load_config(overrides={"env.kwargs": unsupported})
    assert resolve_engine(auto, inspect_env(auto)) == "gymnasium"
    assert resolve_engine(load_config(), inspect_env(load_config())) == "numba"


def _trained_bytes(
    config_path, engine: str, seed: int, episodes: int | None = None
) -> tuple[bytes, str]:  # type: ignore[no-untyped-def]
    overrides = {"engine": engine, "seed": seed, "train.checkpoint_every": 0}
    if episodes is not None:
        overrides["train.episodes"] = episodes
    result = train(load_config(config_path, overrides), final_eval=False)
    assert result.engine == engine
    return result.q_table.tobytes(), metrics_csv(result.metrics)


ALGORITHMS = ("q_learning", "sarsa", "expected_sarsa", "double_q_learning")


@pytest.mark.parametrize("algorithm", ALGORITHMS)
@pytest.mark.parametrize(
    ("config_name", "episodes"),
    [("default.yaml", None), ("blog.yaml", 300), ("sutton_barto.yaml", 150)],
)
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_numba_and_gymnasium_engines_give_byte_identical_runs(
    tmp_path, config_name: str, episodes, seed: int, algorithm: str
) -> None:  # type: ignore[no-untyped-def]
    path = CONFIGS / config_name
    overrides = {"seed": seed, "train.checkpoint_every": 0, "agent.algorithm": algorithm}
    if episodes is not None:
        overrides["train.episodes"] = episodes
    files = {}
    for engine in ("numba", "gymnasium"):
        result = train(load_config(path, {**overrides, "engine": engine}), final_eval=False)
        directory = tmp_path / engine
        directory.mkdir()
        atomic_save_npy(directory / "q_table.npy", result.q_table)
        atomic_save_npy(directory / "visits.npy", result.visits)
        files[engine] = (
            (directory / "q_table.npy").read_bytes(),
            metrics_csv(result.metrics),
            (directory / "visits.npy").read_bytes(),
            result.evaluations,
        )
        assert result.env_steps > 0
    assert files["numba"][0] == files["gymnasium"][0]
    assert files["numba"][1] == files["gymnasium"][1]
    assert files["numba"][2] == files["gymnasium"][2]
    # periodic evaluations ran on the twin for one engine and in Gymnasium for the other
    assert files["numba"][3] == files["gymnasium"][3]


def test_algorithms_learn_different_tables() -> None:
    # the algorithm key reaches the compiled loop: each gives its own table on one seed
    tables = {
        train(load_config(overrides={"agent.algorithm": a, "train.episodes": 50}),
              final_eval=False).q_table.tobytes()
        for a in ALGORITHMS
    }  # fmt: skip
    assert len(tables) == len(ALGORITHMS)


def test_double_q_learning_keeps_the_mean_of_its_two_tables(tmp_path) -> None:  # type: ignore[no-untyped-def]
    from cartpole_q.store.checkpoint import load_checkpoint, write_checkpoint

    config = load_config(overrides={
        "agent.algorithm": "double_q_learning", "train.episodes": 40,
        "train.stop_when_solved": False, "train.checkpoint_every": 40,
    })  # fmt: skip
    saved = []
    result = train(config, on_checkpoint=saved.append, final_eval=False)
    checkpoint = saved[-1]
    q_a, (q_b,) = checkpoint.tables.q, checkpoint.tables.memory
    assert q_b.shape == q_a.shape and not np.array_equal(q_a, q_b)
    expected = (0.5 * (q_a + q_b)).reshape(result.q_table.shape)
    assert result.q_table.tobytes() == expected.tobytes()
    write_checkpoint(tmp_path, checkpoint)  # both tables travel in the checkpoint
    loaded = load_checkpoint(tmp_path)
    assert np.array_equal(loaded.tables.q, q_a) and np.array_equal(loaded.tables.memory[0], q_b)


def test_twin_evaluation_returns_exactly_what_gymnasium_returns() -> None:
    # A half-trained table fails in varied ways, so the returns differ between episodes.
    config = load_config(overrides={"train.episodes": 60, "train.stop_when_solved": False})
    result = train(config, final_eval=False)
    info = inspect_env(config)
    q = result.q_table.reshape(-1, info.n_actions)
    numba_engine = make_engine("numba", config, info, env_seed=0)
    gymnasium_engine = make_engine("gymnasium", config, info, env_seed=0)
    for seed in (0, 1000000, 123):
        compiled = numba_engine.evaluate(q, 40, seed)
        played = gymnasium_engine.evaluate(q, 40, seed)
        assert np.array_equal(compiled, played)
        assert len(set(played.tolist())) > 3


def test_same_seed_gives_the_same_run_and_another_seed_does_not() -> None:
    first = _trained_bytes(None, "numba", 4)
    assert _trained_bytes(None, "numba", 4) == first
    assert _trained_bytes(None, "numba", 5) != first


def test_chunking_does_not_change_results() -> None:
    # Periodic evaluation and checkpoints split training into different chunks.
    base = {"train.episodes": 120, "train.stop_when_solved": False}
    plain = train(
        load_config(overrides={**base, "train.eval_every": 0, "train.checkpoint_every": 0}),
        final_eval=False,
    )
    chunked = train(load_config(overrides={**base, "train.eval_every": 7, "train.checkpoint_every": 13}),
                    on_checkpoint=lambda _: None, final_eval=False)  # fmt: skip
    assert plain.q_table.tobytes() == chunked.q_table.tobytes()
    assert metrics_csv(plain.metrics) == metrics_csv(chunked.metrics)
    assert len(chunked.evaluations) == 120 // 7


def test_generators_are_derived_from_the_seed() -> None:
    rng_a, env_a, physics_a = derive_generators(7)
    rng_b, env_b, physics_b = derive_generators(7)
    assert env_a == env_b and rng_a.random() == rng_b.random()
    assert physics_a.random() == physics_b.random()
    assert derive_generators(8)[1] != env_a
    # the contract, written with NumPy alone: spawn(3)'s first two children are spawn(2)'s
    agent_seq, env_seq, physics_seq = np.random.SeedSequence(7).spawn(3)
    assert env_a == int(env_seq.generate_state(1, dtype=np.uint32)[0])
    assert (
        derive_generators(7)[0].random() == np.random.Generator(np.random.PCG64(agent_seq)).random()
    )
    assert (
        derive_generators(7)[2].random()
        == np.random.Generator(np.random.PCG64(physics_seq)).random()
    )


def test_kept_table_is_the_solve_point_when_training_goes_on() -> None:
    stopped = train(load_config(overrides={"seed": 1}), final_eval=False)
    assert stopped.solved_episode is not None
    assert stopped.episodes == stopped.solved_episode == stopped.kept_episode
    longer = train(
        load_config(
            overrides={
                "seed": 1,
                "train.stop_when_solved": False,
                "train.episodes": stopped.solved_episode + 50,
            }
        ),
        final_eval=False,
    )
    assert longer.episodes == stopped.solved_episode + 50
    assert longer.kept_episode == stopped.solved_episode
    assert longer.q_table.tobytes() == stopped.q_table.tobytes()


@pytest.mark.parametrize("name", ["numba", "gymnasium"])
@pytest.mark.parametrize("algorithm", ["q_learning", "double_q_learning"])
def test_warm_up_touches_no_state_and_draws_nothing(name: str, algorithm: str) -> None:
    from cartpole_q.engines.base import TrainingState

    config = load_config(overrides={"agent.algorithm": algorithm})
    info = inspect_env(config)
    rng = np.random.default_rng(5)
    generator_state = rng.bit_generator.state
    state = TrainingState.fresh(config, info, rng)
    engine = make_engine(name, config, info, env_seed=1)
    env_state = engine.env_rng_state()
    engine.warm_up(state)
    assert rng.bit_generator.state == generator_state
    assert engine.env_rng_state() == env_state
    assert (state.tables.q == config.agent.q_init).all() and not state.tables.visits.any()
    assert state.episode == 0


def test_every_package_twin_loads_through_a_function_mypy_checks() -> None:
    """Each family's profiles load their twins through functions typed ``TwinModule`` (mypy
    checks the module they return against the interface), from the family or the tables."""
    from cartpole_q.families import FAMILIES

    loaded = set()
    for family in FAMILIES:
        for profile in family.PROFILES:
            if profile.twin is None:
                continue
            assert callable(profile.twin), profile.name  # not a module's name
            module = profile.twin()
            assert module.__name__.startswith(
                (f"{family.__name__}.", "cartpole_q.families.tables.")
            ), (profile.name, module.__name__)
            loaded.add(module.__name__)
    # cartpole, mountaincar, acrobot, tables (2), taxi, blackjack (2), puddle
    assert len(loaded) == 9


COLD_WARM_UP = """
import json, sys
import numpy as np
from cartpole_q.config import load_config
from cartpole_q.engines import make_engine
from cartpole_q.engines.base import TrainingState
from cartpole_q.envs.gym import inspect_env

config = load_config(overrides={"env.id": "FrozenLake-v1", "train.episodes": 3})
info = inspect_env(config)
state = TrainingState.fresh(config, info, np.random.default_rng(0))
engine = make_engine("numba", config, info, env_seed=0)
engine.warm_up(state)
stats = engine._kernel.exploring.stats
print(json.dumps({
    "hits": sum(stats.cache_hits.values()), "misses": sum(stats.cache_misses.values()),
    "figure_imported": "matplotlib.figure" in sys.modules,
}))
"""


@pytest.mark.slow
def test_a_cold_warm_up_loads_the_childs_loop_and_imports_for_the_outputs_meanwhile(
    tmp_path: Path,
) -> None:
    """On an empty cache a forked child compiles the exploring loop; this process compiles
    the greedy play, imports matplotlib for the run's figure, and loads the child's loop."""
    env = {**os.environ, "XDG_CACHE_HOME": str(tmp_path / "empty-cache")}
    env.pop("NUMBA_CACHE_DIR", None)
    done = subprocess.run(
        [sys.executable, "-c", COLD_WARM_UP], env=env, capture_output=True, text=True,
        check=False, timeout=300,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    seen = json.loads(done.stdout.strip().splitlines()[-1])
    assert seen == {"hits": 1, "misses": 0, "figure_imported": True}
