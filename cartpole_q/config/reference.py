"""The config reference of docs/reference/configuration.md, generated: ``python -m cartpole_q.config.reference``.

One row per key, in file order: its name, its value in the embedded default
(``default.yaml``) and its :class:`~cartpole_q.config.schema.Key` doc, with the ranges and
choices the validation uses. The registries fill in what the schema cannot know: the
algorithms' names and their own keys (from their :class:`~cartpole_q.rl.algorithm.Param`
declarations), and the physics each environment's profile allows. It documents what is
registered, so a fresh process prints the package's own; docs/reference/configuration.md's table
is that output, and a test fails when they differ.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterable, Iterator
from typing import Any

import yaml

from cartpole_q.config.schema import Config, Key, key_of, sections
from cartpole_q.config.yaml_io import default_raw
from cartpole_q.families import all_profiles
from cartpole_q.rl.algorithm import Param
from cartpole_q.rl.algorithms import algorithms
from cartpole_q.rl.algorithms import names as algorithm_names

HEADER = "| key | default | meaning |\n| --- | --- | --- |\n"
"""the table's first two lines (the reference test finds the table by them)"""


def reference_table() -> str:
    """The Markdown table of every config key: name, default and meaning.

    >>> print(reference_table().splitlines()[4])
    | `engine` | `auto` | `auto`, `numba` or `gymnasium`; `auto` is `numba` where the environment has a compiled twin |
    """
    return HEADER + "".join(f"{row}\n" for row in _rows(Config, "", default_raw()))


def _rows(record: type, prefix: str, defaults: dict[str, Any]) -> Iterator[str]:
    for item in dataclasses.fields(record):
        key, path = key_of(item), f"{prefix}{item.name}"
        if key.kind == "params":
            yield from _param_rows(prefix)
        elif key.kind == "section":
            if key.doc:
                yield _row(path, "(below)", _meaning(key))
            yield from _rows(sections()[item.name], f"{path}.", defaults[item.name])
        else:
            yield _row(path, f"`{_inline(defaults[item.name])}`", _meaning(key))


def _param_rows(prefix: str) -> Iterator[str]:
    """A row per key an algorithm adds (``agent.n``), naming the algorithms that have it.

    Algorithms that declare the same parameter (``agent.lambda`` of the trace methods)
    share a row.
    """
    owners: dict[Param, list[str]] = {}
    for algorithm in algorithms():
        for param in algorithm.params:
            owners.setdefault(param, []).append(algorithm.name)
    for param, names in owners.items():
        meaning = f"{param.doc} ({param.interval}; {_either(names)} only)"
        yield _row(f"{prefix}{param.key}", f"`{_inline(param.default)}`", meaning)


def _meaning(key: Key) -> str:
    choices = algorithm_names() if key.kind == "algorithm" else key.choices
    meaning = key.doc.replace("{interval}", key.interval).replace("{choices}", _either(choices))
    if key.kind == "physics":
        meaning += "".join(f" {name}: {keys}." for name, keys in _physics_keys())
    elif key.kind == "randomize":
        meaning += "".join(f" {name}: {keys}." for name, keys in _randomizable_keys())
    return meaning


def _physics_keys() -> Iterator[tuple[str, str]]:
    """Each profile with physics and its keys' ranges (and why they are what they are)."""
    for profile in all_profiles():
        if profile.physics is not None:
            physics = profile.physics
            keys = [f"`{key}` {allowed.interval}" for key, allowed in physics.ranges.items()]
            keys += [f"`{key}` {_either(values)}" for key, values in physics.choices.items()]
            notes = f"; {physics.notes}" if physics.notes else ""
            yield profile.name, f"{', '.join(keys)}{notes}"


def _randomizable_keys() -> Iterator[tuple[str, str]]:
    for profile in all_profiles():
        if profile.physics is not None and profile.physics.randomizable:
            yield profile.name, ", ".join(f"`{key}`" for key in profile.physics.randomizable)


def _row(path: str, default: str, meaning: str) -> str:
    return f"| `{path}` | {default} | {meaning} |"


def _either(values: Iterable[str]) -> str:
    """```a```, ```b``` or ```c```."""
    quoted = [f"`{value}`" for value in values]
    return ", ".join(quoted[:-1]) + f" or {quoted[-1]}" if len(quoted) > 1 else "".join(quoted)


def _inline(value: Any) -> str:
    """A value as YAML writes it on one line: ``[1, 1, 2, 10]``, ``{type: log, k: 9}``."""
    text = yaml.safe_dump(value, default_flow_style=True, sort_keys=False, width=1_000_000)
    return text.removesuffix("...\n").strip()


if __name__ == "__main__":
    print(reference_table(), end="")
