"""What a world's constructor accepts for each argument, as its signature declares it.

``env.kwargs`` reaches the world's constructor through ``gymnasium.make``, and a
constructor may take a value of the wrong type without a word: FrozenLake's
``is_slippery: [1, 2]`` is a true list, so the lake is slippery; a random walk's
``states: true`` is the integer 1. The signature says what each argument should be. Its
annotation is used where there is one. Without an annotation, the type of the default is
used: a bool default asks for a boolean, an int default for a whole number, a float default
for any number, a str default for a string; a ``None`` default takes anything. Whatever
the signature cannot describe (another class, a callable, a type variable) is left to the
constructor.

>>> def make(flag: bool = True, count: int = 3, size: float | None = None, names=("a",)): ...
>>> rules = {p.name: rule_of(p, {}) for p in inspect.signature(make).parameters.values()}
>>> rules["flag"].text, rules["flag"].accepts(1), rules["flag"].accepts(False)
('a boolean (true or false)', False, True)
>>> rules["count"].accepts(True), rules["count"].accepts(4), rules["count"].accepts(4.0)
(False, True, False)
>>> rules["size"].text, rules["size"].accepts(2), rules["size"].accepts(None)
('a number or null', True, True)
>>> rules["names"] is None  # a tuple default: not one of the types a default speaks for
True
"""

from __future__ import annotations

import collections.abc
import inspect
import numbers
import types
import typing
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

_SEQUENCES = (list, tuple, collections.abc.Sequence, collections.abc.MutableSequence)
"""the annotations a YAML list stands for (``tuple[int, int]`` is given as ``[1, 2]``)"""
_MAPPINGS = (dict, collections.abc.Mapping, collections.abc.MutableMapping)
"""the annotations a YAML mapping stands for"""


@dataclass(frozen=True)
class Rule:
    """What one argument accepts."""

    text: str
    """the values it accepts, in a message's words (YAML's: true, null, a list)"""
    accepts: Callable[[Any], bool]
    """whether a value given in a config is one of them"""


def _is_whole(value: Any) -> bool:
    # bool is a subclass of int: True is not a count.
    return isinstance(value, numbers.Integral) and not isinstance(value, bool)


def _is_number(value: Any) -> bool:
    # A whole number is a float's value too (PEP 484's numeric tower), a boolean is not.
    return isinstance(value, numbers.Real) and not isinstance(value, bool)


BOOLEAN = Rule("a boolean (true or false)", lambda value: isinstance(value, bool))
WHOLE = Rule("a whole number", _is_whole)
NUMBER = Rule("a number", _is_number)
STRING = Rule("a string", lambda value: isinstance(value, str))
NULL = Rule("null", lambda value: value is None)

_BY_TYPE: Mapping[Any, Rule] = {
    bool: BOOLEAN, int: WHOLE, float: NUMBER, complex: NUMBER, str: STRING, type(None): NULL,
    None: NULL,
}  # fmt: skip
"""the rule of each plain type an annotation or a default can name"""


def rule_of(parameter: inspect.Parameter, namespace: Mapping[str, Any]) -> Rule | None:
    """The rule of a constructor's parameter, or ``None`` when it takes anything we can tell.

    Args:
        parameter: the parameter, from ``inspect.signature`` (annotations may be strings).
        namespace: the globals of the function that declares it, to read a string
            annotation in (``from __future__ import annotations``).
    """
    annotation = parameter.annotation
    if isinstance(annotation, str):
        try:
            # The module's own annotation, read as inspect.signature(eval_str=True) reads it.
            annotation = eval(annotation, dict(namespace))
        except Exception:  # a name imported only for type checkers: fall back on the default
            annotation = inspect.Parameter.empty
    if annotation is not inspect.Parameter.empty:
        return annotation_rule(annotation)
    default = parameter.default
    if default is inspect.Parameter.empty or default is None:
        return None
    # The default's own type; a bool default is a flag, not a number (type(), not isinstance).
    return _BY_TYPE.get(type(default)) if type(default) in (bool, int, float, str) else None


def annotation_rule(annotation: Any) -> Rule | None:
    """The rule an annotation states, or ``None`` for one that takes anything we can tell.

    >>> annotation_rule(int | None).text
    'a whole number or null'
    >>> rule = annotation_rule(tuple[int, int, int])
    >>> rule.text, rule.accepts([1, 0, 0]), rule.accepts([1, 0]), rule.accepts([1, 0, "a"])
    ('a list of 3 entries (each a whole number)', True, False, False)
    >>> annotation_rule(list[str]).accepts("SFFF"), annotation_rule(typing.Literal["a", 1]).text
    (False, 'one of "a", 1')
    """
    try:
        if annotation in _BY_TYPE:
            return _BY_TYPE[annotation]
    except TypeError:  # an annotation that cannot be hashed is no plain type
        pass
    origin, arguments = typing.get_origin(annotation), typing.get_args(annotation)
    if origin is typing.Union or origin is types.UnionType:
        members = [annotation_rule(member) for member in arguments]
        if any(member is None for member in members):
            return None
        rules = [member for member in members if member is not None]
        return Rule(
            " or ".join(rule.text for rule in rules),
            lambda value: any(rule.accepts(value) for rule in rules),
        )
    if origin is typing.Literal:
        allowed = list(arguments)
        return Rule(
            "one of " + ", ".join(_yaml(value) for value in allowed),
            lambda value: any(type(value) is type(x) and value == x for x in allowed),
        )
    if annotation in _SEQUENCES or origin in _SEQUENCES:
        return _sequence_rule(origin or annotation, arguments)
    if annotation in _MAPPINGS or origin in _MAPPINGS:
        return Rule("a mapping", lambda value: isinstance(value, dict))
    return None  # Any, object, a class, a callable: the constructor judges


def _sequence_rule(kind: Any, arguments: tuple[Any, ...]) -> Rule:
    """A list's rule: each entry's (``list[X]``, ``tuple[X, ...]``) or each place's."""

    def is_list(value: Any) -> bool:
        return isinstance(value, list | tuple)

    if kind is tuple and arguments and arguments[-1] is not Ellipsis:
        places = [annotation_rule(argument) for argument in arguments]
        texts = {rule.text if rule is not None else "anything" for rule in places}
        each = f"each {texts.pop()}" if len(texts) == 1 else "as declared"
        return Rule(
            f"a list of {len(places)} entries ({each})",
            lambda value: (
                is_list(value)
                and len(value) == len(places)
                and all(
                    rule is None or rule.accepts(x) for rule, x in zip(places, value, strict=True)
                )
            ),
        )
    entry = annotation_rule(arguments[0]) if arguments else None
    if entry is None:
        return Rule("a list", is_list)
    return Rule(
        f"a list (each entry {entry.text})",
        lambda value: is_list(value) and all(entry.accepts(x) for x in value),
    )


def _yaml(value: Any) -> str:
    """A literal as YAML writes it: true, null, "text", 3."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if value is None:
        return "null"
    return f'"{value}"' if isinstance(value, str) else repr(value)


def constructor_parameters(creator: Any) -> tuple[str, Mapping[str, inspect.Parameter], Any]:
    """A world's constructor: its name, its keyword parameters, and its globals.

    Args:
        creator: the entry point, a class (its ``__init__``) or a function.

    Raises:
        TypeError, ValueError: ``inspect.signature`` cannot read it.
    """
    signature = inspect.signature(creator)
    function = typing.cast(Any, creator).__init__ if isinstance(creator, type) else creator
    namespace = getattr(inspect.unwrap(function), "__globals__", {})
    keywords = {
        name: parameter
        for name, parameter in signature.parameters.items()
        if parameter.kind in (parameter.POSITIONAL_OR_KEYWORD, parameter.KEYWORD_ONLY)
    }
    return getattr(creator, "__qualname__", repr(creator)), keywords, namespace


def declared(parameter: inspect.Parameter) -> str:
    """A parameter as its signature declares it: ``is_slippery: bool = True``."""
    text = parameter.name
    annotation = parameter.annotation
    if annotation is not inspect.Parameter.empty:
        shown = annotation if isinstance(annotation, str) else inspect.formatannotation(annotation)
        text += f": {shown}"
    if parameter.default is not inspect.Parameter.empty:
        text += f" = {parameter.default!r}"
    return text
