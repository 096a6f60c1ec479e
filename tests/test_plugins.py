"""Plug-ins: an algorithm defined in one file outside the package trains like a shipped one.

``tests/plugin_algorithm.py`` registers it; nothing in the package names it. It must be
accepted by configs (with its own key), train on both engines to the same bytes, keep its
memory in checkpoints so that a resumed run matches an uninterrupted one, and run from
the command line.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any

import pytest

from cartpole_q.config import ConfigError, load_config
from cartpole_q.config.schema import AgentConfig
from cartpole_q.rl.algorithm import Param
from cartpole_q.rl.algorithms import RESERVED_KEYS, register
from cartpole_q.rl.tabular import ENDED, epsilon_greedy, expected_value, update
from cartpole_q.store.checkpoint import load_checkpoint, write_checkpoint
from cartpole_q.training import Checkpoint, train
from tests import plugin_algorithm
from tests.conftest import invoke, write_yaml

NAME = plugin_algorithm.ALGORITHM.name
SETTINGS = {
    "agent.algorithm": NAME, "agent.behaviour": 0.3, "train.episodes": 120,
    "train.stop_when_solved": False, "train.checkpoint_every": 40,
}  # fmt: skip


def test_configs_take_its_name_and_its_key() -> None:
    config = load_config(overrides=SETTINGS)
    assert config.agent.params == {"behaviour": 0.3}
    assert config.to_dict()["agent"]["behaviour"] == 0.3
    assert load_config(overrides={"agent.algorithm": NAME}).agent.params == {"behaviour": 0.2}
    with pytest.raises(ConfigError, match=r"agent.behaviour: must be in \[0, 1\], got 2"):
        load_config(overrides={**SETTINGS, "agent.behaviour": 2})
    # its key does not apply to other algorithms: left out, not refused
    assert load_config(overrides={"agent.behaviour": 0.5}).agent.params == {}


def test_sample_averages_are_refused_until_it_declares_them() -> None:
    """A plug-in whose hooks may use ``alpha`` as a number is not handed the counts."""
    with pytest.raises(ConfigError, match=r"agent\.alpha: sample_average .* does not declare"):
        load_config(overrides={**SETTINGS, "agent.alpha": "sample_average"})


# One worker for both: each trains the numba reference, whose loops it then compiles once.
@pytest.mark.xdist_group("plugin-numba-loops")
@pytest.mark.parametrize("engine", ["numba", "gymnasium"])
def test_it_trains_on_both_engines_to_the_same_bytes_and_resumes(
    engine: str, tmp_path: Path
) -> None:
    config = load_config(overrides={**SETTINGS, "engine": engine})

    def keep_the_first(checkpoint: Checkpoint) -> None:  # a callback must save, not keep
        if checkpoint.episode == 40:
            write_checkpoint(tmp_path, checkpoint)

    whole = train(config, on_checkpoint=keep_the_first, final_eval=False)
    reference = train(load_config(overrides={**SETTINGS, "engine": "numba"}), final_eval=False)
    assert whole.q_table.tobytes() == reference.q_table.tobytes()
    assert whole.visits.tobytes() == reference.visits.tobytes()
    assert whole.returns.tobytes() == reference.returns.tobytes()
    # its memory counted every update, and travels in the checkpoint file
    first = load_checkpoint(tmp_path)
    (updates,) = first.tables.memory
    assert updates.sum() == first.env_steps > 0
    # resume from the checkpoint at episode 40: the same run, byte for byte
    resumed = train(config, resume=first, final_eval=False)
    assert resumed.q_table.tobytes() == whole.q_table.tobytes()
    assert resumed.visits.tobytes() == whole.visits.tobytes()
    assert resumed.returns.tobytes() == whole.returns.tobytes()


def positional_step(q: Any, memory: Any, params: Any, state: int, action: int, reward: float,
                    next_state: int, terminated: bool, truncated: bool, alpha: float,
                    gamma: float, epsilon: float, rng: Any) -> int:  # fmt: skip
    """The plug-in's ``step`` as a plug-in wrote it before hooks took named records."""
    counts = memory[0]
    counts[state] += 1
    target = reward
    if not terminated:
        target = reward + gamma * expected_value(q, next_state, epsilon)
    update(q, state, action, target, alpha / counts[state])
    if terminated or truncated:
        return ENDED
    return epsilon_greedy(q, next_state, params[0], rng)


def test_a_plugin_written_for_positional_hooks_still_trains_to_the_same_bytes(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A ``step`` of 13 positional arguments is adapted (with a warning), not refused."""
    from cartpole_q.rl import algorithms

    # registered for this test alone: other tests list every algorithm (the schema's names)
    monkeypatch.setattr(algorithms, "_REGISTRY", dict(algorithms._REGISTRY))
    name = "positional_" + NAME
    with pytest.warns(FutureWarning, match=r"13 positional arguments.*CHANGELOG"):
        adapted = register(
            dataclasses.replace(plugin_algorithm.ALGORITHM, name=name, step=positional_step)
        )
    assert adapted.step is not positional_step
    settings = {**SETTINGS, "engine": "gymnasium", "train.episodes": 30}
    old = train(load_config(overrides={**settings, "agent.algorithm": name}), final_eval=False)
    new = train(load_config(overrides=settings), final_eval=False)
    assert old.q_table.tobytes() == new.q_table.tobytes()
    assert old.returns.tobytes() == new.returns.tobytes()
    assert old.env_steps > 30


def test_a_plugin_module_that_cannot_be_imported_is_a_config_error_naming_env_id() -> None:
    """Reading a threshold imports a plug-in world's module, as making the world would."""
    from cartpole_q.envs.gym import config_threshold

    config = load_config()
    missing = dataclasses.replace(
        config, env=dataclasses.replace(config.env, id="tests.gone:Gone-v0")
    )
    with pytest.raises(
        ConfigError, match=r"env\.id: cannot make 'tests\.gone:Gone-v0': the module"
    ):
        config_threshold(missing)


@pytest.mark.parametrize("key", sorted(RESERVED_KEYS))
def test_a_parameter_named_like_a_key_every_algorithm_has_is_refused(key: str) -> None:
    """agent.tie_break and agent.params too (issue 30: they were missing from the list)."""
    clashing = dataclasses.replace(plugin_algorithm.ALGORITHM, name=f"clash_{key}",
                                   params=(Param(key, 0.5, "clashes"),))  # fmt: skip
    with pytest.raises(ValueError, match=f"parameter {key!r} is a base key"):
        register(clashing)


def test_a_prediction_algorithm_must_declare_its_policy_first() -> None:
    """The compiled policy reads ``agent.policy`` at ``params[POLICY_AT]`` (0)."""
    from cartpole_q.rl.algorithms import get
    from cartpole_q.rl.prediction import POLICY_AT

    td = get("td")
    assert POLICY_AT == 0 and td.params[POLICY_AT].key == "policy"
    swapped = dataclasses.replace(td, name="td_policy_second", params=td.params[::-1])
    with pytest.raises(ValueError, match=r"declares agent\.policy .* as its first parameter"):
        register(swapped)


def test_hooks_read_their_parameters_by_name() -> None:
    """Each ``X_AT`` constant is where its parameter stands in the tuple the hooks get."""
    import importlib

    from cartpole_q.rl.algorithms import algorithms

    checked = 0
    for algorithm in algorithms():
        module = importlib.import_module(algorithm.step.__module__)
        for name, value in vars(module).items():
            if name.endswith("_AT") and isinstance(value, int) and name != "POLICY_AT":
                key = getattr(module, name[: -len("_AT")]).key
                assert algorithm.params[value].key == key, (algorithm.name, name)
                checked += 1
    assert checked >= 20


def test_the_reserved_keys_are_the_agent_section_s_fields() -> None:
    assert {field.name for field in dataclasses.fields(AgentConfig)} == RESERVED_KEYS


@pytest.mark.parametrize("engine", ["numba", "gymnasium"])
def test_its_first_run_says_it_is_compiling(
    engine: str, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """The Python API says so on stderr, as the command line does, naming the module."""
    import cartpole_q
    import cartpole_q.numba_cache
    from cartpole_q.engines import loop_names
    from cartpole_q.envs.gym import inspect_env

    config = load_config(overrides={**SETTINGS, "engine": engine, "train.episodes": 3})
    cartpole_q.train(config, final_eval=False)  # compiled now, if it was not
    names = loop_names(config, inspect_env(config), engine)
    assert all(cartpole_q.numba_cache.is_cached(name) for name in names)
    capsys.readouterr()
    cartpole_q.train(config, final_eval=False)
    assert capsys.readouterr().err == ""  # cached: nothing to say

    monkeypatch.setattr(cartpole_q.numba_cache, "is_cached", lambda name: False)
    cartpole_q.train(config, final_eval=False)
    assert capsys.readouterr().err == (
        f"compiling the training loop for {NAME} on CartPole-v1 ({engine} engine): once per "
        f"version of its module {plugin_algorithm.__name__}, up to a minute...\n"
    )
    cartpole_q.train(config, final_eval=False, quiet=True)
    assert capsys.readouterr().err == ""


def test_the_command_line_trains_it(tmp_path: Path) -> None:
    config = write_yaml(
        tmp_path / "plugin.yaml",
        {"agent": {"algorithm": NAME, "behaviour": 0.1}, "train": {"episodes": 30}},
    )
    result = invoke("train", "-c", config, "--out", tmp_path / "run", "-q")
    assert result.exit_code == 0, result.output
    assert f"algorithm: {NAME}" in (tmp_path / "run" / "config.yaml").read_text()


# -- an environment in one file: a registered corridor and its profile ---------------------------

from tests import plugin_world  # noqa: E402 - registers the world and its profile

WORLD = {"env": {"id": plugin_world.ENV_ID}, "agent": {"epsilon": 0.3, "q_init": 0.0},
         "train": {"episodes": 60, "stop_when_solved": False, "checkpoint_every": 20}}  # fmt: skip


def test_its_profile_is_found_by_id_and_names_its_actions() -> None:
    from cartpole_q.families import profile_for
    from cartpole_q.figures import action_names

    assert profile_for(plugin_world.ENV_ID) is plugin_world.PROFILE
    assert action_names(plugin_world.ENV_ID, 2) == ["left", "right"]


def test_a_world_trains_resumes_and_has_its_optimum(tmp_path: Path) -> None:
    config = load_config(WORLD)
    assert config.discretization is None  # a Discrete observation needs no grid

    def keep_the_first(checkpoint: Checkpoint) -> None:
        if checkpoint.episode == 20:
            write_checkpoint(tmp_path, checkpoint)

    whole = train(config, on_checkpoint=keep_the_first, final_eval=True)
    assert whole.engine == "gymnasium" and whole.q_table.shape == (plugin_world.LENGTH, 2)
    resumed = train(config, resume=load_checkpoint(tmp_path), final_eval=False)
    assert resumed.q_table.tobytes() == whole.q_table.tobytes()
    result = invoke("optimum", plugin_world.ENV_ID, "--json")
    assert result.exit_code == 0, result.output
    import json

    assert json.loads(result.stdout)["optimum"]["return"] == 1.0


def test_its_policy_map_is_drawn_as_its_grid(tmp_path: Path) -> None:
    config = write_yaml(tmp_path / "world.yaml", WORLD)
    assert invoke("train", "-c", config, "--out", tmp_path / "run", "-q").exit_code == 0
    result = invoke("plot", tmp_path / "run", "--policy")
    assert result.exit_code == 0, result.output
    from cartpole_q.envs.models import grid_layout

    layout = grid_layout(load_config(WORLD).env)
    assert layout is not None and layout.cells[-1] == "G" and layout.arrows() == "<>"


def test_a_plugin_written_before_the_families_still_imports_the_profiles() -> None:
    """``cartpole_q.profiles`` (the profiles' home before the families) re-exports them."""
    import cartpole_q.families as families
    import cartpole_q.profiles as profiles

    for name in profiles.__all__:
        assert getattr(profiles, name) is getattr(families, name), name
    assert profiles.profile_for(plugin_world.ENV_ID) is plugin_world.PROFILE


def test_a_plugin_id_written_with_its_module_finds_its_profile() -> None:
    """``module:Name-v0`` (Gymnasium imports the module) is the id ``Name-v0``'s profile."""
    from cartpole_q.families import profile_for

    assert profile_for(f"tests.plugin_world:{plugin_world.ENV_ID}") is plugin_world.PROFILE
