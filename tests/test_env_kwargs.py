"""``env.kwargs`` checked against the world's constructor before anything is made or written.

A constructor may take a value of the wrong type without complaint (FrozenLake's
``is_slippery: [1, 2]`` is a true list: the lake is slippery and the run goes on), so the
config check compares each value with the constructor's signature: its annotation, else the
type of its default.
"""

from __future__ import annotations

import inspect
from pathlib import Path
from typing import Any, Literal

import pytest

from cartpole_q.config import ConfigError, load_config
from cartpole_q.envs.arguments import rule_of
from cartpole_q.envs.gym import inspect_env
from tests.conftest import invoke
from tests.test_cli import assert_refused

ROW_SETTINGS = {"agent.algorithm": "td", "agent.policy": "random"}
"""a prediction run: the random walks' worlds evaluate a policy"""


def _inspected(env_id: str, **kwargs: Any) -> Any:
    overrides: dict[str, Any] = {"env.id": env_id, "discretization": None}
    overrides.update({f"env.kwargs.{key}": value for key, value in kwargs.items()})
    return inspect_env(load_config(overrides=overrides))


@pytest.mark.parametrize(
    ("env_id", "key", "value", "expected"),
    [
        ("FrozenLake-v1", "is_slippery", [1, 2], "is_slippery to be a boolean (true or false)"),
        ("FrozenLake-v1", "is_slippery", 1, "is_slippery to be a boolean (true or false)"),
        ("FrozenLake-v1", "map_name", 4, "map_name to be a string"),
        ("FrozenLake-v1", "reward_schedule", [1, "a", 0], "reward_schedule to be a list of 3"),
        ("cartpole_q/RandomWalk1000-v0", "groups", [1, 2], "groups to be a whole number or null"),
        ("cartpole_q/RandomWalk-v0", "states", True, "states to be a whole number"),
        ("cartpole_q/DynaMaze-v0", "scale", [2], "scale to be a whole number"),
        ("cartpole_q/BlackjackDealt-v0", "usable_ace", 1, "usable_ace to be a boolean"),
        ("Blackjack-v1", "natural", 1, "natural to be a boolean"),  # no annotation: the default's
        ("MountainCar-v0", "goal_velocity", True, "goal_velocity to be a number"),
    ],
)
def test_a_value_the_constructor_does_not_take_is_refused_naming_the_key(
    env_id: str, key: str, value: Any, expected: str
) -> None:
    with pytest.raises(ConfigError) as caught:
        _inspected(env_id, **{key: value})
    message = str(caught.value)
    assert f"env.kwargs.{key}: {env_id!r} expects {expected}" in message
    assert "got " in message and "declares" in message
    assert "\n" not in message


@pytest.mark.parametrize(
    ("env_id", "kwargs"),
    [
        ("FrozenLake-v1", {"is_slippery": False, "max_episode_steps": 50}),
        ("FrozenLake-v1", {"map_name": "8x8", "reward_schedule": [1, 0, 0]}),
        ("FrozenLake-v1", {"desc": ["SF", "FG"]}),
        ("cartpole_q/RandomWalk1000-v0", {"groups": 10}),
        ("cartpole_q/RandomWalk5-v0", {"left_reward": 0}),  # a whole number is a float's value
        ("cartpole_q/Gambler-v0", {"p_h": 0.25, "start": None}),
        ("MountainCar-v0", {"goal_velocity": 0.01}),  # declared `=0`, documented a float
        ("Blackjack-v1", {"natural": True, "sab": False}),
    ],
)
def test_values_of_the_declared_types_are_accepted(env_id: str, kwargs: dict[str, Any]) -> None:
    if env_id == "MountainCar-v0":
        grid = {"bins": [4, 4], "low": [-1.2, -0.07], "high": [0.6, 0.07]}
        overrides = {"env.id": env_id, "discretization": grid}
        overrides.update({f"env.kwargs.{key}": value for key, value in kwargs.items()})
        info = inspect_env(load_config(overrides=overrides))
    else:
        info = _inspected(env_id, **kwargs)
    assert info.id == env_id


def test_train_refuses_a_list_where_a_flag_belongs_before_writing_anything(tmp_path: Path) -> None:
    out = tmp_path / "run"
    result = invoke(
        "train", "--set", "env.id=FrozenLake-v1", "--set", "env.kwargs.is_slippery=[1,2]",
        "--episodes", "1", "--out", out,
    )  # fmt: skip
    assert_refused(result, "env.kwargs.is_slippery", "a boolean (true or false)", "[1, 2]")
    assert not out.exists()


def test_train_refuses_a_list_where_a_count_belongs(tmp_path: Path) -> None:
    sets = [f"{key}={value}" for key, value in ROW_SETTINGS.items()]
    result = invoke(
        "train", "--set", "env.id=cartpole_q/RandomWalk1000-v0", "--set",
        "env.kwargs.groups=[1,2]", *[arg for s in sets for arg in ("--set", s)],
        "--episodes", "1", "--out", tmp_path / "run",
    )  # fmt: skip
    assert_refused(result, "env.kwargs.groups", "a whole number or null", "[1, 2]")


def _rule(annotation: Any = inspect.Parameter.empty, default: Any = inspect.Parameter.empty) -> Any:
    parameter = inspect.Parameter(
        "x", inspect.Parameter.KEYWORD_ONLY, annotation=annotation, default=default
    )
    return rule_of(parameter, {})


@pytest.mark.parametrize(
    ("rule", "accepted", "refused"),
    [
        (_rule(bool), [True, False], [1, 0, "true", None]),
        (_rule(int), [0, 7, -3], [True, 1.0, "7", [7]]),
        (_rule(float), [0, 0.5, -2], [False, "0.5", [0.5]]),
        (_rule(str), ["4x4"], [4, None, ["4x4"]]),
        (_rule(int | None), [3, None], [True, 3.5]),
        (_rule("list[str] | None"), [["SF", "FG"], None], ["SFFG", [1]]),
        (_rule(Literal["a", 1]), ["a", 1], [True, "b", 1.0]),
        (_rule(default=True), [False], [1]),
        (_rule(default=3), [4], [True, 4.5]),
        (_rule(default=0.5), [1, 0.25], [True, "x"]),
        (_rule(default="4x4"), ["8x8"], [8]),
    ],
)
def test_a_rule_follows_the_annotation_else_the_default(
    rule: Any, accepted: list[Any], refused: list[Any]
) -> None:
    assert all(rule.accepts(value) for value in accepted)
    assert not any(rule.accepts(value) for value in refused)


@pytest.mark.parametrize(
    "rule", [_rule(), _rule(default=None), _rule(Any), _rule(object), _rule("NotImportedHere")]
)
def test_a_signature_that_says_nothing_we_can_check_takes_anything(rule: Any) -> None:
    assert rule is None
