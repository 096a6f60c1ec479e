"""A run is planned once: its environment is inspected once per command."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

import pytest

import cartpole_q.envs.gym
from cartpole_q.config import load_config
from cartpole_q.engines.plan import plan_run
from tests.conftest import invoke


@pytest.fixture
def inspections(monkeypatch: pytest.MonkeyPatch) -> list[str]:
    """The environment ids ``inspect_env`` is called for, wherever it is called from.

    Every module that has imported it gets the counting one; a module that imports it
    later (inside a function) takes it from ``cartpole_q.envs.gym``, which has it too.
    """
    made: list[str] = []
    inspect_env = cartpole_q.envs.gym.inspect_env

    def counting(config: Any, *args: Any, **kwargs: Any) -> Any:
        made.append(config.env.id)
        return inspect_env(config, *args, **kwargs)

    for name, module in list(sys.modules.items()):
        if name.startswith("cartpole_q") and getattr(module, "inspect_env", None) is inspect_env:
            monkeypatch.setattr(module, "inspect_env", counting)
    return made


@pytest.mark.parametrize("engine", ["numba", "gymnasium"])
def test_train_inspects_its_environment_once(
    engine: str, tmp_path: Path, inspections: list[str]
) -> None:
    result = invoke(
        "train", "--episodes", "3", "--set", "eval.episodes=1", "--engine", engine,
        "--out", tmp_path / "run", "--quiet",
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    assert inspections == ["CartPole-v1"]


def test_a_multi_seed_run_inspects_its_environment_once(
    tmp_path: Path, inspections: list[str]
) -> None:
    result = invoke(
        "train", "--episodes", "3", "--set", "eval.episodes=1", "--seeds", "0-2",
        "--workers", "1", "--out", tmp_path / "runs", "--quiet",
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    assert inspections == ["CartPole-v1"]


def test_a_plan_carries_the_twin_the_numba_engine_runs() -> None:
    plan = plan_run(load_config())
    assert (plan.engine, plan.twin is not None) == ("numba", True)
    assert plan.twin is not None and plan.twin.twin.name == "cartpole"
    gymnasium = plan_run(load_config(overrides={"engine": "gymnasium"}))
    assert (gymnasium.engine, gymnasium.twin) == ("gymnasium", None)
    assert plan.for_seed(7).config.seed == 7 and plan.for_seed(7).twin is plan.twin
