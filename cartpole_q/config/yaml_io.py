"""Reading YAML safely: unique keys, plain values only, bounded, and the configs the package ships.

Nothing here constructs Python objects from YAML tags: a tag other than YAML's plain ones
is an error, and so is a key given twice (YAML would keep the last silently).

Every YAML text is bounded before it is used: a file larger than :data:`MAX_YAML_BYTES` is
not read, and a document is refused when it holds more than :data:`MAX_YAML_VALUES` values
once its aliases (``*name``) are expanded, nests deeper than :data:`MAX_YAML_DEPTH`, or
refers to itself. Aliases stay usable (a sweep file may repeat a schedule with ``*name``);
a few hundred bytes of nested aliases ("a billion laughs") may not become millions of
values that every later step (merging, validation, an error message) would walk.
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

from cartpole_q.config.messages import shown, type_name
from cartpole_q.errors import ConfigError

# libyaml's parser when PyYAML has it (ten times faster), the same safe constructors.
_SafeLoader: Any = getattr(yaml, "CSafeLoader", yaml.SafeLoader)

MAX_YAML_BYTES = 256 * 1024
"""the largest config, sweep or tune file read (the shipped ones are under 4 KiB)"""
MAX_YAML_VALUES = 100_000
"""the most values (scalars, lists and mappings) a YAML document may hold, aliases expanded"""
MAX_YAML_DEPTH = 64
"""the deepest a YAML document may nest lists and mappings (a config nests four levels)"""


class YamlLimitError(yaml.YAMLError):
    """A YAML document beyond the bounds above; its message says which one."""


class UniqueKeyLoader(_SafeLoader):  # type: ignore[misc]
    """A safe loader that refuses duplicate mapping keys, and documents beyond the bounds.

    The bounds are checked on the composed node graph, before any value is constructed:
    PyYAML shares an anchored node between its aliases, so counting each node once per
    path that reaches it (memoised per node) measures the expansion without making it.
    """

    def get_single_data(self) -> Any:
        """The document's value, once its node graph is known to be within the bounds."""
        node = self.get_single_node()
        if node is None:
            return None
        check_yaml_bounds(node)
        return self.construct_document(node)


def check_yaml_bounds(root: yaml.Node) -> None:
    """Refuse a node graph that expands beyond :data:`MAX_YAML_VALUES` or nests too deep.

    Iterative, so that the check itself cannot run out of stack on what it refuses.

    Raises:
        YamlLimitError: too many values once aliases are expanded, too deep, or an alias
            inside the value it names (a document that contains itself).
    """
    expanded: dict[int, int] = {}  # id(node) -> values in its expansion, once finished
    open_nodes: set[int] = set()  # the nodes whose expansion is in progress: the path
    stack: list[tuple[yaml.Node, int, bool]] = [(root, 1, False)]
    while stack:
        node, depth, finished = stack.pop()
        children = _children(node)
        if finished:
            open_nodes.discard(id(node))
            total = 1 + sum(expanded[id(child)] for child in children)
            if total > MAX_YAML_VALUES:
                raise YamlLimitError(
                    f"holds more than {MAX_YAML_VALUES:,} values once its aliases (*name) are "
                    f"expanded{_yaml_mark(node.start_mark)}; write the values out, or use fewer "
                    "nested aliases"
                    if len(expanded) < MAX_YAML_VALUES
                    else f"holds more than {MAX_YAML_VALUES:,} values; a config needs far fewer"
                )
            expanded[id(node)] = total
            continue
        if id(node) in expanded:
            continue
        if id(node) in open_nodes:
            raise YamlLimitError(
                f"has an alias inside the value it names{_yaml_mark(node.start_mark)}, so the "
                "value would contain itself"
            )
        if depth > MAX_YAML_DEPTH:
            raise YamlLimitError(
                f"nests lists and mappings more than {MAX_YAML_DEPTH} levels "
                f"deep{_yaml_mark(node.start_mark)}"
            )
        open_nodes.add(id(node))
        stack.append((node, depth, True))
        stack.extend((child, depth + 1, False) for child in children)


def _children(node: yaml.Node) -> list[yaml.Node]:
    if isinstance(node, yaml.SequenceNode):
        return list(node.value)
    if isinstance(node, yaml.MappingNode):
        return [part for pair in node.value for part in pair]
    return []


def load_yaml_text(text: str) -> Any:
    """Parse YAML text with the safe, bounded loader (the one parser of every YAML input).

    Raises:
        yaml.YAMLError: not YAML, a tag that would construct an object, a duplicate key,
            or beyond the bounds (:class:`YamlLimitError`).
    """
    if not text.isascii():
        try:
            text.encode("utf-8")
        except UnicodeEncodeError as error:  # bytes the locale could not decode, as surrogates
            raise NotTextError(error.start) from None
    return yaml.load(text, Loader=UniqueKeyLoader)


class NotTextError(yaml.YAMLError):
    r"""The input holds bytes that are not UTF-8 (a shell's ``$'\xff'``): YAML is text."""

    def __init__(self, position: int) -> None:
        self.problem = f"not UTF-8 text: character {position + 1} is a byte no text decodes to"
        super().__init__(self.problem)


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
                None, None, f"duplicate key {shown(key)}", key_node.start_mark
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
        ConfigError: the file is missing, unreadable, larger than :data:`MAX_YAML_BYTES`,
            not YAML, not a mapping, beyond the bounds on values and nesting, or uses a tag
            that would construct a Python object.
    """
    try:
        with path.open("rb") as stream:
            # At most one byte more than the limit: a huge file (or an endless one, such
            # as a device) is refused without reading it whole.
            content = stream.read(MAX_YAML_BYTES + 1)
        if len(content) > MAX_YAML_BYTES:
            raise ConfigError(
                f"{path}: is larger than {MAX_YAML_BYTES // 1024} KiB, the most a {what} may "
                "be (the shipped ones are a few KiB); is this the file you meant?"
            )
        text = content.decode("utf-8")
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
        data = load_yaml_text(text)
    except YamlLimitError as error:
        raise ConfigError(f"{path}: {error}.") from None
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
    data = load_yaml_text(default_yaml_text())
    assert isinstance(data, dict)  # the packaged file is ours; tests check it loads
    return data
