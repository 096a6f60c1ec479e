"""Reading YAML safely: unique keys, plain values only, and the configs the package ships.

Nothing here constructs Python objects from YAML tags: a tag other than YAML's plain ones
is an error, and so is a key given twice (YAML would keep the last silently).
"""

from __future__ import annotations

import copy
import functools
import os
from collections.abc import Iterable
from importlib import resources
from pathlib import Path
from typing import Any

import yaml

from cartpole_q.config.messages import type_name
from cartpole_q.errors import ConfigError

# libyaml's parser when PyYAML has it (ten times faster), the same safe constructors.
_SafeLoader: Any = getattr(yaml, "CSafeLoader", yaml.SafeLoader)


class UniqueKeyLoader(_SafeLoader):  # type: ignore[misc]
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


UniqueKeyLoader.add_constructor(
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
        data = yaml.load(text, Loader=UniqueKeyLoader)
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
        raise ConfigError(f"{path}: must be a mapping of keys to values, not a {type_name(data)}.")
    return data


def _yaml_mark(mark: Any) -> str:
    return "" if mark is None else f" (line {mark.line + 1}, column {mark.column + 1})"


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
    data = yaml.load(default_yaml_text(), Loader=UniqueKeyLoader)
    assert isinstance(data, dict)  # the packaged file is ours; tests check it loads
    return data
