"""A run is planned once: every command inspects its environment once.

Inspecting makes and resets a real Gymnasium environment; a command used to do it up to
eight times (a sweep: each point twice, compiling ahead, the figure's threshold).
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

import pytest

import cartpole_q.envs.gym
from cartpole_q.config import load_config
from cartpole_q.engines.plan import env_facts, plan_run, planned, planning
from cartpole_q.envs.gym import inspect_env, inspected_fields
from tests.conftest import invoke, write_yaml

QUICK = ("--episodes", "3", "--set", "eval.episodes=1", "--quiet")


@pytest.fixture
def inspections(monkeypatch: pytest.MonkeyPatch) -> list[str]:
    """The environment ids ``inspect_env`` is called for, wherever it is called from.

    Every module that has imported it gets the counting one; a module that imports it
    later (inside a function) takes it from ``cartpole_q.envs.gym``, which has it too.
    """
    made: list[str] = []
    original = cartpole_q.envs.gym.inspect_env

    def counting(config: Any, *args: Any, **kwargs: Any) -> Any:
        made.append(config.env.id)
        return original(config, *args, **kwargs)

    for name, module in list(sys.modules.items()):
        if name.startswith("cartpole_q") and getattr(module, "inspect_env", None) is original:
            monkeypatch.setattr(module, "inspect_env", counting)
    return made


@pytest.fixture(scope="module")
def runs(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A single run (``one``) and a multi-seed run (``seeds``) to evaluate."""
    root = tmp_path_factory.mktemp("runs")
    assert invoke("train", *QUICK, "--out", root / "one").exit_code == 0
    seeds = ("--seeds", "0-2", "--workers", "1", "--out", root / "seeds")
    assert invoke("train", *QUICK, *seeds).exit_code == 0
    return root


@pytest.mark.parametrize("engine", ["numba", "gymnasium"])
def test_train_inspects_its_environment_once(
    engine: str, tmp_path: Path, inspections: list[str]
) -> None:
    result = invoke("train", *QUICK, "--engine", engine, "--out", tmp_path / "run")
    assert result.exit_code == 0, result.output
    assert inspections == ["CartPole-v1"]


def test_a_multi_seed_run_inspects_its_environment_once(
    tmp_path: Path, inspections: list[str]
) -> None:
    """Not again to compile ahead, nor in each job (jobs share the command's plan)."""
    result = invoke("train", *QUICK, "--seeds", "0-2", "--workers", "1", "--out", tmp_path / "runs")
    assert result.exit_code == 0, result.output
    assert inspections == ["CartPole-v1"]


@pytest.mark.parametrize(
    "command",
    [
        ("eval", "one"),
        ("eval", "seeds"),
        ("robustness", "one", "--episodes", "1", "--vary", "length=0.4:0.6:2", "--out", "r.png"),
    ],
    ids=["eval", "eval-seeds", "robustness"],
)
def test_evaluating_a_run_inspects_its_environment_once(
    command: tuple[str, ...], runs: Path, tmp_path: Path, inspections: list[str]
) -> None:
    """The tables' check, the play and the threshold share one inspection."""
    name, run, *rest = command
    args = [tmp_path / arg if arg.endswith(".png") else arg for arg in rest]
    result = invoke(name, runs / run, *args)
    assert result.exit_code == 0, result.output
    assert inspections == ["CartPole-v1"]


def test_a_sweep_inspects_its_environment_once(tmp_path: Path, inspections: list[str]) -> None:
    """Its points differ in alpha only: they share the environment's facts."""
    sweep = write_yaml(
        tmp_path / "sweep.yaml",
        {
            "name": "alpha",
            "base": {"train": {"episodes": 3}, "eval": {"episodes": 1}},
            "seeds": [0, 1],
            "grid": {"agent.alpha": [0.1, 0.2]},
        },
    )
    result = invoke("sweep", sweep, "--out", tmp_path / "out", "--workers", "1", "--quiet")
    assert result.exit_code == 0, result.output
    assert inspections == ["CartPole-v1"]


def test_a_tune_inspects_its_environment_once(tmp_path: Path, inspections: list[str]) -> None:
    """Its trials differ in alpha only: they share the environment's facts."""
    pytest.importorskip("optuna")
    study = write_yaml(
        tmp_path / "tune.yaml",
        {
            "name": "alpha",
            "base": {"train": {"episodes": 3}, "eval": {"episodes": 1}},
            "seeds": "0-1",
            "trials": 3,
            "space": {"agent.alpha": {"low": 0.05, "high": 1.0}},
            "sampler": {"type": "tpe", "seed": 3},
        },
    )
    result = invoke("tune", study, "--out", tmp_path / "out", "--workers", "1", "--quiet")
    assert result.exit_code == 0, result.output
    assert inspections == ["CartPole-v1"]


def test_a_plan_carries_the_twin_the_numba_engine_runs() -> None:
    plan = plan_run(load_config())
    assert (plan.engine, plan.twin is not None) == ("numba", True)
    assert plan.twin is not None and plan.twin.twin.name == "cartpole"
    gymnasium = plan_run(load_config(overrides={"engine": "gymnasium"}))
    assert (gymnasium.engine, gymnasium.twin) == ("gymnasium", None)
    assert plan.for_seed(7).config.seed == 7 and plan.for_seed(7).twin is plan.twin


def test_plans_are_kept_per_config_but_its_seed_inside_a_planning_scope() -> None:
    config = load_config()
    with planning():
        first = planned(config)
        assert planned(config.for_seed(5)).env_info is first.env_info
        assert planned(config.for_seed(5)).config.seed == 5
        other = planned(load_config(overrides={"agent.alpha": 0.3}))
        assert other.env_info is first.env_info  # inspect_env reads nothing of alpha
        assert other.config.agent.alpha.start == 0.3
        with planning():  # an inner scope shares the outer one's
            assert planned(config).env_info is first.env_info
        assert planned(config).env_info is first.env_info
    with planning():  # the outermost scope closed: forgotten
        assert planned(config).env_info is not first.env_info


def test_outside_a_planning_scope_nothing_is_kept(inspections: list[str]) -> None:
    """A long-lived program may register an environment anew between two calls."""
    config = load_config()
    env_facts(config)
    planned(config)
    assert inspections == ["CartPole-v1", "CartPole-v1"]


@pytest.mark.parametrize(
    "overrides",
    [
        {"agent.alpha": 0.3},
        {"agent.algorithm": "sarsa_lambda"},
        {"agent.epsilon": 0.2},
        {"train.episodes": 7},
        {"seed": 3},
        {"engine": "gymnasium"},
        {"eval.episodes": 2},
        {"env.id": "FrozenLake-v1", "agent.algorithm": "td", "agent.policy": "random"},
    ],
)
def test_configs_alike_in_what_inspect_env_reads_have_the_same_facts(
    overrides: dict[str, Any],
) -> None:
    """:func:`inspected_fields` holds all that ``inspect_env`` reads: the facts it keys agree."""
    base = load_config(overrides={k: v for k, v in overrides.items() if k == "env.id"})
    varied = load_config(overrides=overrides)
    assert inspected_fields(base) == inspected_fields(varied)
    assert inspect_env(base) == inspect_env(varied)


@pytest.mark.parametrize(
    "overrides",
    [
        {"env.kwargs.max_episode_steps": 200},
        {"discretization.bins": [1, 1, 8, 4]},
        {"train.reward_threshold": 100.0},
        {"agent.max_q_table_bytes": 10**6},
    ],
)
def test_configs_that_differ_in_what_inspect_env_reads_do_not_share_facts(
    overrides: dict[str, Any],
) -> None:
    base, varied = load_config(), load_config(overrides=overrides)
    assert inspected_fields(base) != inspected_fields(varied)
    with planning():
        assert env_facts(base) is not env_facts(varied)
