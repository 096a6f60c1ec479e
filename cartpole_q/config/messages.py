"""How config messages show values and name unknown keys, for every module that reads configs."""

from __future__ import annotations

import difflib
from typing import Any


def shown(value: Any) -> str:
    """A value as a message quotes it: its repr, cut to 60 characters.

    >>> shown("x" * 100)[-5:], shown([1, 2])
    ('xx...', '[1, 2]')
    """
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def type_name(value: Any) -> str:
    """What a YAML value is, in YAML's words: ``list``, ``string``, ``number``, ``boolean``."""
    return {list: "list", str: "string", int: "number", float: "number", bool: "boolean"}.get(
        type(value), type(value).__name__
    )


def unknown_key(key: Any, valid: list[str], prefix: str) -> str:
    """The message for an unknown key, with the closest valid one when there is one.

    >>> unknown_key("sed", ["name", "seed"], "")
    "unknown key 'sed'; did you mean 'seed'?"
    """
    close = difflib.get_close_matches(str(key), valid, n=1, cutoff=0.6)
    hint = (
        f"; did you mean '{prefix}{close[0]}'?" if close else f"; valid keys: {', '.join(valid)}."
    )
    return f"unknown key '{prefix}{key}'{hint}"
