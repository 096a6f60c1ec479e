"""Overrides and merging: ``--set KEY=VALUE``, dotted keys, and laying a file over the default.

A file, a mapping and the command line's overrides all merge the same way, by the schema's
fields: a section or a schedule mapping merges key by key, anything else replaces. Keys the
schema does not know are refused here, before anything is read.
"""

from __future__ import annotations

import copy
import dataclasses
import functools
from collections.abc import Iterable, Mapping
from typing import Any

import yaml

from cartpole_q.config.messages import shown, type_name, unknown_key
from cartpole_q.config.schema import Config, key_of, sections
from cartpole_q.config.yaml_io import NotTextError, YamlLimitError, load_yaml_text
from cartpole_q.errors import ConfigError
from cartpole_q.rl.algorithms import algorithms

OVERRIDE_SOURCE = "overrides"
"""how errors name overrides by default: the ``overrides`` argument of the Python API's
:func:`~cartpole_q.config.load_config` (the command line passes :data:`COMMAND_LINE`)"""
COMMAND_LINE = "command line"
"""how errors name the command line's overrides (``--set``, ``--seed`` and the like)"""


@dataclasses.dataclass(frozen=True)
class Provenance:
    """Where a config's values came from, so that a message blames the right one.

    Checks made after loading (against the environment, say) name a field; the field's
    value came from the file, or from an override (``--set env.id=...``).

    >>> where = Provenance("blog.yaml", ("env.id", "agent.alpha"), COMMAND_LINE)
    >>> where.of("env.id"), where.of("discretization.bins"), where.of("agent"), str(where)
    ('command line', 'blog.yaml', 'command line', 'blog.yaml')
    """

    file: str
    """the file (or "default config", or another label) the config was loaded from"""
    overridden: tuple[str, ...] = ()
    """the dotted keys set by overrides"""
    override_source: str = OVERRIDE_SOURCE

    def of(self, field: str) -> str:
        """Who gave ``field`` (or a key or an entry inside it, or a section holding it)."""
        for key in self.overridden:
            if (
                key == field
                or key.startswith(f"{field}.")
                or field.startswith((f"{key}.", f"{key}["))
            ):
                return self.override_source
        return self.file

    def __str__(self) -> str:
        return self.file


def blame(source: str | Provenance, field: str) -> str:
    """The source to name in a message about ``field``.

    A plain label as it is; a :class:`Provenance`, the file or the overrides that gave it.

    >>> blame("a.yaml", "env.id"), blame(Provenance("a.yaml", ("env.id",)), "env.id")
    ('a.yaml', 'overrides')
    """
    return source.of(field) if isinstance(source, Provenance) else str(source)


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
            f"{option} {shown(text)}: expected KEY=VALUE, e.g. {_ASSIGNMENT_EXAMPLES.get(option, option)}."
        )
    try:
        parsed = load_yaml_text(value) if value.strip() else None
    except YamlLimitError as error:
        raise ConfigError(f"{option} {shown(text)}: the value {error}.") from None
    except NotTextError as error:
        raise ConfigError(f"{option} {shown(text)}: the value is {error.problem}.") from None
    except yaml.YAMLError as error:
        problem = getattr(error, "problem", None) or "invalid syntax"
        raise ConfigError(
            f"{option} {shown(text)}: the value is not plain YAML ({problem}); quote strings "
            "that contain ':', '#', '[' or '{'."
        ) from None
    return key, parsed


def nest(dotted: Any, value: Any, source: str = OVERRIDE_SOURCE) -> dict[str, Any]:
    """Turn ``("agent.epsilon.k", 5)`` into ``{"agent": {"epsilon": {"k": 5}}}``.

    Raises:
        ConfigError: ``dotted`` is not a dotted path (``agent..gamma``, a number).
    """
    parts = dotted.split(".") if isinstance(dotted, str) else []
    if not parts or not all(parts):
        raise ConfigError(
            f"{source}: {shown(dotted)} is not a config key; give a dotted path "
            "such as 'agent.alpha' or 'env.kwargs.max_episode_steps'."
        )
    nested: dict[str, Any] = {parts[-1]: copy.deepcopy(value)}
    for part in reversed(parts[:-1]):
        nested = {part: nested}
    return nested


def leaf_paths(data: Mapping[Any, Any], prefix: str = "") -> list[str]:
    """The dotted paths of the values a nested mapping sets (an empty mapping is a value)."""
    paths: list[str] = []
    for key, value in data.items():
        path = f"{prefix}{key}"
        if isinstance(value, Mapping) and value:
            paths.extend(leaf_paths(value, f"{path}."))
        else:
            paths.append(path)
    return paths


def check_known_keys(user: Mapping[Any, Any], source: str) -> None:
    """Refuse keys the config does not know, suggesting the closest valid one.

    Raises:
        ConfigError: naming the unknown key and, when one is close, the likely intended key.
    """
    _check_keys(user, [item.name for item in dataclasses.fields(Config)], "", source)
    for section, section_type in sections().items():
        if section not in user or user[section] is None:
            continue
        value = user[section]
        if not isinstance(value, Mapping):
            raise ConfigError(
                f"{source}: {section}: must be a mapping of keys to values, "
                f"not a {type_name(value)}."
            )
        names: list[str] = []
        params: list[str] = []
        for item in dataclasses.fields(section_type):
            if key_of(item).kind == "params":
                params = algorithm_param_keys()  # the keys, not the field, are in files
            else:
                names.append(item.name)
        _check_keys(value, names + params, f"{section}.", source)


STUDY_FILE_KEYS = ("kind", "base", "grid", "zip", "testbed", "curves", "panels", "scales",
                   "branching", "figure", "book")  # fmt: skip
"""keys of study files that no config has: a file holding one is a study, not a config"""
TUNE_FILE_KEYS = ("trials", "space", "objective")
"""keys of tune files that no config has"""


def refuse_study_file(user: Mapping[Any, Any], source: str) -> None:
    """Refuse a study or tune file given as a config, naming the command that runs it.

    Raises:
        ConfigError: the mapping has a key only study (or tune) files have.
    """
    if not isinstance(user, Mapping):
        return
    found = next((key for key in user if key in TUNE_FILE_KEYS), None)
    if found is not None:
        raise ConfigError(
            f"{source}: is a tune file, not a config (it has `{found}`): run it with "
            f"`cartpole-q tune {source}`."
        )
    found = next((key for key in user if key in STUDY_FILE_KEYS), None)
    if found is not None:
        kind = user.get("kind", "sweep")
        raise ConfigError(
            f"{source}: is a study file ({'kind: ' + str(kind) if 'kind' in user else 'a sweep'}),"
            f" not a config (it has `{found}`): run it with `cartpole-q study {source}`."
        )


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
            raise ConfigError(f"{source}: {unknown_key(key, valid, prefix)}")


def merge(
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
        if not path and value is None and key in _sections_that_ignore_null():
            continue  # (an explicit `discretization: null` means no grid)
        if isinstance(value, Mapping) and isinstance(old, Mapping) and _merges(here, old, value):
            merged[key] = merge(old, value, here)
        else:
            merged[key] = copy.deepcopy(value)
    return merged


@functools.cache
def _sections_that_ignore_null() -> frozenset[str]:
    """The sections for which ``null`` changes nothing: all but those where it is a value."""
    return frozenset(
        item.name
        for item in dataclasses.fields(Config)
        if key_of(item).kind == "section" and not key_of(item).nullable
    )


def _merges(path: tuple[Any, ...], old: Mapping[Any, Any], new: Mapping[Any, Any]) -> bool:
    if path in _schedule_paths():
        return "type" not in new or new["type"] == old.get("type")
    return True


@functools.cache
def _schedule_paths() -> frozenset[tuple[str, str]]:
    """The schedule keys' paths: ``("agent", "alpha")``, ``("agent", "epsilon")``."""
    return frozenset(
        (section, item.name)
        for section, section_type in sections().items()
        for item in dataclasses.fields(section_type)
        if key_of(item).kind == "schedule"
    )
