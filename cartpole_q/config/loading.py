"""Loading a run configuration: safe YAML, merging onto the default, validation.

A config file may give only some keys; every key it leaves out takes the value of the
embedded default (``cartpole_q/default.yaml``). Loading never constructs Python objects
from YAML tags and never returns a half-checked config: it returns a frozen
:class:`Config` or raises :class:`ConfigError`, whose message names the file and field.

This module imports neither numba nor gymnasium, so that ``cartpole-q --help`` stays fast.

>>> config = load_config()
>>> config.env.id, config.discretization.bins
('CartPole-v1', (1, 1, 2, 10))
>>> load_config(overrides={"agent.alpha": "5e-4"}).agent.alpha
Schedule(kind='constant', start=0.0005, end=0.0005, rate=1.0)
"""

from __future__ import annotations

import copy
import dataclasses
import difflib
import functools
import json
import math
import os
import re
from collections.abc import Iterable, Mapping
from importlib import resources
from pathlib import Path
from types import MappingProxyType
from typing import Any

import yaml

from cartpole_q.config.schema import (
    ENGINES,
    EXACT_INTEGER,
    MAX_EPISODES,
    MAX_SEED,
    MAX_SEEDS,
    AgentConfig,
    Config,
    DiscretizationConfig,
    EnvConfig,
    EvalConfig,
    Schedule,
    TrainConfig,
)
from cartpole_q.errors import ConfigError
from cartpole_q.profiles import PhysicsRange, all_profiles, profile_for
from cartpole_q.rl.algorithm import ParamValue
from cartpole_q.rl.algorithms import algorithms
from cartpole_q.rl.algorithms import get as get_algorithm
from cartpole_q.rl.algorithms import names as algorithm_names
from cartpole_q.rl.schedules import SCHEDULE_KINDS

_NAME_PATTERN = re.compile(r"^[A-Za-z0-9_-]{1,64}$")
_NUMBER_PATTERN = re.compile(r"^[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?$")
_MISSING = object()


_SECTIONS: dict[str, type] = {
    "env": EnvConfig,
    "discretization": DiscretizationConfig,
    "agent": AgentConfig,
    "train": TrainConfig,
    "eval": EvalConfig,
}
_TOP_LEVEL_KEYS = ("name", "seed", "engine", *_SECTIONS)
_SCHEDULE_REQUIRED = {
    "constant": ("value",),
    "exponential": ("start", "decay", "end"),
    "log": ("k", "end"),
}
_SCHEDULE_KEYS = {
    "constant": ("type", "value"),
    "exponential": ("type", "start", "decay", "end"),
    "log": ("type", "k", "end", "start"),
}


ConfigSource = str | os.PathLike[str] | Mapping[str, Any]
"""What :func:`load_config` reads: a YAML file, a shipped config's name, or a mapping."""


def load_config(
    path: ConfigSource | None = None,
    overrides: Mapping[str, Any] | None = None,
    *,
    source: str | None = None,
    override_source: str | None = None,
) -> Config:
    """Load, complete and validate a config.

    Overrides merge exactly as a config file does: a section or schedule mapping merges
    key by key (``{"agent": {"gamma": 0.9}}`` keeps ``agent.alpha``; ``agent.epsilon.k``
    keeps the schedule's other fields), anything else replaces, and unknown keys are
    refused with the closest valid key suggested.

    >>> load_config("blog").name
    'blog'
    >>> load_config({"agent": {"gamma": 0.9}}, {"agent.epsilon.k": 25}).agent.epsilon
    Schedule(kind='log', start=1.0, end=0.0, rate=25.0)

    Args:
        path: a YAML file, the name of a shipped config (``"blog"``, see
            :func:`shipped_configs`), or a mapping laid out like a config file; ``None``
            loads the embedded default alone.
        overrides: dotted keys (``"train.episodes"``, ``"env.kwargs.max_episode_steps"``)
            or section names with mappings, and the values that replace the file's, as
            given on the command line; applied in order.
        source: how errors name ``path`` (default: the file, or "config mapping").
        override_source: how errors name the overrides (default: "command line"; a
            sweep names its file and point).

    Returns:
        The validated, frozen config.

    Raises:
        ConfigError: the file cannot be read or parsed, or a key or value is invalid.
    """
    raw = default_raw()
    named = "default config"
    if isinstance(path, Mapping):
        named = "config mapping"
        user: Mapping[Any, Any] = path
    elif path is not None:
        file = resolve_config_path(path)
        named = str(path) if file == Path(path) else str(file)
        user = read_yaml_mapping(file)
    else:
        user = {}
    named = source or named
    override_source = override_source or OVERRIDE_SOURCE
    check_known_keys(user, named)
    raw = _merge(raw, user)
    overridden: list[str] = []
    for dotted, value in (overrides or {}).items():
        nested = _nest(dotted, value, override_source)
        check_known_keys(nested, override_source)
        raw = _merge(raw, nested)
        overridden.extend(_leaf_paths(nested))
    raw = _without_default_grid(raw, user, overridden)
    return _Reader(raw, named, overridden, override_source).config()


OVERRIDE_SOURCE = "command line"
"""how errors name the source of an override (``--set``, ``--seed`` and the like)"""


@dataclasses.dataclass(frozen=True)
class Provenance:
    """Where a config's values came from, so that a message blames the right one.

    Checks made after loading (against the environment, say) name a field; the field's
    value came from the file, or from an override (``--set env.id=...``).

    >>> where = Provenance("blog.yaml", ("env.id", "agent.alpha"))
    >>> where.of("env.id"), where.of("discretization.bins"), where.of("agent"), str(where)
    ('command line', 'blog.yaml', 'command line', 'blog.yaml')
    """

    file: str
    """the file (or "default config", or another label) the config was loaded from"""
    overridden: tuple[str, ...] = ()
    """the dotted keys set by overrides"""
    override_source: str = OVERRIDE_SOURCE

    def of(self, field: str) -> str:
        """Who gave ``field`` (or a key inside it, or a section holding it)."""
        for key in self.overridden:
            if key == field or key.startswith(f"{field}.") or field.startswith(f"{key}."):
                return self.override_source
        return self.file

    def __str__(self) -> str:
        return self.file


def blame(source: str | Provenance, field: str) -> str:
    """The source to name in a message about ``field``.

    A plain label as it is; a :class:`Provenance`, the file or the overrides that gave it.

    >>> blame("a.yaml", "env.id"), blame(Provenance("a.yaml", ("env.id",)), "env.id")
    ('a.yaml', 'command line')
    """
    return source.of(field) if isinstance(source, Provenance) else str(source)


def _without_default_grid(
    raw: dict[str, Any], user: Mapping[Any, Any], overridden: list[str]
) -> dict[str, Any]:
    """Drop the embedded default's grid for an environment other than CartPole.

    The default's ``discretization`` describes CartPole's four dimensions. A config that
    gives no ``discretization`` (neither the file nor an override) takes it only on
    CartPole; elsewhere it has none, which Discrete and Tuple-of-Discrete observations
    need (a Box observation then asks for one, see ``inspect_env``).
    """
    given = "discretization" in user or any(
        path == "discretization" or path.startswith("discretization.") for path in overridden
    )
    env = raw.get("env")
    if given or not isinstance(env, dict) or not isinstance(env.get("id"), str):
        return raw
    if profile_for(env["id"]).default_grid:
        return raw
    return {**raw, "discretization": None}


def _nest(dotted: Any, value: Any, source: str = OVERRIDE_SOURCE) -> dict[str, Any]:
    """Turn ``("agent.epsilon.k", 5)`` into ``{"agent": {"epsilon": {"k": 5}}}``."""
    parts = dotted.split(".") if isinstance(dotted, str) else []
    if not parts or not all(parts):
        raise ConfigError(
            f"{source}: {_shown(dotted)} is not a config key; give a dotted path "
            "such as 'agent.alpha' or 'env.kwargs.max_episode_steps'."
        )
    nested: dict[str, Any] = {parts[-1]: copy.deepcopy(value)}
    for part in reversed(parts[:-1]):
        nested = {part: nested}
    return nested


def _leaf_paths(data: Mapping[Any, Any], prefix: str = "") -> list[str]:
    paths: list[str] = []
    for key, value in data.items():
        path = f"{prefix}{key}"
        if isinstance(value, Mapping) and value:
            paths.extend(_leaf_paths(value, f"{path}."))
        else:
            paths.append(path)
    return paths


_ASSIGNMENT_EXAMPLES = {
    "--set": "--set agent.alpha=5e-4 or --set discretization.bins=[1,1,6,12]",
    "--physics": "--physics length=0.75 or --physics gravity=12",
}


def parse_assignment(text: str, option: str = "--set") -> tuple[str, Any]:
    """Parse one ``--set KEY=VALUE``: the value is read as YAML (``5e-4``, ``[1, 2]``, ``true``).

    >>> parse_assignment("discretization.bins=[1, 1, 6, 12]")
    ('discretization.bins', [1, 1, 6, 12])

    Raises:
        ConfigError: there is no ``=``, the key is empty, or the value is not plain YAML.
    """
    key, equals, value = text.partition("=")
    key = key.strip()
    if not equals or not key:
        raise ConfigError(
            f"{option} {text!r}: expected KEY=VALUE, e.g. {_ASSIGNMENT_EXAMPLES.get(option, option)}."
        )
    try:
        parsed = yaml.load(value, Loader=_UniqueKeyLoader) if value.strip() else None
    except yaml.YAMLError as error:
        problem = getattr(error, "problem", None) or "invalid syntax"
        raise ConfigError(
            f"{option} {text!r}: the value is not plain YAML ({problem}); quote strings that "
            "contain ':', '#', '[' or '{'."
        ) from None
    return key, parsed


def shipped_configs() -> dict[str, str]:
    """The example configs shipped with the package: name -> one-line description.

    >>> {"blog", "default", "sutton_barto"} <= set(shipped_configs())
    True
    """
    found: dict[str, str] = {}
    for entry in sorted(_configs_dir().iterdir(), key=lambda item: item.name):
        if entry.name.endswith(".yaml"):
            text = entry.read_text(encoding="utf-8")
            found[entry.name.removesuffix(".yaml")] = _description(text)
    return found


def _configs_dir() -> Any:
    return resources.files("cartpole_q").joinpath("configs")


def _description(text: str) -> str:
    """The first comment line of a config file, without its ``#``."""
    for line in text.splitlines():
        stripped = line.strip()
        if stripped.startswith("#"):
            return stripped.lstrip("#").strip()
        if stripped:
            break
    return ""


def resolve_config_path(value: str | os.PathLike[str]) -> Path:
    """The file ``--config VALUE`` means: an existing file, else a shipped config's name.

    A value that names neither is returned as given, so that reading it reports
    "config file not found" with the shipped names.
    """
    path = Path(value)
    text = os.fspath(value)
    if path.is_file() or "/" in text or os.sep in text or path.suffix:
        return path
    shipped = _configs_dir().joinpath(f"{text}.yaml")
    return Path(str(shipped)) if shipped.is_file() else path


def default_yaml_text() -> str:
    """Return the embedded default config file's text (``cartpole_q/default.yaml``).

    ``configs/default.yaml`` (among the shipped configs) is a link to the same file.
    """
    return resources.files("cartpole_q").joinpath("default.yaml").read_text(encoding="utf-8")


def default_raw() -> dict[str, Any]:
    """Return the embedded default config as plain data (a fresh copy)."""
    return copy.deepcopy(_parsed_default())


@functools.cache
def _parsed_default() -> dict[str, Any]:
    # Parsed once per process: a sweep or a multi-seed run loads many configs.
    data = yaml.load(default_yaml_text(), Loader=_UniqueKeyLoader)
    assert isinstance(data, dict)  # the packaged file is ours; tests check it loads
    return data


# libyaml's parser when PyYAML has it (ten times faster), the same safe constructors.
_SafeLoader: Any = getattr(yaml, "CSafeLoader", yaml.SafeLoader)


class _UniqueKeyLoader(_SafeLoader):  # type: ignore[misc]
    """A safe loader that refuses duplicate mapping keys instead of keeping the last."""


def _construct_unique_mapping(loader: yaml.SafeLoader, node: yaml.MappingNode) -> dict[Any, Any]:
    seen: set[Any] = set()
    for key_node, _ in node.value:
        key = loader.construct_object(key_node)
        if isinstance(key, Iterable) and not isinstance(key, str):
            raise yaml.constructor.ConstructorError(
                None, None, "a mapping key must be a scalar", key_node.start_mark
            )
        if key in seen:
            raise yaml.constructor.ConstructorError(
                None, None, f"duplicate key {key!r}", key_node.start_mark
            )
        seen.add(key)
    return loader.construct_mapping(node)


_UniqueKeyLoader.add_constructor(
    yaml.resolver.BaseResolver.DEFAULT_MAPPING_TAG, _construct_unique_mapping
)


def read_yaml_mapping(path: Path, what: str = "config file") -> dict[str, Any]:
    """Read a YAML file that must hold a mapping, with the safe loader only.

    An empty file (or one with only comments) is the empty mapping. ``what`` names the
    kind of file in messages ("config file", "sweep file", "tune file").

    Raises:
        ConfigError: the file is missing, unreadable, not YAML, not a mapping, or uses a
            tag that would construct a Python object.
    """
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        if what != "config file":
            raise ConfigError(f"{path}: {what} not found.") from None
        names = ", ".join(shipped_configs())
        raise ConfigError(
            f"{path}: config file not found; give a YAML file or the name of a shipped "
            f"config ({names}; see `cartpole-q configs`)."
        ) from None
    except IsADirectoryError:
        raise ConfigError(f"{path}: is a directory, not a {what}.") from None
    except UnicodeDecodeError:
        raise ConfigError(f"{path}: is not a UTF-8 text file.") from None
    except OSError as error:
        raise ConfigError(f"{path}: cannot be read ({error.strerror}).") from None
    try:
        data = yaml.load(text, Loader=_UniqueKeyLoader)
    except yaml.constructor.ConstructorError as error:
        where = _yaml_mark(error.problem_mark)
        if error.problem and "could not determine a constructor" in error.problem:
            problem = (
                f"uses a YAML tag that is not allowed{where}; only plain YAML "
                "(mappings, lists, numbers, strings, booleans, null) is accepted, and "
                "nothing was executed"
            )
        else:
            problem = f"{error.problem}{where}"
        raise ConfigError(f"{path}: {problem}.") from None
    except yaml.YAMLError as error:
        mark = getattr(error, "problem_mark", None)
        problem = getattr(error, "problem", None) or "invalid syntax"
        raise ConfigError(f"{path}: is not valid YAML: {problem}{_yaml_mark(mark)}.") from None
    if data is None:
        return {}  # an empty file (or only comments) changes nothing: all defaults
    if not isinstance(data, dict):
        raise ConfigError(f"{path}: must be a mapping of keys to values, not a {_type_name(data)}.")
    return data


def _yaml_mark(mark: Any) -> str:
    return "" if mark is None else f" (line {mark.line + 1}, column {mark.column + 1})"


def check_known_keys(user: Mapping[Any, Any], source: str) -> None:
    """Refuse keys the config does not know, suggesting the closest valid one.

    Raises:
        ConfigError: naming the unknown key and, when one is close, the likely intended key.
    """
    _check_keys(user, _TOP_LEVEL_KEYS, "", source)
    for section, section_type in _SECTIONS.items():
        if section not in user or user[section] is None:
            continue
        value = user[section]
        if not isinstance(value, Mapping):
            raise ConfigError(
                f"{source}: {section}: must be a mapping of keys to values, "
                f"not a {_type_name(value)}."
            )
        names = [field.name for field in dataclasses.fields(section_type)]
        if section == "agent":  # the algorithms' own keys, instead of the params mapping
            names = [name for name in names if name != "params"] + algorithm_param_keys()
        _check_keys(value, names, f"{section}.", source)


def algorithm_param_keys() -> list[str]:
    """Every key some registered algorithm adds under ``agent`` (``n``, ``lambda``, ...)."""
    keys: dict[str, None] = {}
    for algorithm in algorithms():
        keys.update(dict.fromkeys(param.key for param in algorithm.params))
    return list(keys)


def _check_keys(data: Mapping[Any, Any], valid: Iterable[str], prefix: str, source: str) -> None:
    valid = list(valid)
    for key in data:
        if key not in valid:
            raise ConfigError(f"{source}: {_unknown_key(key, valid, prefix)}")


def _unknown_key(key: Any, valid: list[str], prefix: str) -> str:
    """The message for an unknown key, with the closest valid one when there is one."""
    close = difflib.get_close_matches(str(key), valid, n=1, cutoff=0.6)
    hint = (
        f"; did you mean '{prefix}{close[0]}'?" if close else f"; valid keys: {', '.join(valid)}."
    )
    return f"unknown key '{prefix}{key}'{hint}"


_SCHEDULE_PATHS = (("agent", "alpha"), ("agent", "epsilon"))


def _merge(
    base: Mapping[Any, Any], user: Mapping[Any, Any], path: tuple[Any, ...] = ()
) -> dict[Any, Any]:
    """Overlay ``user`` on ``base``: mappings merge key by key, other values replace.

    A section left empty (``agent:``) changes nothing, except ``discretization:``, which
    means no grid (Discrete observations). A schedule mapping merges into
    the base schedule when it keeps its ``type`` (or gives none), and replaces it when
    it names another type; a number replaces a schedule and vice versa.
    """
    merged = copy.deepcopy(dict(base))
    for key, value in user.items():
        here = (*path, key)
        old = merged.get(key)
        if not path and key in _SECTIONS and value is None and key != "discretization":
            continue  # (an explicit `discretization: null` means no grid)
        if isinstance(value, Mapping) and isinstance(old, Mapping) and _merges(here, old, value):
            merged[key] = _merge(old, value, here)
        else:
            merged[key] = copy.deepcopy(value)
    return merged


def _merges(path: tuple[Any, ...], old: Mapping[Any, Any], new: Mapping[Any, Any]) -> bool:
    if path in _SCHEDULE_PATHS:
        return "type" not in new or new["type"] == old.get("type")
    return True


class _Reader:
    """Typed, range-checked access to the merged raw mapping, with precise error messages."""

    def __init__(
        self,
        raw: dict[str, Any],
        source: str,
        overridden: list[str],
        override_source: str = OVERRIDE_SOURCE,
    ) -> None:
        self._raw = raw
        self._source = source
        self._overridden = overridden
        self._override_source = override_source

    def source_of(self, field: str) -> str:
        """The command line if an override set ``field`` (or a part of it), else the file."""
        for path in self._overridden:
            if (
                path == field
                or field.startswith((f"{path}.", f"{path}["))
                or path.startswith(f"{field}.")
            ):
                return self._override_source
        return self._source

    def error(self, field: str, problem: str) -> ConfigError:
        return ConfigError(f"{self.source_of(field)}: {field}: {problem}")

    def _value(self, field: str) -> Any:
        section, _, key = field.rpartition(".")
        return (self._raw[section] if section else self._raw)[key]

    # -- scalar readers ---------------------------------------------------------------

    def number(
        self,
        field: str,
        value: Any = _MISSING,
        *,
        low: float = -math.inf,
        high: float = math.inf,
        low_open: bool = False,
        interval: str = "",
    ) -> float:
        value = self._value(field) if value is _MISSING else value
        number = _as_number(value)
        if number is None:
            raise self.error(field, f"must be a number, got {_shown(value)}.")
        if not math.isfinite(number):
            raise self.error(field, f"must be a finite number, got {_shown(value)}.")
        too_low = number <= low if low_open else number < low
        if too_low or number > high:
            raise self.error(field, f"must be in {interval}, got {_shown(value)}.")
        return number

    def integer(self, field: str, *, minimum: int, maximum: int | None = None) -> int:
        return self.integer_value(field, self._value(field), minimum=minimum, maximum=maximum)

    def integer_value(
        self, field: str, value: Any, *, minimum: float | None, maximum: float | None = None
    ) -> int:
        number = _as_number(value)
        if number is None or not math.isfinite(number) or number != int(number):
            raise self.error(field, f"must be an integer, got {_shown(value)}.")
        if not isinstance(value, int) and abs(number) >= EXACT_INTEGER:
            raise self.error(
                field, f"must be an integer written out in digits, got {_shown(value)}."
            )
        integer = int(value) if isinstance(value, int) else int(number)
        if minimum is not None and integer < minimum:
            raise self.error(field, f"must be at least {int(minimum)}, got {integer}.")
        if maximum is not None and integer > maximum:
            raise self.error(field, f"must be at most {int(maximum)}, got {integer}.")
        return integer

    def boolean(self, field: str) -> bool:
        value = self._value(field)
        if not isinstance(value, bool):
            raise self.error(field, f"must be true or false, got {_shown(value)}.")
        return value

    def string(self, field: str) -> str:
        value = self._value(field)
        if not isinstance(value, str) or not value:
            raise self.error(field, f"must be a non-empty string, got {_shown(value)}.")
        return value

    def choice(self, field: str, choices: tuple[str, ...]) -> str:
        value = self._value(field)
        if value not in choices:
            raise self.error(field, f"must be one of {', '.join(choices)}; got {_shown(value)}.")
        return str(value)

    # -- composite readers ------------------------------------------------------------

    def number_list(self, field: str) -> tuple[float, ...]:
        values = self._value(field)
        if not isinstance(values, list) or not values:
            raise self.error(field, f"must be a non-empty list of numbers, got {_shown(values)}.")
        return tuple(self.number(f"{field}[{i}]", v) for i, v in enumerate(values))

    def bins(self, field: str) -> tuple[int, ...]:
        values = self._value(field)
        if not isinstance(values, list) or not values:
            raise self.error(
                field, f"must be a non-empty list of positive integers, got {_shown(values)}."
            )
        result = []
        for i, value in enumerate(values):
            number = _as_number(value)
            if number is None or not math.isfinite(number) or number != int(number):
                raise self.error(
                    field, f"entry {i} must be a positive integer, got {_shown(value)}."
                )
            if number < 1:
                raise self.error(field, f"entry {i} must be at least 1, got {_shown(value)}.")
            result.append(int(number))
        return tuple(result)

    def schedule(self, field: str, *, low: float, low_open: bool, interval: str) -> Schedule:
        value = self._value(field)
        bounded = {"low": low, "high": 1.0, "low_open": low_open, "interval": interval}
        if not isinstance(value, dict):
            constant = self.number(field, value, **bounded)  # type: ignore[arg-type]
            return Schedule("constant", constant, constant)
        kind = value.get("type")
        if kind is None:
            raise self.error(
                field,
                f"a schedule mapping needs 'type' ({', '.join(SCHEDULE_KINDS)}), got "
                f"{_shown(value)}; a number is a constant.",
            )
        if kind not in SCHEDULE_KINDS:
            raise self.error(
                f"{field}.type",
                f"must be one of {', '.join(SCHEDULE_KINDS)}; got {_shown(kind)}.",
            )
        keys = _SCHEDULE_KEYS[kind]
        for key in value:
            if key not in keys:
                raise ConfigError(
                    f"{self.source_of(field)}: {_unknown_key(key, list(keys), f'{field}.')}"
                )
        for key in _SCHEDULE_REQUIRED[kind]:
            if key not in value:
                raise self.error(field, f"a {kind} schedule needs '{key}'.")
        if kind == "constant":
            constant = self.number(f"{field}.value", value["value"], **bounded)  # type: ignore[arg-type]
            return Schedule("constant", constant, constant)
        end = self.number(f"{field}.end", value["end"], **bounded)  # type: ignore[arg-type]
        if kind == "exponential":
            start = self.number(f"{field}.start", value["start"], **bounded)  # type: ignore[arg-type]
            decay = self.number(
                f"{field}.decay",
                value["decay"],
                low=0.0,
                high=1.0,
                low_open=True,
                interval="(0, 1]",
            )
            return Schedule("exponential", start, end, decay)
        start = self.number(f"{field}.start", value.get("start", 1.0), **bounded)  # type: ignore[arg-type]
        k = self.number(f"{field}.k", value["k"], low=0.0, low_open=True, interval="(0, inf)")
        return Schedule("log", start, end, k)

    def seeds(self, field: str) -> tuple[int, ...] | None:
        value = self._value(field)
        if value is None:
            return None
        try:
            seeds = parse_seeds(value)
        except ValueError as error:
            raise self.error(field, str(error)) from None
        return seeds

    def kwargs(self, field: str) -> Mapping[str, Any]:
        value = self._value(field)
        if value is None:
            return MappingProxyType({})
        if not isinstance(value, dict) or not all(isinstance(key, str) for key in value):
            raise self.error(
                field, f"must be a mapping of argument names to values, got {_shown(value)}."
            )
        steps = value.get("max_episode_steps")
        if "max_episode_steps" in value and (
            isinstance(steps, bool) or not isinstance(steps, int) or steps < 1
        ):
            raise self.error(
                f"{field}.max_episode_steps",
                f"the time limit must be a positive whole number of steps, got {_shown(steps)}.",
            )
        return MappingProxyType(copy.deepcopy(value))

    # -- the whole config -------------------------------------------------------------

    def config(self) -> Config:
        raw = self._raw
        for section in _SECTIONS:
            if section == "discretization" and raw.get(section) is None:
                continue  # no grid: Discrete observations (checked against the env later)
            if not isinstance(raw.get(section), dict):
                raise self.error(section, "must be a mapping of keys to values.")
        name = self.string("name")
        if not _NAME_PATTERN.fullmatch(name):
            raise self.error(
                "name",
                f"must be 1-64 letters, digits, '-' or '_' (it names a directory; no path "
                f"separators or '..'), got {_shown(name)}.",
            )
        discretization = self._discretization()
        return Config(
            name=name,
            seed=self.integer("seed", minimum=0, maximum=MAX_SEED),
            engine=self.choice("engine", ENGINES),
            env=self._env(),
            discretization=discretization,
            agent=AgentConfig(
                algorithm=self.choice("agent.algorithm", algorithm_names()),
                gamma=self.number("agent.gamma", low=0.0, high=1.0, interval="[0, 1]"),
                alpha=self.schedule("agent.alpha", low=0.0, low_open=True, interval="(0, 1]"),
                epsilon=self.schedule("agent.epsilon", low=0.0, low_open=False, interval="[0, 1]"),
                q_init=self.number("agent.q_init"),
                max_q_table_bytes=self.integer("agent.max_q_table_bytes", minimum=1),
                params=self._algorithm_params(),
            ),
            train=TrainConfig(
                episodes=self.integer("train.episodes", minimum=1, maximum=MAX_EPISODES),
                seeds=self.seeds("train.seeds"),
                stop_when_solved=self.boolean("train.stop_when_solved"),
                reward_threshold=(
                    None
                    if raw["train"]["reward_threshold"] is None
                    else self.number("train.reward_threshold")
                ),
                eval_every=self.integer("train.eval_every", minimum=0),
                eval_episodes=self.integer("train.eval_episodes", minimum=1, maximum=MAX_EPISODES),
                checkpoint_every=self.integer("train.checkpoint_every", minimum=0),
            ),
            eval=EvalConfig(
                episodes=self.integer("eval.episodes", minimum=1, maximum=MAX_EPISODES),
                seed=self.integer("eval.seed", minimum=0, maximum=MAX_SEED),
            ),
        )

    def _algorithm_params(self) -> Mapping[str, ParamValue]:
        """The chosen algorithm's own keys, defaults filled; other algorithms' keys ignored.

        A key of another algorithm does not apply to this one (a sweep or a study may vary
        ``agent.algorithm`` over a base that sets ``agent.lambda``), so it is left out of the
        config; a key of no algorithm was refused as unknown already.
        """
        algorithm = get_algorithm(self.string("agent.algorithm"))
        agent = self._raw["agent"]
        values: dict[str, ParamValue] = {}
        for param in algorithm.params:
            field = f"agent.{param.key}"
            value = agent.get(param.key, param.default)
            if param.kind == "choice":
                values[param.key] = self.choice_value(field, value, param.choices)
            elif param.kind == "int":
                values[param.key] = self.integer_value(
                    field, value, minimum=param.low, maximum=param.high
                )
            else:
                values[param.key] = self.number(
                    field, value, low=-math.inf if param.low is None else param.low,
                    high=math.inf if param.high is None else param.high,
                    low_open=param.low_open, interval=param.interval,
                )  # fmt: skip
        return MappingProxyType(values)

    def _env(self) -> EnvConfig:
        env_id = self.string("env.id")
        physics = self._physics(env_id)
        randomize = self._randomize(env_id)
        return EnvConfig(
            id=env_id, kwargs=self.kwargs("env.kwargs"), physics=physics, randomize=randomize
        )

    def _physics_mapping(self, field: str, env_id: str, kind: str) -> tuple[dict[str, Any], Any]:
        """The raw ``env.physics`` or ``env.randomize`` mapping, and the env's physics."""
        value = self._value(field)
        if value is None or value == {}:
            return {}, None
        if not isinstance(value, dict):
            raise self.error(field, f"must be a mapping of keys to values, got {_shown(value)}.")
        physics = profile_for(env_id).physics
        if physics is None:
            with_physics = [p.ids[0] for p in all_profiles() if p.physics is not None]
            raise self.error(
                field,
                f"applies to environments with physics to set ({', '.join(with_physics)}), but "
                f"env.id is {env_id!r}.",
            )
        keys = physics.keys if kind == "physics" else physics.randomizable
        for key in value:
            if key not in keys:
                raise ConfigError(
                    f"{self.source_of(field)}: {_unknown_key(key, list(keys), f'{field}.')}"
                )
        return value, physics

    def _physics(self, env_id: str) -> Mapping[str, float | str]:
        value, spec = self._physics_mapping("env.physics", env_id, "physics")
        physics: dict[str, float | str] = {}
        for key in spec.keys if spec is not None else ():  # canonical order
            if key not in value:
                continue
            field = f"env.physics.{key}"
            if key in spec.choices:
                physics[key] = self.choice_value(field, value[key], spec.choices[key])
            else:
                physics[key] = self.number(field, value[key], **_bounds(spec.ranges[key]))
        return MappingProxyType(physics)

    def _randomize(self, env_id: str) -> Mapping[str, tuple[float, float]]:
        value, spec = self._physics_mapping("env.randomize", env_id, "randomize")
        ranges: dict[str, tuple[float, float]] = {}
        for key in spec.randomizable if spec is not None else ():  # the order of the draws
            if key not in value:
                continue
            field = f"env.randomize.{key}"
            pair = value[key]
            if not isinstance(pair, list) or len(pair) != 2:
                raise self.error(field, f"must be [low, high], got {_shown(pair)}.")
            low = self.number(f"{field}[0]", pair[0], **_bounds(spec.ranges[key]))
            high = self.number(f"{field}[1]", pair[1], **_bounds(spec.ranges[key]))
            if low > high:
                raise self.error(field, f"low ({low}) must not be above high ({high}).")
            ranges[key] = (low, high)
        return MappingProxyType(ranges)

    def choice_value(self, field: str, value: Any, choices: tuple[str, ...]) -> str:
        if value not in choices:
            raise self.error(field, f"must be one of {', '.join(choices)}; got {_shown(value)}.")
        return str(value)

    def _discretization(self) -> DiscretizationConfig | None:
        if self._raw["discretization"] is None:
            return None
        bins = self.bins("discretization.bins")
        low = self.number_list("discretization.low")
        high = self.number_list("discretization.high")
        for field, values in (("discretization.low", low), ("discretization.high", high)):
            if len(values) != len(bins):
                raise self.error(
                    field,
                    f"has {len(values)} entries but discretization.bins has {len(bins)}; "
                    "give one per observation dimension.",
                )
        for d, (lo, hi) in enumerate(zip(low, high, strict=True)):
            if not lo < hi:
                raise self.error(
                    "discretization.low",
                    f"entry {d} ({lo}) must be below discretization.high entry {d} ({hi}).",
                )
        return DiscretizationConfig(bins=bins, low=low, high=high)


def _bounds(allowed: PhysicsRange) -> dict[str, Any]:
    """The :meth:`_Reader.number` bounds of a physics key (its profile's range)."""
    return {
        "low": allowed.low, "low_open": allowed.low_open, "high": allowed.high,
        "interval": allowed.interval,
    }  # fmt: skip


def config_differences(old: Config, new: Config) -> list[tuple[str, Any, Any]]:
    """The dotted keys whose values differ between two configs, in file order.

    A key present in only one of them (inside ``env.kwargs``) has the value
    :data:`NOT_SET` in the other.

    >>> config_differences(load_config(), load_config(overrides={"agent.gamma": 0.9}))
    [('agent.gamma', 0.995, 0.9)]
    """
    return mapping_differences(old.to_dict(), new.to_dict())


def mapping_differences(old: Any, new: Any) -> list[tuple[str, Any, Any]]:
    """The dotted keys whose values differ between two nested mappings, in key order.

    >>> mapping_differences({"a": {"b": 1, "c": 2}}, {"a": {"b": 1, "c": 3}, "d": 4})
    [('a.c', 2, 3), ('d', '(not set)', 4)]
    """
    return _differences(old, new, "")


NOT_SET = "(not set)"
"""stands for a key that one of two compared configs does not have"""


def shown_value(value: Any) -> str:
    """A config value as a message shows it: 0.995, [1, 1, 2, 10], "CartPole-v1", null.

    >>> shown_value([1, 2]), shown_value("sarsa"), shown_value(None), shown_value(NOT_SET)
    ('[1, 2]', '"sarsa"', 'null', '(not set)')
    """
    if value is NOT_SET:
        return str(value)
    return json.dumps(value, default=str)


def _differences(old: Any, new: Any, prefix: str) -> list[tuple[str, Any, Any]]:
    if isinstance(old, dict) and isinstance(new, dict):
        found: list[tuple[str, Any, Any]] = []
        for key in dict.fromkeys([*old, *new]):
            found.extend(
                _differences(old.get(key, NOT_SET), new.get(key, NOT_SET), f"{prefix}{key}.")
            )
        return found
    if old == new and type(old) is type(new):
        return []
    return [(prefix.removesuffix("."), old, new)]


def parse_seeds(value: Any) -> tuple[int, ...]:
    """Parse a seed list: an integer, a list of integers, or a string like ``"0-9,20"``.

    Returns:
        The distinct seeds in ascending order.

    Raises:
        ValueError: the value is not a seed list, a seed is negative, or there are too many.

    >>> parse_seeds("0-3,7")
    (0, 1, 2, 3, 7)
    """
    seeds: list[int] = []
    if isinstance(value, bool):
        raise ValueError(f"must be seeds like '0-99' or [0, 1, 2], got {_shown(value)}.")
    if isinstance(value, int):
        seeds = [value]
    elif isinstance(value, list) and value:
        for item in value:
            if isinstance(item, bool) or not isinstance(item, int):
                raise ValueError(f"every seed must be an integer, got {_shown(item)}.")
            seeds.append(item)
    elif isinstance(value, str) and value.strip():
        for part in value.split(","):
            match = re.fullmatch(r"\s*(\d+)\s*(?:-\s*(\d+)\s*)?", part)
            if not match:
                raise ValueError(f"must be seeds like '0-99' or '0,5,10-19', got {_shown(value)}.")
            first, last = int(match[1]), int(match[2] or match[1])
            if last < first:
                raise ValueError(f"range '{part.strip()}' runs backwards.")
            if last - first >= MAX_SEEDS:
                raise ValueError(f"at most {MAX_SEEDS} seeds, got range '{part.strip()}'.")
            seeds.extend(range(first, last + 1))
    else:
        raise ValueError(f"must be seeds like '0-99' or [0, 1, 2], got {_shown(value)}.")
    if any(seed < 0 for seed in seeds):
        raise ValueError("seeds must be non-negative.")
    if any(seed > MAX_SEED for seed in seeds):
        raise ValueError(f"seeds must be at most {MAX_SEED:,}.")
    unique = sorted(set(seeds))
    if len(unique) > MAX_SEEDS:
        raise ValueError(f"at most {MAX_SEEDS} seeds, got {len(unique)}.")
    return tuple(unique)


def _as_number(value: Any) -> float | None:
    """Return ``value`` as a float if it is a number or a numeric string like ``5e-4``."""
    if isinstance(value, bool):
        return None
    if isinstance(value, int | float):
        return float(value)
    if isinstance(value, str) and _NUMBER_PATTERN.fullmatch(value.strip()):
        return float(value)
    return None


def _type_name(value: Any) -> str:
    return {list: "list", str: "string", int: "number", float: "number", bool: "boolean"}.get(
        type(value), type(value).__name__
    )


def _shown(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."
