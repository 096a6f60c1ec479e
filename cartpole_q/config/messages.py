"""How messages quote values and name unknown keys, for every module that reads input.

A message quotes what the user gave briefly: a value of a megabyte (or an alias bomb's
expansion) must not become a megabyte of error. :func:`shown` is the one way a message
quotes a value, :func:`shorten` the one way it quotes a text it did not write (an
exception's message); both stop at :data:`QUOTE_LIMIT` characters and cost no more than
that to build, however large the value.
"""

from __future__ import annotations

import difflib
import reprlib
from typing import Any

QUOTE_LIMIT = 80
"""the most characters a message spends on quoting one value"""


def shorten(text: str, limit: int = QUOTE_LIMIT) -> str:
    """``text`` cut to ``limit`` characters, ending in ``...`` when it was cut.

    >>> shorten("x" * 100)[-5:], len(shorten("x" * 100)), shorten("short")
    ('xx...', 80, 'short')
    """
    return text if len(text) <= limit else text[: limit - 3] + "..."


class _Brief(reprlib.Repr):
    """A repr that looks at no more of a value than a quote of :data:`QUOTE_LIMIT` needs."""

    def __init__(self) -> None:
        super().__init__()
        self.maxlevel = 3
        self.maxlist = self.maxtuple = self.maxset = self.maxdict = 8
        self.maxstring = self.maxother = QUOTE_LIMIT
        self.maxlong = 40

    def repr_str(self, x: str, level: int) -> str:
        # reprlib cuts a string in its middle; a message reads better cut at its end.
        return repr(x) if len(x) <= self.maxstring else repr(x[: self.maxstring]) + "..."


_BRIEF = _Brief()


def shown(value: Any) -> str:
    """A value as a message quotes it: its repr, at most :data:`QUOTE_LIMIT` characters.

    Only the first entries of a long list or mapping, and the first levels of a nested
    one, are looked at, so quoting a huge value is as cheap as quoting a small one.

    >>> shown("x" * 100)[-5:], shown([1, 2]), shown(list(range(10**6)))
    ('xx...', '[1, 2]', '[0, 1, 2, 3, 4, 5, 6, 7, ...]')
    """
    return shorten(_BRIEF.repr(value))


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
    name = shorten(str(key))
    close = difflib.get_close_matches(name, valid, n=1, cutoff=0.6)
    hint = (
        f"; did you mean '{prefix}{close[0]}'?" if close else f"; valid keys: {', '.join(valid)}."
    )
    return f"unknown key '{prefix}{name}'{hint}"
