"""Config loading: defaults, partial files, overrides, and every kind of bad input."""

from __future__ import annotations

import contextlib
import math
import re
from pathlib import Path

import pytest
import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from cartpole_q.config import (
    Config,
    ConfigError,
    Schedule,
    default_raw,
    default_yaml_text,
    format_seeds,
    load_config,
    parse_assignment,
    parse_seeds,
    shipped_configs,
)
from tests.conftest import CONFIGS, write_yaml


def test_the_repository_configs_are_the_shipped_ones_and_default_is_embedded() -> None:
    shipped = shipped_configs()
    assert {"blog", "default", "sutton_barto", "sarsa", "expected_sarsa", "double_q_learning",
            "mountaincar", "acrobot"} <= set(shipped)  # fmt: skip
    assert {path.stem for path in CONFIGS.glob("*.yaml")} == set(shipped)
    assert (CONFIGS / "default.yaml").read_text(encoding="utf-8") == default_yaml_text()
    assert all(description and not description.startswith("#") for description in shipped.values())


def test_a_shipped_config_loads_by_its_name(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    assert load_config("blog") == load_config(CONFIGS / "blog.yaml")
    assert load_config("sutton_barto").train.reward_threshold == 0.0
    # an existing file of that name wins over the shipped config
    monkeypatch.chdir(tmp_path)
    write_yaml(tmp_path / "blog", {"seed": 5})
    assert load_config("blog").seed == 5
    with pytest.raises(ConfigError, match=r"not found.*blog, .*default, double_q_learning"):
        load_config("blgo")


def test_an_empty_config_file_is_the_default(tmp_path: Path) -> None:
    for text in ("", "# only a comment\n", "\n\n"):
        path = tmp_path / "empty.yaml"
        path.write_text(text, encoding="utf-8")
        assert load_config(path) == load_config()


def test_default_config_loads_with_every_section() -> None:
    config = load_config()
    assert config.env.id == "CartPole-v1"
    assert config.engine == "auto"
    assert len(config.discretization.bins) == 4
    assert config.train.stop_when_solved is True
    assert config.train.seeds is None


def test_partial_file_takes_every_other_key_from_the_default(tmp_path: Path) -> None:
    path = write_yaml(tmp_path / "c.yaml", {"seed": 7, "agent": {"gamma": 0.9}})
    config = load_config(path)
    default = load_config()
    assert config.seed == 7
    assert config.agent.gamma == 0.9
    assert config.agent.alpha == default.agent.alpha
    assert config.discretization == default.discretization
    assert config.eval == default.eval


def test_overrides_replace_file_values(tmp_path: Path) -> None:
    path = write_yaml(tmp_path / "c.yaml", {"seed": 7, "train": {"episodes": 50}})
    config = load_config(path, {"seed": 3, "train.episodes": 9, "engine": "gymnasium"})
    assert (config.seed, config.train.episodes, config.engine) == (3, 9, "gymnasium")


def test_resolved_yaml_round_trips_to_an_equal_config(tmp_path: Path) -> None:
    config = load_config(CONFIGS / "blog.yaml")
    path = tmp_path / "resolved.yaml"
    path.write_text(config.to_yaml(), encoding="utf-8")
    assert load_config(path) == config
    # every key is present in the resolved file
    assert set(yaml.safe_load(config.to_yaml())) == set(default_raw())


@pytest.mark.parametrize(
    ("value", "expected"),
    [
        (0.25, Schedule("constant", 0.25, 0.25)),
        ("5e-4", Schedule("constant", 0.0005, 0.0005)),
        ({"type": "constant", "value": 0.5}, Schedule("constant", 0.5, 0.5)),
        (
            {"type": "exponential", "start": 1.0, "decay": 0.995, "end": 0.01},
            Schedule("exponential", 1.0, 0.01, 0.995),
        ),
        ({"type": "log", "k": 25, "end": 0.1}, Schedule("log", 1.0, 0.1, 25.0)),
        ({"type": "log", "k": "2.5e1", "end": 0.1, "start": 0.5}, Schedule("log", 0.5, 0.1, 25.0)),
    ],
)
def test_schedule_forms(value: object, expected: Schedule) -> None:
    assert load_config(overrides={"agent.alpha": value}).agent.alpha == expected


@pytest.mark.parametrize("value", ["sample_average", {"type": "sample_average"}])
def test_alpha_may_be_the_sample_average_and_round_trips(tmp_path: Path, value: object) -> None:
    config = load_config(overrides={"agent.alpha": value})
    assert config.agent.alpha == Schedule("sample_average", 0.0, 0.0)
    assert config.agent.alpha.averages and not config.agent.epsilon.averages
    assert yaml.safe_load(config.to_yaml())["agent"]["alpha"] == "sample_average"
    path = tmp_path / "resolved.yaml"
    path.write_text(config.to_yaml(), encoding="utf-8")
    assert load_config(path) == config


@pytest.mark.parametrize(
    ("overrides", "message"),
    [
        (
            {"agent.epsilon": "sample_average"},
            r"agent\.epsilon: cannot be sample_average: only agent\.alpha",
        ),
        (
            {"agent.alpha": {"type": "sample_average", "start": 1.0}},
            r"agent\.alpha.*start",
        ),
        (
            {"agent.algorithm": "true_online_sarsa_lambda"},
            r"agent\.alpha: sample_average does not apply to agent\.algorithm "
            r"true_online_sarsa_lambda: its dutch traces and its correction are derived for one "
            r"step size",
        ),
        (
            {"agent.algorithm": "batch_prediction"},
            r"agent\.alpha: sample_average does not apply .* iteration over the whole batch",
        ),
        (
            {"agent.algorithm": "off_policy_monte_carlo"},
            r"agent\.alpha: sample_average does not apply .* importance-sampling weights already",
        ),
        (
            {"discretization.tilings": 4},
            r"agent\.alpha: sample_average counts the updates .* tiles",
        ),
    ],
)
def test_sample_averages_are_refused_where_they_have_no_meaning(
    overrides: dict[str, object], message: str
) -> None:
    """Only agent.alpha, only algorithms whose updates move one entry toward a target, no tiles."""
    with pytest.raises(ConfigError, match=message):
        load_config(overrides={"agent.alpha": "sample_average", **overrides})


def test_yaml_reads_5e_minus_4_as_a_string_and_we_take_the_number(tmp_path: Path) -> None:
    path = tmp_path / "c.yaml"
    path.write_text(
        "agent:\n  alpha: 5e-4\n  gamma: 1e0\ntrain:\n  episodes: 1e3\n", encoding="utf-8"
    )
    assert yaml.safe_load(path.read_text())["agent"]["alpha"] == "5e-4"
    config = load_config(path)
    assert config.agent.alpha.start == 0.0005
    assert config.agent.gamma == 1.0
    assert config.train.episodes == 1000


def _error(tmp_path: Path, text: str) -> str:
    path = tmp_path / "bad.yaml"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(ConfigError) as caught:
        load_config(path)
    message = str(caught.value)
    assert message.startswith(str(path)), message
    assert "\n" not in message.strip(), "one paragraph"
    return message


@pytest.mark.parametrize(
    ("text", "named"),
    [
        ("seed: [unclosed", "not valid YAML"),
        ("- 1\n- 2\n", "must be a mapping"),
        ("just a string", "must be a mapping"),
        ("!!python/object/apply:os.system ['echo hacked']", "tag that is not allowed"),
        ("seed: !!python/object/apply:os.getcwd []", "tag that is not allowed"),
        ("seed: 1\nseed: 2\n", "duplicate key 'seed'"),
        ("sed: 1", "did you mean 'seed'?"),
        ("agent:\n  epsilom: 0.1\n", "did you mean 'agent.epsilon'?"),
        ("train:\n  episode: 10\n", "did you mean 'train.episodes'?"),
        ("zzz: 1", "unknown key 'zzz'"),
        ("agent: 3", "agent: must be a mapping"),
        ("train:\n  episodes: many\n", "train.episodes: must be an integer, got 'many'"),
        (
            "discretization:\n  bins: [1, 1, 6.5, 12]\n",
            "discretization.bins: entry 2 must be a positive integer",
        ),
        ("seed: 1.5", "seed: must be an integer, got 1.5"),
        ("seed: true", "seed: must be an integer"),
        ("seed: -1", "seed: must be at least 0"),
        ("agent:\n  alpha: 0\n", "agent.alpha: must be in (0, 1]"),
        ("agent:\n  alpha: 1.5\n", "agent.alpha: must be in (0, 1]"),
        ("agent:\n  gamma: -0.1\n", "agent.gamma: must be in [0, 1]"),
        ("agent:\n  gamma: 1.01\n", "agent.gamma: must be in [0, 1]"),
        ("agent:\n  epsilon: 2\n", "agent.epsilon: must be in [0, 1]"),
        (
            "agent:\n  epsilon: {type: exponential, start: 1, decay: 1.5, end: 0}\n",
            "agent.epsilon.decay",
        ),
        ("agent:\n  epsilon: {type: cosine}\n", "agent.epsilon.type: must be one of"),
        ("agent:\n  epsilon: {type: log, k: 25, ned: 0}\n", "did you mean 'agent.epsilon.end'?"),
        ("agent:\n  alpha: {type: log, end: 0.1}\n", "a log schedule needs 'k'"),
        ("agent:\n  alpha: {k: 5}\n", "agent.alpha: a schedule mapping needs 'type'"),
        ("agent:\n  alpha: {type: log, k: 25, end: 0}\n", "agent.alpha.end: must be in (0, 1]"),
        ("train:\n  episodes: 0\n", "train.episodes: must be at least 1"),
        ("train:\n  episodes: -5\n", "train.episodes: must be at least 1"),
        ("train:\n  max_env_steps: 0\n", "train.max_env_steps: must be at least 1"),
        ("train:\n  max_env_steps: 2.5\n", "train.max_env_steps: must be"),
        ("discretization:\n  bins: [1, 0, 6, 12]\n", "entry 1 must be at least 1"),
        ("discretization:\n  bins: 4\n", "discretization.bins: must be a non-empty list"),
        (
            "discretization:\n  low: [-2.4, -3.0, .nan, -3.5]\n",
            "discretization.low[2]: must be a finite number",
        ),
        (
            "discretization:\n  high: [2.4, .inf, 0.2, 3.5]\n",
            "discretization.high[1]: must be a finite number",
        ),
        ("discretization:\n  low: [2.4, -3.0, -0.2, -3.5]\n", "entry 0 (2.4) must be below"),
        (
            "discretization:\n  low: [-1, -1, -1]\n",
            "discretization.low: has 3 entries but discretization.bins has 4",
        ),
        ("name: ../escape", "name: must be 1-64 letters"),
        ("name: a/b", "no path separators"),
        ("name: ''", "name: must be a non-empty string"),
        ("engine: turbo", "engine: must be one of auto, numba, gymnasium"),
        ("env:\n  kwargs: [1, 2]\n", "env.kwargs: must be a mapping"),
        ("train:\n  seeds: 5-2\n", "runs backwards"),
        ("train:\n  seeds: [1, x]\n", "every seed must be an integer"),
        (
            "train:\n  stop_when_solved: yes please\n",
            "train.stop_when_solved: must be true or false",
        ),
        ("agent:\n  max_q_table_bytes: 0\n", "agent.max_q_table_bytes: must be at least 1"),
    ],
)
def test_bad_config_names_file_and_field(tmp_path: Path, text: str, named: str) -> None:
    assert named in _error(tmp_path, text)


def test_python_tags_are_never_executed(tmp_path: Path) -> None:
    marker = tmp_path / "executed"
    path = tmp_path / "evil.yaml"
    path.write_text(f"seed: !!python/object/apply:os.mkdir ['{marker}']\n", encoding="utf-8")
    with pytest.raises(ConfigError):
        load_config(path)
    assert not marker.exists()


def test_missing_file_and_directory_are_config_errors(tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match="config file not found"):
        load_config(tmp_path / "nope.yaml")
    with pytest.raises(ConfigError, match="is a directory"):
        load_config(tmp_path)
    binary = tmp_path / "binary.yaml"
    binary.write_bytes(b"\xff\xfe\x00bad")
    with pytest.raises(ConfigError, match="not a UTF-8"):
        load_config(binary)


def test_override_errors_name_the_overrides_argument() -> None:
    # The Python API has no command line: its overrides are the `overrides` argument
    # (issue 29); the command line names itself.
    with pytest.raises(ConfigError, match=r"^overrides: train\.seeds"):
        load_config(overrides={"train.seeds": "x-y"})
    with pytest.raises(ConfigError, match=r"^overrides: agent\.alpha: must be in"):
        load_config("blog", {"agent.alpha": 2})
    with pytest.raises(ConfigError, match=r"^command line: train\.seeds"):
        load_config(overrides={"train.seeds": "x-y"}, override_source="command line")


# -- overrides merge exactly as a file does (issue 8, bug 8) ---------------------------


def test_a_nested_override_merges_into_its_section() -> None:
    config = load_config(overrides={"agent": {"gamma": 0.9}})
    default = load_config()
    assert config.agent.gamma == 0.9
    assert (config.agent.alpha, config.agent.epsilon) == (
        default.agent.alpha,
        default.agent.epsilon,
    )


def test_a_dotted_override_of_a_schedule_field_keeps_its_other_fields() -> None:
    assert load_config(overrides={"agent.epsilon.k": 25}).agent.epsilon == Schedule(
        "log", 1.0, 0.0, 25.0
    )
    assert load_config(overrides={"agent": {"epsilon": {"end": 0.05}}}).agent.epsilon == Schedule(
        "log", 1.0, 0.05, 9.0
    )
    # another type replaces the schedule; a number replaces it too
    exponential = {"type": "exponential", "start": 1, "decay": 0.99, "end": 0.01}
    assert load_config(overrides={"agent.epsilon": exponential}).agent.epsilon == Schedule(
        "exponential", 1.0, 0.01, 0.99
    )
    assert load_config(overrides={"agent.epsilon": 0.2}).agent.epsilon == Schedule(
        "constant", 0.2, 0.2
    )
    # overrides apply in order, like successive --set options
    overrides = {"agent.epsilon": exponential, "agent.epsilon.decay": 0.5}
    assert load_config(overrides=overrides).agent.epsilon.rate == 0.5


def test_overrides_and_files_merge_the_same_way(tmp_path: Path) -> None:
    nested = {"agent": {"epsilon": {"k": 30}}, "env": {"kwargs": {"max_episode_steps": 1000}}}
    from_file = load_config(write_yaml(tmp_path / "c.yaml", nested))
    assert load_config(overrides=nested) == from_file
    dotted = {"agent.epsilon.k": 30, "env.kwargs.max_episode_steps": 1000}
    assert load_config(overrides=dotted) == from_file
    assert load_config(nested) == from_file  # a mapping in place of the file


@pytest.mark.parametrize(
    ("overrides", "named"),
    [
        (
            {"agent.alpah": 0.1},
            "overrides: unknown key 'agent.alpah'; did you mean 'agent.alpha'?",
        ),
        ({"agent": {"alpah": 0.1}}, "unknown key 'agent.alpah'; did you mean 'agent.alpha'?"),
        ({"agnet.alpha": 0.1}, "unknown key 'agnet'; did you mean 'agent'?"),
        (
            {"agent.epsilon.kk": 5},
            "unknown key 'agent.epsilon.kk'; did you mean 'agent.epsilon.k'?",
        ),
        ({"agent.epsilon.k": 0}, "overrides: agent.epsilon.k: must be in (0, inf)"),
        ({"agent.alpha.k": 5}, "overrides: agent.alpha: a schedule mapping needs 'type'"),
        ({"agent.gamma.x": 1}, "overrides: agent.gamma: must be a number"),
        ({"agent..gamma": 1}, "'agent..gamma' is not a config key"),
        ({"train": 5}, "overrides: train: must be a mapping"),
    ],
)
def test_bad_overrides_raise_config_error_naming_the_key(overrides: dict, named: str) -> None:
    with pytest.raises(ConfigError) as caught:
        load_config(overrides=overrides)
    assert named in str(caught.value)


def test_errors_blame_the_file_or_the_overrides_for_each_key(tmp_path: Path) -> None:
    path = write_yaml(tmp_path / "c.yaml", {"agent": {"gamma": 2}})
    with pytest.raises(ConfigError, match=f"^{re.escape(str(path))}: agent.gamma"):
        load_config(path, {"agent.alpha": 0.5})
    with pytest.raises(ConfigError, match=r"^overrides: agent\.alpha"):
        load_config(tmp_path / "c.yaml", {"agent": {"alpha": 2, "gamma": 0.5}})


def test_a_mapping_config_names_itself_in_errors() -> None:
    with pytest.raises(ConfigError, match=r"^config mapping: unknown key 'sed'"):
        load_config({"sed": 3})


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("agent.alpha=5e-4", ("agent.alpha", "5e-4")),
        ("discretization.bins=[1,1,6,12]", ("discretization.bins", [1, 1, 6, 12])),
        ("env.kwargs.max_episode_steps=1000", ("env.kwargs.max_episode_steps", 1000)),
        ("train.stop_when_solved=false", ("train.stop_when_solved", False)),
        ("env.id=CartPole-v0", ("env.id", "CartPole-v0")),
        ("train.reward_threshold=", ("train.reward_threshold", None)),
        (
            "agent.epsilon={type: log, k: 25, end: 0}",
            ("agent.epsilon", {"type": "log", "k": 25, "end": 0}),
        ),
    ],
)
def test_set_assignments_read_the_value_as_yaml(text: str, expected: tuple) -> None:
    assert parse_assignment(text) == expected


@pytest.mark.parametrize(
    "text", ["agent.alpha", "=3", "agent.alpha=[1,", "seed=!!python/name:os.system"]
)
def test_malformed_set_assignments_are_config_errors(text: str) -> None:
    with pytest.raises(ConfigError, match=r"^--set"):
        parse_assignment(text)


@pytest.mark.parametrize(
    ("overrides", "threshold"),
    [
        ({}, 475.0),
        ({"env.kwargs.max_episode_steps": 1000}, 950.0),
        ({"env.kwargs.max_episode_steps": 200}, 190.0),
        ({"env.kwargs.max_episode_steps": 1000, "train.reward_threshold": 480}, 480.0),
        ({"env.id": "CartPole-v0", "env.kwargs.max_episode_steps": 400}, 390.0),
        ({"env.id": "Acrobot-v1", "discretization.bins": [2] * 6, "discretization.low": [-1] * 6,
          "discretization.high": [1] * 6, "env.kwargs.max_episode_steps": 1000}, -100.0),
    ],
)  # fmt: skip
def test_cartpole_threshold_scales_with_the_time_limit(
    overrides: dict, threshold: float, monkeypatch: pytest.MonkeyPatch
) -> None:
    import gymnasium

    from cartpole_q.envs.gym import config_threshold, inspect_env

    config = load_config(overrides=overrides)
    assert inspect_env(config).reward_threshold == threshold
    # a run directory's reader asks the registry alone: it makes no environment
    monkeypatch.setattr(gymnasium, "make", lambda *a, **k: pytest.fail("an environment was made"))
    assert config_threshold(config) == threshold


@pytest.mark.parametrize(
    ("epsilon", "episodes", "refused"),
    [
        (1e-310, 10, True),  # a constant so small that epsilon / n can round to 0
        ({"type": "exponential", "start": 1.0, "decay": 0.5, "end": 0.0}, 2000, True),
        ({"type": "exponential", "start": 1.0, "decay": 0.5, "end": 0.0}, 900, False),
        ({"type": "exponential", "start": 1.0, "decay": 0.995, "end": 0.0}, 1000, False),
        (0.0, 10, False),  # greedy behaviour: b_t is 1 / k, never 0
        (1e-300, 10, False),
    ],
)
def test_off_policy_monte_carlo_refuses_an_epsilon_that_makes_it_undefined(
    epsilon: object, episodes: int, refused: bool
) -> None:
    overrides = {
        "agent.algorithm": "off_policy_monte_carlo",
        "agent.epsilon": epsilon,
        "train.episodes": episodes,
    }
    if not refused:
        assert load_config(overrides=overrides).train.episodes == episodes
        return
    with pytest.raises(ConfigError, match=r"agent\.epsilon: off_policy_monte_carlo divides"):
        load_config(overrides=overrides)
    # Only the method that divides by the behaviour probability refuses it.
    assert load_config(overrides={**overrides, "agent.algorithm": "monte_carlo"})


def test_an_env_module_that_cannot_be_imported_is_a_config_error() -> None:
    from cartpole_q.envs.gym import inspect_env, make_env

    config = load_config(overrides={"env.id": "no_such_module_xyz:Env-v0"})
    with pytest.raises(ConfigError, match=r"^c\.yaml: env\.id: .*'no_such_module_xyz' cannot be"):
        inspect_env(config, "c.yaml")
    with pytest.raises(ConfigError, match="no_such_module_xyz"):
        make_env(config.env, render_mode="rgb_array")


def test_seed_lists() -> None:
    assert parse_seeds("0-3,7") == (0, 1, 2, 3, 7)
    assert parse_seeds([3, 1]) == (1, 3)
    with pytest.raises(ValueError, match=r"^seed 3 is given twice"):
        parse_seeds([3, 1, 3])
    with pytest.raises(ValueError, match=r"^seeds 0-1,5 are given twice"):
        parse_seeds("0-9,0-1,5")
    assert parse_seeds(5) == (5,)
    assert format_seeds(range(100)) == "0-99"
    assert format_seeds([0, 2, 3, 4, 9]) == "0,2-4,9"
    with pytest.raises(ValueError, match="at most"):
        parse_seeds("0-20000")


@given(st.lists(st.integers(0, 300), min_size=1, max_size=40))
def test_seed_format_round_trips(seeds: list[int]) -> None:
    assert parse_seeds(format_seeds(seeds)) == tuple(sorted(set(seeds)))


def test_frozen() -> None:
    config = load_config()
    with pytest.raises(AttributeError):
        config.seed = 3  # type: ignore[misc]
    with pytest.raises(TypeError):
        config.env.kwargs["x"] = 1  # type: ignore[index]


# -- properties: anything either loads or raises ConfigError ---------------------------

_scalars = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(-(10**6), 10**6),
    st.floats(allow_nan=True, allow_infinity=True),
    st.text(max_size=12),
)
_values = st.recursive(
    _scalars,
    lambda inner: (
        st.lists(inner, max_size=5) | st.dictionaries(st.text(max_size=8), inner, max_size=5)
    ),
    max_leaves=12,
)


def _paths(data: dict, prefix: tuple = ()) -> list[tuple]:
    paths = []
    for key, value in data.items():
        paths.append((*prefix, key))
        if isinstance(value, dict):
            paths.extend(_paths(value, (*prefix, key)))
    return paths


@settings(
    max_examples=300, suppress_health_check=[HealthCheck.function_scoped_fixture], deadline=None
)
@given(data=st.data())
def test_mutated_valid_config_loads_or_raises_config_error(
    tmp_path: Path, data: st.DataObject
) -> None:
    raw = default_raw()
    for _ in range(data.draw(st.integers(1, 3))):
        path = data.draw(st.sampled_from(_paths(raw)))
        target = raw
        for key in path[:-1]:
            target = target[key]
        if data.draw(st.booleans()):
            target[path[-1]] = data.draw(_values)
        else:
            target.pop(path[-1])
            if data.draw(st.booleans()):
                target[data.draw(st.text(max_size=10))] = data.draw(_values)
    file = tmp_path / "mutated.yaml"
    file.write_text(yaml.safe_dump(raw), encoding="utf-8")
    try:
        config = load_config(file)
    except ConfigError as error:
        assert str(error).startswith(str(file))
    else:
        assert isinstance(config, Config)
        grid = config.discretization
        assert grid is None or all(math.isfinite(x) for x in (*grid.low, *grid.high))


@settings(
    max_examples=300, suppress_health_check=[HealthCheck.function_scoped_fixture], deadline=None
)
@given(text=st.text(max_size=200))
def test_random_documents_load_or_raise_config_error(tmp_path: Path, text: str) -> None:
    file = tmp_path / "random.yaml"
    file.write_text(text, encoding="utf-8")
    with contextlib.suppress(ConfigError):  # any other exception fails the test
        load_config(file)


@settings(
    max_examples=200, suppress_health_check=[HealthCheck.function_scoped_fixture], deadline=None
)
@given(document=st.dictionaries(st.sampled_from([*default_raw(), "x"]), _values, max_size=6))
def test_random_yaml_mappings_load_or_raise_config_error(tmp_path: Path, document: dict) -> None:
    file = tmp_path / "random.yaml"
    file.write_text(yaml.safe_dump(document), encoding="utf-8")
    with contextlib.suppress(ConfigError):  # any other exception fails the test
        load_config(file)
