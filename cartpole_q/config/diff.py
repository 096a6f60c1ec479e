"""What differs between two configs (or any two nested mappings), key by dotted key."""

from __future__ import annotations

import itertools
import json
from typing import Any

from cartpole_q.config.messages import shorten
from cartpole_q.config.schema import Config

NOT_SET = "(not set)"
"""stands for a key that one of two compared configs does not have"""


def config_differences(old: Config, new: Config) -> list[tuple[str, Any, Any]]:
    """The dotted keys whose values differ between two configs, in file order.

    A key present in only one of them (inside ``env.kwargs``) has the value
    :data:`NOT_SET` in the other.

    >>> from cartpole_q.config import load_config
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


def shown_value(value: Any) -> str:
    """A config value as a message shows it: 0.995, [1, 1, 2, 10], "CartPole-v1", null.

    As YAML and JSON write it, cut like every quoted value
    (:func:`~cartpole_q.config.messages.shorten`), and as cheap for a huge value.

    >>> shown_value([1, 2]), shown_value("sarsa"), shown_value(None), shown_value(NOT_SET)
    ('[1, 2]', '"sarsa"', 'null', '(not set)')
    >>> shown_value(list(range(10**6)))
    '[0, 1, 2, 3, 4, 5, 6, 7, 8, ...]'
    """
    if value is NOT_SET:
        return str(value)
    return shorten(json.dumps(_first_parts(value), default=str).replace('"..."', "..."))


def _first_parts(value: Any, depth: int = 3, entries: int = 9) -> Any:
    """``value`` with only the entries and levels a short quote can show (``"..."`` for the rest)."""
    if isinstance(value, str):
        return value[:80]
    if not isinstance(value, list | tuple | dict):
        return value
    if depth == 0:
        return "..."
    if isinstance(value, dict):
        items = list(itertools.islice(value.items(), entries))
        shown = {str(key)[:80]: _first_parts(item, depth - 1) for key, item in items}
        return shown if len(value) <= entries else {**shown, "...": "..."}
    parts = [_first_parts(item, depth - 1) for item in value[:entries]]
    return parts if len(value) <= entries else [*parts, "..."]


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
