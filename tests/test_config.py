"""Config loading: defaults, partial files, overrides, and every kind of bad input."""

from __future__ import annotations

import contextlib
import math
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
    parse_seeds,
)
from tests.conftest import CONFIGS, write_yaml


def test_embedded_default_and_its_twin_in_configs_are_the_same_file() -> None:
    assert (CONFIGS / "default.yaml").read_text(encoding="utf-8") == default_yaml_text()


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
        ("", "is empty"),
        ("# only a comment\n", "is empty"),
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
        ("agent:\n  epsilon: {type: log, end: 0}\n", "a log schedule needs 'k'"),
        ("agent:\n  alpha: {type: log, k: 25, end: 0}\n", "agent.alpha.end: must be in (0, 1]"),
        ("train:\n  episodes: 0\n", "train.episodes: must be at least 1"),
        ("train:\n  episodes: -5\n", "train.episodes: must be at least 1"),
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


def test_override_errors_name_the_command_line() -> None:
    with pytest.raises(ConfigError, match=r"^command line: train\.seeds"):
        load_config(overrides={"train.seeds": "x-y"})


def test_seed_lists() -> None:
    assert parse_seeds("0-3,7") == (0, 1, 2, 3, 7)
    assert parse_seeds([3, 1, 3]) == (1, 3)
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
        assert all(
            math.isfinite(x) for x in (*config.discretization.low, *config.discretization.high)
        )


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
