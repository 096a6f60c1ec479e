"""The config file's JSON Schema, generated: ``cartpole-q schema config``.

Editors with the YAML language server complete and check a config file with it, and a stock
validator (``jsonschema``) accepts every shipped config. Nothing here repeats a config key:
the schema walks the dataclasses of :mod:`~cartpole_q.config.schema` and the
:class:`~cartpole_q.config.schema.Key` each field carries (its kind, range, choices, doc),
the algorithms' own keys from the registry's :class:`~cartpole_q.rl.algorithm.Param`
declarations, the physics from the environments' profiles and the defaults from
``default.yaml``. A new config key is therefore in the schema as soon as it is in the
dataclass.

What a schema can say, it says: the keys of each section (no other), each value's type,
range and choices, a number written as YAML's string (``5e-4``), the forms of a schedule,
and the rules across keys that name no computed value (tile coding widens ``agent.alpha``
to ``tilings`` and refuses ``sample_average``; an algorithm that cannot average refuses it).
What needs the environment or arithmetic (an ``env.id`` that exists, low edges below high
ones, the physics keys of the chosen environment) is left to the readers.
"""

from __future__ import annotations

import dataclasses
import functools
import json
import re
from collections.abc import Iterable, Mapping
from typing import Any

from cartpole_q.config.reference import _either, _meaning
from cartpole_q.config.schema import (
    EXACT_INTEGER,
    MAX_SEED,
    MAX_SEEDS,
    SAMPLE_AVERAGE_KIND,
    SCHEDULE_FORMS,
    AgentConfig,
    Config,
    DiscretizationConfig,
    Key,
    key_of,
    sections,
)
from cartpole_q.config.validation import _NAME_PATTERN, _NUMBER_PATTERN
from cartpole_q.config.yaml_io import default_raw
from cartpole_q.families import all_profiles
from cartpole_q.learning_curves import INFO_KEY_PATTERN
from cartpole_q.rl.algorithm import Param
from cartpole_q.rl.algorithms import algorithms
from cartpole_q.rl.algorithms import names as algorithm_names

Schema = dict[str, Any]
"""A JSON Schema (or a part of one), as plain data ready for ``json.dumps``."""

DIALECT = "https://json-schema.org/draft/2020-12/schema"
"""the ``$schema`` of every schema the package writes"""
SCHEMA_BASE = "https://cartpole-q.invalid/schemas/"
"""where the schemas' ``$id`` lives: a name, not a place (``.invalid`` never resolves)"""

NUMBER_TEXT = rf"^\s*(?:{_NUMBER_PATTERN.pattern.removeprefix('^').removesuffix('$')})\s*$"
"""a number as YAML leaves it a string (``5e-4``), which the readers take as the number
(they strip the text first)"""
SEEDS_TEXT = r"^\s*\d+\s*(?:-\s*\d+\s*)?(?:,\s*\d+\s*(?:-\s*\d+\s*)?)*$"
"""seeds as text (``"0-99"``, ``"0,5,10-19"``): what :func:`parse_seeds` splits at commas"""
KWARGS_REFUSED = "render_mode"
"""the ``env.kwargs`` key the reader refuses (training never renders)"""
TIME_LIMIT = "max_episode_steps"
"""the ``env.kwargs`` key the reader checks itself: a positive whole number"""


def config_schema() -> Schema:
    """The JSON Schema (draft 2020-12) of a config file: every key optional, none other.

    >>> schema = config_schema()
    >>> list(schema["properties"])
    ['name', 'seed', 'engine', 'env', 'discretization', 'agent', 'train', 'eval']
    >>> schema["properties"]["agent"]["properties"]["gamma"]["maximum"]
    1.0
    """
    return {
        "$schema": DIALECT,
        "$id": f"{SCHEMA_BASE}config.json",
        "title": "cartpole-q config file",
        "description": (
            "A run's config (`cartpole-q train -c FILE`): every key it leaves out takes the "
            "embedded default's value (docs/reference/configuration.md)."
        ),
        **_record(Config, default_raw(), loose=False),
        "type": ["object", "null"],  # an empty file (YAML's null) is the default
        "allOf": [_tile_rules()],
    }


def override_schemas() -> tuple[dict[str, Schema], dict[str, Schema]]:
    r"""What a dotted key of a sweep axis or a tune dimension may name, and its value's schema.

    Every config key by its dotted path (``seed``, ``agent``, ``agent.alpha``,
    ``agent.lambda``), then patterns for the paths into a mapping's own keys
    (``agent.epsilon.decay``, ``env.kwargs.map_name``), whose values are not checked here.
    A value merges into the base config, so a schedule mapping may leave out its ``type``
    and keys (the base's schedule has them) and a step size may reach tile coding's range.

    >>> names, patterns = override_schemas()
    >>> "agent.lambda" in names, "train.seeds" in names, r"^agent\.epsilon\..+$" in patterns
    (True, True, True)
    """
    names: dict[str, Schema] = {}
    patterns: dict[str, Schema] = {}
    for path, key, schema in _leaves(Config, "", loose=True):
        names[path] = schema
        if key is not None and key.kind in ("schedule", "kwargs", "physics", "randomize"):
            patterns[rf"^{re.escape(path)}\..+$"] = {}
    return names, patterns


# -- one value of each kind ----------------------------------------------------------------


def number_schema(
    low: float | None = None,
    high: float | None = None,
    *,
    low_open: bool = False,
    integer: bool = False,
    text: str | None = NUMBER_TEXT,
) -> Schema:
    """A number in a range; with ``text``, also a string of that form (its range unchecked).

    >>> number_schema(0.0, 1.0, low_open=True, text=None)
    {'type': 'number', 'exclusiveMinimum': 0.0, 'maximum': 1.0}
    """
    kind = "integer" if integer else "number"
    schema: Schema = {"type": [kind, "string"], "pattern": text} if text else {"type": kind}
    if low is not None:
        schema["exclusiveMinimum" if low_open else "minimum"] = low
    if integer:
        # The readers take integers written as floats (1e6) only where floats are exact.
        high = EXACT_INTEGER - 1 if high is None else min(int(high), EXACT_INTEGER - 1)
    if high is not None:
        schema["maximum"] = high
    return schema


def seeds_schema() -> Schema:
    r"""Seeds as :func:`~cartpole_q.config.parse_seeds` reads them: one, a list, or text.

    >>> seeds_schema()["anyOf"][2]["pattern"]
    '^\\s*\\d+\\s*(?:-\\s*\\d+\\s*)?(?:,\\s*\\d+\\s*(?:-\\s*\\d+\\s*)?)*$'
    """
    seed = {"type": "integer", "minimum": 0, "maximum": MAX_SEED}
    return {
        "anyOf": [
            seed,
            {"type": "array", "items": seed, "minItems": 1, "maxItems": MAX_SEEDS,
             "uniqueItems": True},
            {"type": "string", "pattern": SEEDS_TEXT},
        ]
    }  # fmt: skip


def with_null(schema: Schema) -> Schema:
    """``schema`` or ``null``.

    >>> with_null({"type": "string"}), with_null({"enum": ["a"]})
    ({'type': ['string', 'null']}, {'enum': ['a', None]})
    """
    if "enum" in schema:
        return {**schema, "enum": [*schema["enum"], None]}
    if "type" in schema and "anyOf" not in schema:
        kinds = schema["type"] if isinstance(schema["type"], list) else [schema["type"]]
        return {**schema, "type": [*kinds, "null"]}
    return {"anyOf": [schema, {"type": "null"}]}


def _value(spec: Key | Param, default: Any, loose: bool) -> Schema:
    """The schema of one value of ``spec``'s kind, as the reader of that kind checks it."""
    match spec.kind:
        case "name":
            return {"type": "string", "pattern": _NAME_PATTERN.pattern}
        case "str":
            # An algorithm's text (a path) may be left empty; a config key's may not.
            return {"type": ["string", "null"]} if isinstance(spec, Param) else _TEXT
        case "int":
            return number_schema(spec.low, spec.high, integer=True)
        case "float":
            return number_schema(spec.low, spec.high, low_open=spec.low_open)
        case "bool":
            return {"type": "boolean"}
        case "choice":
            return {"enum": list(spec.choices)}
        case "algorithm":
            return {"enum": list(algorithm_names())}
        case "schedule" if isinstance(spec, Key):  # (an algorithm's keys are never schedules)
            return _schedule(spec, None if loose else default)
        case "seeds":
            return seeds_schema()
        case "bins":
            return {"type": "array", "minItems": 1, "items": number_schema(1, integer=True)}
        case "floats":
            return {"type": "array", "minItems": 1, "items": number_schema()}
        case "kwargs":
            return {
                "type": ["object", "null"],
                "propertyNames": {"not": {"const": KWARGS_REFUSED}},
                "properties": {TIME_LIMIT: {"type": "integer", "minimum": 1}},
            }
        case "physics":
            return _physics(randomize=False)
        case "randomize":
            return _physics(randomize=True)
        case "info_key":
            return {"type": "string", "pattern": INFO_KEY_PATTERN.pattern}
    raise ValueError(f"no JSON Schema for the kind {spec.kind!r}")


_TEXT: Schema = {"type": "string", "minLength": 1}


def _schedule(key: Key, default: Any) -> Schema:
    """A number, ``sample_average`` where allowed, or one of the schedule mappings.

    A mapping merges into the default's schedule when it keeps its ``type`` (or gives
    none): of the default's form no key is required. Without a ``default`` (a sweep axis,
    merged into a base the schema does not know) none is, of any form.
    """
    merged = default.get("type") if isinstance(default, Mapping) else None
    forms: list[Schema] = [number_schema(key.low, key.high, low_open=key.low_open)]
    if key.sample_average:
        forms.append(SAMPLE_AVERAGE)
    for kind, form in SCHEDULE_FORMS.items():
        properties: dict[str, Schema] = {"type": {"const": kind}}
        for schedule_key in form:
            bounds = schedule_key.bounds or key
            properties[schedule_key.name] = number_schema(
                bounds.low, bounds.high, low_open=bounds.low_open
            )
        required: list[str] = []
        if default is not None and kind != merged:
            required = ["type", *(k.name for k in form if k.default is None)]
        forms.append(_object(properties, required))
    return {"anyOf": forms}


SAMPLE_AVERAGE: Schema = {
    "anyOf": [
        {"const": SAMPLE_AVERAGE_KIND},
        {"type": "object", "properties": {"type": {"const": SAMPLE_AVERAGE_KIND}},
         "required": ["type"], "additionalProperties": False},
    ]
}  # fmt: skip
"""``sample_average``, written alone or as ``{type: sample_average}``"""


def _physics(randomize: bool) -> Schema:
    """``env.physics`` (or ``env.randomize``): the keys some environment's profile allows.

    Which environment's keys apply is the reader's to say: an ``env.id`` registered under a
    profile's entry point takes its physics too.
    """
    allowed: dict[str, list[Schema]] = {}
    for profile in all_profiles():
        physics = profile.physics
        if physics is None:
            continue
        for name, bounds in physics.ranges.items():
            if randomize and name not in physics.randomizable:
                continue
            number = number_schema(bounds.low, bounds.high, low_open=bounds.low_open)
            pair = {"type": "array", "items": number, "minItems": 2, "maxItems": 2}
            allowed.setdefault(name, []).append(pair if randomize else number)
        for name, values in physics.choices.items():
            if not randomize:
                allowed.setdefault(name, []).append({"enum": list(values)})
    properties = {name: _either_of(schemas) for name, schemas in allowed.items()}
    return {"type": ["object", "null"], "properties": properties, "additionalProperties": False}


def _either_of(schemas: Iterable[Schema]) -> Schema:
    """One schema, or ``anyOf`` the distinct ones (two declarations of the same key)."""
    distinct = list({json.dumps(s, sort_keys=True): s for s in schemas}.values())
    return distinct[0] if len(distinct) == 1 else {"anyOf": distinct}


# -- sections ------------------------------------------------------------------------------


def _record(record: type, defaults: Mapping[str, Any] | None, loose: bool) -> Schema:
    """A section (or the whole file) as an object of its fields' schemas, no other key."""
    properties: dict[str, Schema] = {}
    for name, key, schema in _fields(record, defaults, loose):
        if key is not None and key.kind != "section" and defaults and name in defaults:
            schema = {**schema, "default": defaults[name]}
        properties[name] = schema
    built = _object(properties)
    if record is AgentConfig and _sample_average_rules():
        built["allOf"] = _sample_average_rules()
    return built


def _fields(
    record: type, defaults: Mapping[str, Any] | None, loose: bool
) -> Iterable[tuple[str, Key | None, Schema]]:
    """Each key of a section in file order, the algorithms' own keys where they stand.

    A section's key yields ``None`` for its :class:`Key` (it is described by its own keys).
    """
    for item in dataclasses.fields(record):
        key = key_of(item)
        if key.kind == "params":
            for name, schema in _algorithm_keys().items():
                yield name, None, schema
            continue
        if key.kind == "section":
            inner = None if defaults is None else defaults.get(item.name)
            # A section left out, or null, keeps the default's (``discretization``: no grid).
            schema = with_null(_record(sections()[item.name], inner, loose))
        else:
            default = None if defaults is None else defaults.get(item.name)
            schema = _value(_widened(record, item.name) or key, default, loose)
            if key.nullable:
                schema = with_null(schema)
        if key.doc:
            schema = {"description": _meaning(key), **schema}
        yield item.name, key, schema


def _leaves(record: type, prefix: str, loose: bool) -> Iterable[tuple[str, Key | None, Schema]]:
    """Every dotted path of a config key (sections and the keys inside them) and its schema."""
    for name, key, schema in _fields(record, None, loose):
        yield f"{prefix}{name}", key, schema
        if key is not None and key.kind == "section":
            yield from _leaves(sections()[name], f"{prefix}{name}.", loose)


@functools.cache
def _declarations() -> dict[str, list[tuple[str, Param]]]:
    """Each algorithm's own key, with every algorithm that declares it (and how)."""
    found: dict[str, list[tuple[str, Param]]] = {}
    for algorithm in algorithms():
        for param in algorithm.params:
            found.setdefault(param.key, []).append((algorithm.name, param))
    return found


def _algorithm_keys() -> dict[str, Schema]:
    """``agent.n``, ``agent.lambda``, ...: each key some algorithm adds, as they declare it.

    The key of another algorithm than the chosen one is ignored by the reader (a sweep may
    vary the algorithm over a base that sets it), but checked here as its algorithms
    declare it: in a file it is a mistake either way.
    """
    keys: dict[str, Schema] = {}
    for key, owners in _declarations().items():
        params = [param for _, param in owners]
        schema = _either_of(_value(param, param.default, loose=False) for param in params)
        first = params[0]
        schema = {
            "description": f"{first.doc} ({first.interval}; {_either(n for n, _ in owners)} only)",
            **schema,
        }
        if len({json.dumps(param.default) for param in params}) == 1:
            schema["default"] = first.default
        keys[key] = schema
    return keys


# -- the rules across keys -----------------------------------------------------------------


def _sample_average_rules() -> list[Schema]:
    """``agent.alpha: sample_average`` is refused by the algorithms that say why."""
    refusing = [a.name for a in algorithms() if a.no_sample_average]
    if not refusing:
        return []
    return [
        {
            "if": {"required": ["algorithm"], "properties": {"algorithm": {"enum": refusing}}},
            "then": {"properties": {"alpha": {"not": SAMPLE_AVERAGE}}},
        }
    ]


def _tile_rules() -> Schema:
    """Tile coding (``discretization.tilings`` > 1) widens ``agent.alpha`` and refuses some.

    On tiles ``agent.alpha`` is Q's step, up to ``tilings`` (the schema's properties allow
    the most tilings there are); without them it keeps its own range. On tiles
    ``sample_average`` has no entries to count, and the algorithms that keep states across
    episodes do not run.
    """
    untiled_alpha = _schedule(_key_of(AgentConfig, "alpha"), default_raw()["agent"]["alpha"])
    not_on_tiles = [a.name for a in algorithms() if a.not_on_tiles]
    single = _tilings_key().low
    agent_on_tiles: Schema = {"properties": {"alpha": {"not": SAMPLE_AVERAGE}}}
    if not_on_tiles:
        agent_on_tiles["properties"]["algorithm"] = {"not": {"enum": not_on_tiles}}
    return {
        "if": {
            "required": ["discretization"],
            "properties": {
                "discretization": {
                    "type": "object",
                    "required": ["tilings"],
                    "properties": {"tilings": {"type": "number", "exclusiveMinimum": single}},
                }
            },
        },
        "then": {"properties": {"agent": agent_on_tiles}},
        "else": {"properties": {"agent": {"properties": {"alpha": untiled_alpha}}}},
    }


def _widened(record: type, name: str) -> Key | None:
    """A key whose range another key widens, at its widest (``None``: no such key).

    ``agent.alpha`` reaches ``tilings`` on tiles; :func:`_tile_rules` narrows it again
    without them.
    """
    if record is not AgentConfig or name != "alpha":
        return None
    return dataclasses.replace(_key_of(AgentConfig, "alpha"), high=_tilings_key().high)


def _tilings_key() -> Key:
    return _key_of(DiscretizationConfig, "tilings")


def _key_of(record: type, name: str) -> Key:
    """The :class:`Key` of one field of a section."""
    return key_of(next(item for item in dataclasses.fields(record) if item.name == name))


def _object(properties: dict[str, Schema], required: Iterable[str] = ()) -> Schema:
    """An object of these keys and no other (``required`` among them)."""
    schema: Schema = {"type": "object", "properties": properties, "additionalProperties": False}
    if required:
        schema["required"] = list(required)
    return schema
