"""The JSON Schemas of study and tune files: ``cartpole-q schema study`` and ``schema tune``.

One schema covers every study file (and tune file, so that one editor setting covers
``examples/``): the file's ``kind`` selects its kind's schema, and a file without ``kind``
is what the readers take it for: a sweep, unless its ``figure.kind`` is one of another
kind's figures (:func:`~cartpole_q.experiments.study.study_of`), or a tune file when it has
a key only tune files have (``trials``, ``space``, ``objective``:
:data:`~cartpole_q.config.overrides.TUNE_FILE_KEYS`, by which a config refuses them).

Each kind's keys are its reader's own constants (``SWEEP_KEYS``, the bandit's
``STUDY_KEYS``, ``CURVE_KEYS``, ...), imported, never retyped, with the types and ranges the
reader checks; a sweep's or tune file's ``base`` mapping is the config schema
(:func:`~cartpole_q.config.json_schema.config_schema`), and its axes and dimensions name the
config's dotted keys. What a schema cannot say is left to the readers: sizes that depend
on each other (a zip's lengths, a book entry's curve index, a panel's ``every`` dividing
its ``updates``, the memory a study would take), a base file that must exist, the world an
``env.id`` names.
"""

from __future__ import annotations

import dataclasses
import re
import typing
from collections.abc import Callable, Iterable, Mapping
from typing import Any

from cartpole_q.config.bounds import MAX_COUNT
from cartpole_q.config.json_schema import (
    DIALECT,
    NUMBER_TEXT,
    SCHEMA_BASE,
    Schema,
    config_schema,
    number_schema,
    override_schemas,
    seeds_schema,
    with_null,
)
from cartpole_q.config.overrides import TUNE_FILE_KEYS
from cartpole_q.experiments import (
    average_reward,
    bandits,
    linear,
    panels,
    planning,
    policy_gradient,
    study_kinds,
    sweep_spec,
    tune_spec,
    updates,
)
from cartpole_q.experiments.study import KIND_KEY
from cartpole_q.learning_curves import (
    AGGREGATES,
    INFO_KEY_PATTERN,
    INFO_METRIC_PREFIX,
    METRICS,
    X_AXES,
)
from cartpole_q.rl.solvers import SWEEP_ORDERS

CONFIG_REF = "#/$defs/config"
"""where a study schema holds the config schema (a sweep's and a tune file's ``base``)"""
SCHEMAS = ("config", "study", "tune")
"""the schemas ``cartpole-q schema`` writes"""

NAME: Schema = {"type": "string", "pattern": rf"^(?:{sweep_spec._NAME.pattern})$"}
"""a study's ``name``: it names the directory"""
TEXT: Schema = {"type": "string"}
BOOLEAN: Schema = {"type": "boolean"}
WHOLE: Schema = {"type": "integer", "minimum": 0}
"""a whole number as the study readers take it: an integer, never text"""
FRACTION_TEXT = r"^\s*\d+(?:\.\d+)?\s*/\s*\d+(?:\.\d+)?\s*$"
"""a bandit study's number as the book's axis labels write it (``1/128``)"""


def schema_named(name: str) -> Schema:
    """The schema ``cartpole-q schema NAME`` writes: one of :data:`SCHEMAS`.

    Raises:
        ValueError: another name.
    """
    if name == "config":
        return config_schema()
    if name == "study":
        return study_schema()
    if name == "tune":
        return tune_schema()
    raise ValueError(f"no schema named {name!r}; one of {', '.join(SCHEMAS)}")


def study_schema() -> Schema:
    """The JSON Schema (draft 2020-12) of every study file, and of tune files.

    >>> schema = study_schema()
    >>> sorted(name for name in schema["$defs"] if "." not in name)
    ['average_reward', 'bandit', 'config', 'dp', 'linear', 'panels', 'policy_gradient', 'sweep', 'tune', 'updates']
    >>> schema["properties"]["kind"]["enum"]
    ['average_reward', 'bandit', 'dp', 'linear', 'panels', 'policy_gradient', 'sweep', 'updates']
    """
    schemas = kind_schemas()
    kinds = sorted(schemas)
    # An older file without `kind`: the kind whose figures its `figure.kind` is, else a sweep.
    by_figure = {
        name: _figure_kind_in(kind.figure_kinds)
        for name, kind in study_kinds.registered().items()
        if kind.figure_kinds
    }
    untold: list[Schema] = [
        {"if": matches, "then": _ref(name)} for name, matches in by_figure.items()
    ]
    untold.append({"if": {"anyOf": list(by_figure.values())}, "else": _ref("sweep")})
    return {
        **_header("study", "cartpole-q study or tune file"),
        "description": (
            "A study file (`cartpole-q study FILE`): its `kind` says what it runs; without "
            "one it is a sweep, or a tune file (`cartpole-q tune FILE`) when it has "
            f"{', '.join(f'`{key}`' for key in TUNE_FILE_KEYS)} (docs/commands.md)."
        ),
        "type": "object",
        "properties": {KIND_KEY: {"enum": kinds}},
        "if": {"required": [KIND_KEY]},
        "then": {
            "allOf": [
                {"if": {"properties": {KIND_KEY: {"const": name}}}, "then": _ref(name)}
                for name in kinds
            ]
        },
        "else": {
            "if": {"anyOf": [{"required": [key]} for key in TUNE_FILE_KEYS]},
            "then": _ref("tune"),
            "else": {"allOf": untold},
        },
        "$defs": {
            "config": _embedded(config_schema()),
            **schemas,
            "tune": _tune(),
            **_dimension_defs(),
            **_key_defs(),
        },
    }


def tune_schema() -> Schema:
    """The JSON Schema (draft 2020-12) of a tune file (``cartpole-q tune FILE``).

    >>> list(tune_schema()["properties"]) == list(tune_spec.TUNE_KEYS)
    True
    """
    return {
        **_header("tune", "cartpole-q tune file"),
        **_tune(),
        "$defs": {"config": _embedded(config_schema()), **_dimension_defs(), **_key_defs()},
    }


def kind_schemas() -> dict[str, Schema]:
    """Each study kind's schema, by its ``kind``; their ``base`` refers to ``#/$defs/config``.

    Raises:
        ValueError: a registered kind has no schema here (a new kind needs one).
    """
    built = {
        "sweep": _sweep(), "bandit": _bandit(), "dp": _dp(), "updates": _updates(),
        "linear": _linear(), "policy_gradient": _policy_gradient(),
        "average_reward": _average_reward(), "panels": _panels(),
    }  # fmt: skip
    missing = sorted(set(study_kinds.registered()) - set(built))
    if missing:
        raise ValueError(f"no JSON Schema for the study kinds {', '.join(missing)}")
    return built


# -- sweep -----------------------------------------------------------------------------------


def _sweep() -> Schema:
    properties: dict[str, Schema] = {
        "name": NAME,
        "base": _base(),
        "seeds": seeds_schema(),
        "grid": _axes(distinct=True),
        "zip": _axes(distinct=False),
        "curves": BOOLEAN,
        "figure": _sweep_figure(),
    }
    schema = _kind("sweep", sweep_spec.SWEEP_KEYS, properties, "Sweep files")
    schema["minProperties"] = 1  # an empty file says nothing to sweep
    return schema


def _base() -> Schema:
    """A config file (relative to the study file), a shipped config's name, or a mapping."""
    return {
        "description": (
            "the config every point starts from: a config file (relative to this file), a "
            "shipped config's name (`cartpole-q configs`), or a mapping of config keys"
        ),
        "anyOf": [{"type": "string", "pattern": r"\S"}, {"$ref": CONFIG_REF}, {"type": "null"}],
    }


KEY_DEFS = "config."
"""the ``$defs`` of each dotted config key's value: ``#/$defs/config.agent.alpha``"""


def _key_defs() -> dict[str, Schema]:
    """Each dotted config key an axis or a dimension may name, and its value's schema."""
    names, _ = override_schemas()
    return {
        f"{KEY_DEFS}{path}": {k: v for k, v in schema.items() if k != "description"}
        for path, schema in names.items()
        if path not in sweep_spec.FORBIDDEN_AXES
    }


def _dotted_keys(value: Callable[[Schema, str | None], Schema]) -> Schema:
    """An object of dotted config keys (not the seeds'), each holding ``value(its schema)``.

    ``value`` gets the key's schema (a reference into :func:`_key_defs`) and its description.
    """
    names, patterns = override_schemas()
    allowed = {
        path: value({"$ref": f"#/$defs/{KEY_DEFS}{path}"}, schema.get("description"))
        for path, schema in names.items()
        if path not in sweep_spec.FORBIDDEN_AXES
    }
    return {
        "type": "object",
        "properties": allowed,
        "patternProperties": {pattern: value(schema, None) for pattern, schema in patterns.items()},
        "additionalProperties": False,
    }


def _axes(distinct: bool) -> Schema:
    """``grid`` (or ``zip``): dotted config keys, each with a non-empty list of its values.

    A grid's values differ (its reader compares them as cells, where ``1`` and ``1.0``
    differ, so the schema leaves it to the reader).
    """
    kind = "the cartesian product" if distinct else "axes that move together (equal lengths)"
    return {
        "description": f"{kind}: dotted config keys, each with the list of its values",
        **_dotted_keys(_values),
    }


def _values(item: Schema, description: str | None) -> Schema:
    """An axis: a non-empty list of values of its key (described as the key is)."""
    return {**_described(description), "type": "array", "minItems": 1, "items": item}


def _described(description: str | None) -> Schema:
    return {"description": description} if description else {}


def _sweep_figure() -> Schema:
    """The ``figure`` section: its keys' types from :class:`FigureSpec`, then their ranges."""
    hints = typing.get_type_hints(sweep_spec.FigureSpec)
    defaults = {
        item.name: item.default
        for item in dataclasses.fields(sweep_spec.FigureSpec)
        if item.default is not dataclasses.MISSING
    }
    properties: dict[str, Schema] = {}
    for key in sweep_spec.FIGURE_KEYS:
        schema = _python_type(hints[key])
        properties[key] = with_null(schema) if key in defaults and defaults[key] is None else schema
    metric = rf"^{re.escape(INFO_METRIC_PREFIX)}{INFO_KEY_PATTERN.pattern.removeprefix('^')}"
    figures = [*METRICS, sweep_spec.VALUES_FIGURE, sweep_spec.POLICY_FIGURE]
    properties["metric"] = {"anyOf": [{"enum": figures}, {"type": "string", "pattern": metric}]}
    properties["x"] = {"enum": list(X_AXES)}
    properties["aggregate"] = {"enum": list(AGGREGATES)}
    properties["smooth"] = {**properties["smooth"], "minimum": 1}
    properties["first"] = {**properties["first"], "minimum": 1}
    properties["x_max"] = {**properties["x_max"], "exclusiveMinimum": 0}
    properties["dashed"] = {**properties["dashed"], "minProperties": 1, "maxProperties": 1}
    properties["best"] = {
        **properties["best"], "minProperties": 1, "maxProperties": 1,
        "additionalProperties": {"enum": ["min", "max"]},
    }  # fmt: skip
    own = [name.rpartition(".")[0] for name in sweep_spec.SWEEP_OWN_FILES]
    properties["file"] = {
        **_figure_file(),
        "not": {"pattern": rf"^(?:{'|'.join(_any_case(stem) for stem in own)})\.[^.]+$"},
    }
    return _object(properties, ["metric"])


def _python_type(hint: Any) -> Schema:
    """A :class:`FigureSpec` field's type as JSON's (``float | None``: a number or null)."""
    members = [m for m in typing.get_args(hint) if m is not type(None)] or [hint]
    origin = typing.get_origin(members[0]) or members[0]
    kinds = {str: "string", int: "integer", float: "number", bool: "boolean", dict: "object"}
    return {"type": kinds[origin]}


# -- bandit ----------------------------------------------------------------------------------


def _bandit_number(
    low: float | None = None, high: float | None = None, *, low_open: bool = False
) -> Schema:
    """A bandit study's number: also as text, ``1e-3`` or a fraction ``1/128`` (unchecked)."""
    schema = number_schema(low, high, low_open=low_open, text=None)
    return {**schema, "type": ["number", "string"], "anyOf": [
        {"type": "number"}, {"pattern": NUMBER_TEXT}, {"pattern": FRACTION_TEXT},
    ]}  # fmt: skip


_SCALE = bandits.MAX_TESTBED_SCALE
_PARAMETER_RANGES: dict[str, tuple[float, float, bool]] = {
    "epsilon": (0.0, 1.0, False),
    "c": (0.0, _SCALE, False),
    "alpha": (0.0, _SCALE, True),
    "q_init": (-_SCALE, _SCALE, False),
}
"""each parameter's range as the bandit reader checks it (``_check_range``, and alpha
positive): the reader states them in code, not in constants"""
PARAMETER_STUDY = "parameter_study"
"""the bandit figure that varies each curve's parameter (the reader's name for it)"""
NO_SAMPLE_AVERAGE = "gradient"
"""the bandit method whose ``alpha`` cannot be ``sample_average`` and must be given"""


def _bandit() -> Schema:
    testbed = _object({
        "k": {"type": "integer", "minimum": 1},
        "mean": _bandit_number(-_SCALE, _SCALE),
        "spread": _bandit_number(0.0, _SCALE),
        "walk": _bandit_number(0.0, _SCALE),
    })  # fmt: skip
    _check_keys(testbed, bandits.TESTBED_KEYS)
    metrics = {"type": "array", "minItems": 1, "uniqueItems": True,
               "items": {"enum": list(bandits.METRICS)}}  # fmt: skip
    properties: dict[str, Schema] = {
        "name": NAME,
        "testbed": testbed,
        "seeds": seeds_schema(),
        "steps": {"type": "integer", "minimum": 1, "maximum": bandits.MAX_STEPS},
        "engine": {"enum": list(bandits.ENGINES)},
        "curves": {"type": "array", "minItems": 1, "items": _bandit_curve()},
        "figure": _study_figure(bandits.FIGURE_KEYS, bandits.FIGURE_KINDS, {"metrics": metrics}),
        "book": {"type": "array", "items": _bandit_book()},
    }
    schema = _kind("bandit", bandits.STUDY_KEYS, properties, "Bandit files")
    schema["required"] = ["seeds", "curves", "figure"]
    parameter_study = _figure_kind_in([PARAMETER_STUDY])
    schema["if"] = parameter_study
    schema["then"] = {"properties": {
        "curves": {"items": {"required": ["vary"]}},
        "figure": {"properties": {"metrics": {"const": ["average_reward"]}}},
        "book": {"items": {"required": ["of"], "properties": {
            "of": {"const": "peak"}, "above": {"type": "null"}}}},
    }}  # fmt: skip
    schema["else"] = {"properties": {
        "curves": {"items": {"properties": {"vary": False, "values": False}}},
        "book": {"items": {"properties": {"of": {"not": {"const": "peak"}}}}},
    }}  # fmt: skip
    return schema


def _bandit_curve() -> Schema:
    """One learner: its method and the parameters that method takes, or varies."""
    properties: dict[str, Schema] = {
        "label": {"type": "string", "minLength": 1},
        "method": {"enum": list(bandits.METHOD_PARAMETERS)},
        **{key: _bandit_number(*_PARAMETER_RANGES[key][:2], low_open=_PARAMETER_RANGES[key][2])
           for key in bandits.PARAMETERS},
        "baseline": BOOLEAN,
        "vary": {"enum": list(bandits.PARAMETERS)},
        "values": {"type": "array", "minItems": 1, "items": _bandit_number(0.0, _SCALE, low_open=True)},
    }  # fmt: skip
    properties["alpha"] = {"anyOf": [properties["alpha"], {"const": "sample_average"}]}
    curve = _object(properties, ["method"])
    _check_keys(curve, bandits.CURVE_KEYS)
    # (if/then rather than dependentRequired: the YAML language server knows draft-07's words)
    rules: list[Schema] = [
        {"if": {"required": [given]}, "then": {"required": [needed]}}
        for given, needed in (("values", "vary"), ("vary", "values"))
    ]
    for method, takes in bandits.METHOD_PARAMETERS.items():
        refused = [key for key in (*bandits.PARAMETERS, "baseline") if key not in takes]
        then: Schema = {"properties": {
            **dict.fromkeys(refused, False),
            "vary": {"enum": [key for key in takes if key != "baseline"]},
        }}  # fmt: skip
        if method == NO_SAMPLE_AVERAGE:
            then["properties"]["alpha"] = {"not": {"const": "sample_average"}}
            then["if"] = {"required": ["vary"], "properties": {"vary": {"const": "alpha"}}}
            then["else"] = {"required": ["alpha"]}
        rules.append({"if": {"properties": {"method": {"const": method}}}, "then": then})
    for key in bandits.PARAMETERS:
        low, high, _ = _PARAMETER_RANGES[key]
        values = _bandit_number(max(low, 0.0), high, low_open=True)  # (values are positive)
        rules.append({
            "if": {"required": ["vary"], "properties": {"vary": {"const": key}}},
            "then": {"not": {"required": [key]}, "properties": {"values": {"items": values}}},
        })  # fmt: skip
    curve["allOf"] = rules
    return curve


def _bandit_book() -> Schema:
    """A number the book shows, or its claim that one curve lies above another."""
    index = {"type": "integer", "minimum": 0}
    step = {"type": "integer", "minimum": 1, "maximum": bandits.MAX_STEPS}
    book = _object({
        "label": TEXT,
        "value": {"type": ["number", "null"]},
        "curve": index,
        "above": with_null(index),
        "of": {"enum": list(bandits.BOOK_OF)},
        "step": step,
        "steps": {"type": "array", "items": step, "minItems": 2, "maxItems": 2},
    }, ["label", "curve"])  # fmt: skip
    _check_keys(book, bandits.BOOK_KEYS)
    book["not"] = {"required": ["step", "steps"]}
    book["if"] = {"required": ["above"], "properties": {"above": {"type": "integer"}}}
    book["then"] = {"properties": {"value": {"type": "null"}}}
    book["else"] = {"required": ["value"], "properties": {"value": {"type": "number"}}}
    return book


# -- dp --------------------------------------------------------------------------------------

POLICY_ITERATION = "policy_iteration"
"""the dp algorithm that starts from a policy, an action given for every state"""
VALUE_ITERATION = "value_iteration"
"""the dp algorithm that follows no policy"""
CAR_RENTAL = "car_rental"
"""the dp figure of policy iteration's policies (Figure 4.2)"""
GAMBLER = "gambler"
"""the dp figure of value iteration's sweeps (Figure 4.3)"""


def _dp() -> Schema:
    positive = number_schema(0.0, low_open=True)
    figure = {"show": {"type": "array", "items": WHOLE}, "greedy": BOOLEAN,
              "decimals": with_null(WHOLE)}  # fmt: skip
    properties: dict[str, Schema] = {
        "name": NAME,
        # (the reference inside allOf: editors on draft-07 ignore the siblings of a $ref)
        "env": {
            "allOf": [{"$ref": f"{CONFIG_REF}/properties/env"}],
            "type": "object",
            "required": ["id"],
        },
        "algorithm": {"enum": list(planning.ALGORITHMS)},
        "gamma": number_schema(0.0, 1.0),
        "policy": {"anyOf": [{"const": "random"}, WHOLE]},
        "sweeps": {"enum": list(SWEEP_ORDERS)},
        "tolerance": positive,
        "max_sweeps": {"type": "integer", "minimum": 1, "maximum": planning.MAX_SWEEPS},
        "tie_tolerance": number_schema(0.0),
        "figure": _study_figure(planning.FIGURE_KEYS, planning.FIGURE_KINDS, figure),
        "book": {"type": "array", "items": _dp_book()},
    }
    schema = _kind("dp", planning.STUDY_KEYS, properties, "Dp files")
    schema["required"] = ["env", "algorithm", "gamma", "figure"]
    schema["allOf"] = [
        {   # policy iteration starts from a deterministic policy: an action, given
            "if": {"properties": {"algorithm": {"const": POLICY_ITERATION}}},
            "then": {"required": ["policy"], "properties": {"policy": WHOLE}},
        },
        {   # value iteration follows no policy
            "if": {"properties": {"algorithm": {"const": VALUE_ITERATION}}},
            "then": {"not": {"required": ["policy"]}},
        },
        {   # Figure 4.2 draws policy iteration's policies (on a square of states: the world's)
            "if": _figure_kind_in([CAR_RENTAL]),
            "then": {"properties": {"algorithm": {"const": POLICY_ITERATION}}},
        },
        {   # Figure 4.3 draws sweeps
            "if": _figure_kind_in([GAMBLER]),
            "then": {"properties": {"algorithm": {"not": {"const": POLICY_ITERATION}}}},
        },
    ]  # fmt: skip
    return schema


def _dp_book() -> Schema:
    """A number the book prints: a state's value or action (``state`` needed), or a count."""
    book = _object({
        "label": TEXT,
        "value": {"type": "number"},
        "state": with_null(WHOLE),
        "of": {"enum": list(planning.BOOK_OF)},
        "sweep": with_null(WHOLE),
        "decimals": with_null(WHOLE),
    }, ["label", "value"])  # fmt: skip
    _check_keys(book, planning.BOOK_KEYS)
    of_a_state = ["value", "action"]
    book["if"] = {"required": ["of"], "properties": {"of": {"not": {"enum": of_a_state}}}}
    book["else"] = {"required": ["state"], "properties": {"state": WHOLE}}
    return book


# -- updates ---------------------------------------------------------------------------------


def _updates() -> Schema:
    def whole(least: int, most: int | None = MAX_COUNT) -> Schema:
        return {"type": "integer", "minimum": least, **({"maximum": most} if most else {})}

    def branching(least: int) -> Schema:
        return {"type": "array", "minItems": 1, "items": whole(least, updates.MAX_BRANCHING)}

    unit = number_schema(0.0, 1.0, low_open=True)
    side = whole(1, updates.MAX_SCALE)  # a maze's block: k (k x k), or [rows, columns]
    within = number_schema(1.0)  # a greedy path at most this many times the shortest
    panel = _object({
        "states": whole(1, updates.MAX_TASK_STATES),
        "branching": branching(1),
        "updates": whole(1),
        "every": whole(1, None),
    }, updates.PANEL_KEYS)  # fmt: skip
    _check_keys(panel, updates.PANEL_KEYS)
    properties: dict[str, Schema] = {
        "name": NAME,
        "seeds": seeds_schema(),
        "branching": branching(1),
        "initial_error": number_schema(0.0),
        "panels": {"type": "array", "minItems": 1, "items": panel},
        "actions": whole(1, None),
        "epsilon": number_schema(),
        "termination": unit,
        "tolerance": number_schema(0.0, low_open=True),
        "scales": {"type": "array", "minItems": 1, "uniqueItems": True, "items": {"anyOf": [
            side, {"type": "array", "items": side, "minItems": 2, "maxItems": 2},
        ]}},
        "methods": {"type": "array", "minItems": 1, "uniqueItems": True,
                    "items": {"enum": list(updates.UNTIL_OPTIMAL_METHODS)}},
        "alpha": unit,
        "gamma": unit,
        "planning_steps": whole(0, updates.MAX_BRANCHING),
        "theta": number_schema(0.0),
        "max_updates": whole(1),
        "max_steps": whole(1),
        "optimal_within": {"anyOf": [
            within, {"type": "array", "minItems": 1, "uniqueItems": True, "items": within},
        ]},
        "figure": _study_figure(updates.FIGURE_KEYS, updates.FIGURE_KINDS, {}),
    }  # fmt: skip
    schema = _kind("updates", updates.STUDY_KEYS, properties, "Updates files")
    schema["required"] = ["seeds", "figure"]
    # what each figure kind needs beyond its keys (the reader's checks of that kind)
    needs: dict[str, Schema] = {
        "expected_vs_sample": {"required": ["branching"],
                               "properties": {"branching": branching(2)}},
        "trajectory_sampling": {"required": ["panels"],
                                "properties": {"epsilon": number_schema(0.0, 1.0)}},
        "until_optimal": {"required": ["scales"], "properties": {"epsilon": unit}},
    }  # fmt: skip
    rules = []
    for kind, takes in updates.KIND_KEYS.items():
        common = ("name", "seeds", "figure")
        refused = [key for key in updates.STUDY_KEYS if key not in (*common, *takes)]
        then = needs[kind]
        then = {**then, "properties": {**then.get("properties", {}),
                                       **dict.fromkeys(refused, False)}}  # fmt: skip
        rules.append({"if": _figure_kind_in([kind]), "then": then})
    schema["allOf"] = rules
    return schema


# -- tune ------------------------------------------------------------------------------------


def _tune() -> Schema:
    sampler = _object({"type": {"enum": list(tune_spec.SAMPLERS)}, "seed": WHOLE})
    properties: dict[str, Schema] = {
        "name": NAME,
        "base": _base(),
        "seeds": seeds_schema(),
        "trials": {"type": "integer", "minimum": 1, "maximum": tune_spec.MAX_TRIALS},
        "objective": {"enum": list(tune_spec.OBJECTIVES)},
        "space": {
            "description": "the keys searched: dotted config keys, each a range or choices",
            "minProperties": 1,
            **_dotted_keys(_dimension),
        },
        "sampler": with_null(sampler),
        "pruner": BOOLEAN,
    }
    schema = _object(properties, ["space"])
    _check_keys(schema, tune_spec.TUNE_KEYS)
    schema["description"] = (
        "A tune file (`cartpole-q tune FILE`): a base config, the seeds every trial runs, and "
        'ranges of config keys to search (docs/commands.md, "cartpole-q tune").'
    )
    # the pruner stops trials by their success rate, the first objective
    schema["if"] = {"required": ["pruner"], "properties": {"pruner": {"const": True}}}
    schema["then"] = {"properties": {"objective": {"const": tune_spec.OBJECTIVES[0]}}}
    return schema


def _dimension(value: Schema, description: str | None) -> Schema:
    """A searched key: ``{choices: [...]}`` of its values, or a numeric range within its own."""
    return {
        **_described(description),
        "anyOf": [_ref(f"{TUNE_DEFS}choices"), _ref(f"{TUNE_DEFS}range")],
        "properties": {"choices": {"items": value}, "low": value, "high": value},
    }


TUNE_DEFS = "tune."
"""the ``$defs`` of a tune dimension's two forms: ``#/$defs/tune.range``"""


def _dimension_defs() -> dict[str, Schema]:
    """A dimension's forms, whatever its key (:func:`_dimension` checks the values)."""
    choices = _object({"choices": {"type": "array", "minItems": 1}}, ["choices"])
    span = _object({
        "low": number_schema(),
        "high": number_schema(),
        "log": BOOLEAN,
        "step": number_schema(0.0, low_open=True),
        "int": BOOLEAN,
    }, ["low", "high"])  # fmt: skip
    _check_keys(span, tune_spec.RANGE_KEYS)
    span["allOf"] = [
        {   # a log range stays above 0 and takes no step
            "if": {"required": ["log"], "properties": {"log": {"const": True}}},
            "then": {"not": {"required": ["step"]},
                     "properties": {"low": {"exclusiveMinimum": 0}}},
        },
        {   # an int range has whole ends (and a whole step)
            "if": {"required": ["int"], "properties": {"int": {"const": True}}},
            "then": {"properties": {key: {"multipleOf": 1} for key in ("low", "high", "step")}},
        },
    ]  # fmt: skip
    return {f"{TUNE_DEFS}choices": choices, f"{TUNE_DEFS}range": span}


# -- linear ---------------------------------------------------------------------------------


def _linear() -> Schema:
    number = _bandit_number()
    probabilities = {"type": "array", "minItems": 1, "items": _bandit_number(0.0, 1.0)}
    policy: Schema = {"anyOf": [{"const": "random"}, probabilities]}
    world = _object(
        {"id": {"type": "string", "minLength": 1}, "kwargs": {"type": "object"}}, ["id"]
    )
    _check_keys(world, linear.WORLD_KEYS)
    errors = {"type": "array", "minItems": 1, "uniqueItems": True,
              "items": {"enum": list(linear.MEASURES)}}  # fmt: skip
    count = {"type": "integer", "minimum": 1, "maximum": MAX_COUNT}
    own = {
        "y_min": number, "y_max": number, "log_y": BOOLEAN, "fixed_points": BOOLEAN,
        "show_errors": BOOLEAN,
    }  # fmt: skip
    properties: dict[str, Schema] = {
        "name": NAME,
        "world": world,
        "gamma": number_schema(0.0, 1.0),
        "seeds": seeds_schema(),
        "episodes": count,
        "steps": count,
        "record_every": count,
        "engine": {"enum": list(linear.ENGINES)},
        "target": policy,
        "behaviour": policy,
        "errors": errors,
        "curves": {"type": "array", "minItems": 1, "items": _linear_curve()},
        "figure": _study_figure(linear.FIGURE_KEYS, linear.FIGURE_KINDS, own),
        "book": {"type": "array", "items": _linear_book()},
    }
    schema = _kind("linear", linear.STUDY_KEYS, properties, "Linear files")
    schema["required"] = ["world", "curves"]
    schema["not"] = {"required": ["episodes", "steps"]}  # the world says which (the reader)
    return schema


def _linear_curve() -> Schema:
    """One curve: an algorithm on a feature layer, its step sizes and starting weights."""
    from cartpole_q.rl import features
    from cartpole_q.rl import linear as methods

    order = {"type": "integer", "minimum": 1, "maximum": features.MAX_ORDER}
    whole = {"type": "integer", "minimum": 1}
    numbers = {"type": "array", "minItems": 1, "items": _bandit_number()}
    layer_properties: dict[str, Schema] = {
        "kind": {"enum": list(features.KINDS)}, "order": order, "tilings": whole,
        "bins": {"type": "array", "minItems": 1, "items": whole}, "low": numbers, "high": numbers,
    }  # fmt: skip
    layer = _object(layer_properties, ["kind"])
    layer["allOf"] = [
        {
            "if": {"properties": {"kind": {"const": kind}}},
            "then": {
                "properties": dict.fromkeys(
                    [key for key in layer_properties if key not in keys], False
                ),
                "required": [key for key in keys if key in ("order", "bins", "low", "high")],
            },
        }
        for kind, keys in linear.FEATURE_KEYS.items()
    ]
    positive = _bandit_number(0.0, low_open=True)
    curve = _object({
        "label": TEXT,
        "algorithm": {"enum": list(methods.ALGORITHMS)},
        "features": layer,
        "alpha": positive,
        "beta": positive,
        "epsilon": positive,
        "w0": {"anyOf": [_bandit_number(), numbers]},
    }, ["algorithm", "features"])  # fmt: skip
    _check_keys(curve, linear.CURVE_KEYS)
    curve["allOf"] = [
        {"if": {"properties": {"algorithm": {"enum": list(methods.WITH_BETA)}}},
         "then": {"required": ["alpha", "beta"]},
         "else": {"properties": {"beta": False}}},
        {"if": {"properties": {"algorithm": {"const": "lstd"}}},
         "then": {"properties": {"alpha": False}},
         "else": {"required": ["alpha"], "properties": {"epsilon": False}}},
    ]  # fmt: skip
    return curve


def _linear_book() -> Schema:
    """A number the book shows at one point of a curve, or its claim that one lies below another."""
    index = {"type": "integer", "minimum": 0}
    book = _object({
        "label": TEXT,
        "curve": index,
        "at": {"type": "integer", "minimum": 0},
        "of": {"type": "string", "pattern": r"^(?:ve|pbe|w[1-9][0-9]*)$"},
        "value": {"type": ["number", "null"]},
        "below": with_null(index),
        "text": TEXT,
    }, ["label", "curve"])  # fmt: skip
    _check_keys(book, linear.BOOK_KEYS)
    return book


# -- policy gradient ------------------------------------------------------------------------


def _curve_study_parts() -> tuple[Schema, Schema, Schema, Schema, Schema]:
    """What the curve kinds' files share: a number, ``world``, a count, a step size, a list."""
    number = _bandit_number()
    world = _object(
        {"id": {"type": "string", "minLength": 1}, "kwargs": {"type": "object"}}, ["id"]
    )
    count = {"type": "integer", "minimum": 1, "maximum": MAX_COUNT}
    positive = _bandit_number(0.0, low_open=True)
    numbers = {"type": "array", "minItems": 1, "items": number}
    return number, world, count, positive, numbers


def _policy_gradient() -> Schema:
    from cartpole_q.rl import policy_gradient as methods

    number, world, count, positive, numbers = _curve_study_parts()
    curve = _object({
        "label": TEXT,
        "algorithm": {"enum": list(methods.ALGORITHMS)},
        "alpha": positive,
        "alpha_w": positive,
        "policy_features": {"enum": list(methods.POLICY_LAYERS)},
        "value_features": {"enum": list(methods.VALUE_LAYERS)},
        "theta0": {"anyOf": [number, numbers]},
        "w0": {"anyOf": [number, numbers]},
        "min_probability": _bandit_number(0.0, 0.5),
        "lambda_theta": _bandit_number(0.0, 1.0),
        "lambda_w": _bandit_number(0.0, 1.0),
    }, ["algorithm", "alpha"])  # fmt: skip
    _check_keys(curve, policy_gradient.CURVE_KEYS)
    curve["allOf"] = [
        {"if": {"properties": {"algorithm": {"enum": list(methods.WITH_VALUE)}}},
         "then": {"required": ["alpha_w"]},
         "else": {"properties": {"alpha_w": False, "value_features": False, "w0": False}}},
        {"if": {"properties": {"algorithm": {"enum": list(methods.WITH_TRACES)}}},
         "then": {"required": ["lambda_theta", "lambda_w"]},
         "else": {"properties": {"lambda_theta": False, "lambda_w": False}}},
    ]  # fmt: skip
    own = {"y_min": number, "y_max": number, "optimum": BOOLEAN}
    properties: dict[str, Schema] = {
        "name": NAME,
        "world": world,
        "gamma": number_schema(0.0, 1.0),
        "seeds": seeds_schema(),
        "episodes": count,
        "engine": {"enum": list(policy_gradient.ENGINES)},
        "curves": {"type": "array", "minItems": 1, "items": curve},
        "figure": _study_figure(policy_gradient.FIGURE_KEYS, policy_gradient.FIGURE_KINDS, own),
    }
    schema = _kind(
        "policy_gradient", policy_gradient.STUDY_KEYS, properties, "Policy-gradient files"
    )
    schema["required"] = ["world", "episodes", "curves"]
    return schema


def _average_reward() -> Schema:
    from cartpole_q.rl import average_reward as methods

    number, world, count, positive, numbers = _curve_study_parts()
    curve = _object({
        "label": TEXT,
        "algorithm": {"enum": list(methods.ALGORITHMS)},
        "alpha": positive,
        "beta": positive,
        "epsilon": _bandit_number(0.0, 1.0),
        "features": {"enum": list(methods.LAYERS)},
        "w0": {"anyOf": [number, numbers]},
        "r_bar0": number,
    }, ["algorithm", "alpha", "beta"])  # fmt: skip
    _check_keys(curve, average_reward.CURVE_KEYS)
    own = {"y_min": number, "y_max": number, "optimum": BOOLEAN}
    properties: dict[str, Schema] = {
        "name": NAME,
        "world": world,
        "seeds": seeds_schema(),
        "steps": count,
        "record_every": count,
        "engine": {"enum": list(average_reward.ENGINES)},
        "curves": {"type": "array", "minItems": 1, "items": curve},
        "figure": _study_figure(average_reward.FIGURE_KEYS, average_reward.FIGURE_KINDS, own),
    }
    schema = _kind("average_reward", average_reward.STUDY_KEYS, properties, "Average-reward files")
    schema["required"] = ["world", "steps", "curves"]
    return schema


def _panels() -> Schema:
    properties: dict[str, Schema] = {
        "name": NAME,
        "panels": {
            "type": "array", "minItems": 1,
            "items": {"type": "string", "description": "a sweep file with a figure, beside this file"},
        },
        "columns": {"type": "integer", "minimum": 1},
        "title": TEXT,
        "file": _figure_file(),
    }  # fmt: skip
    schema = _kind("panels", panels.STUDY_KEYS, properties, "Panels files")
    schema["required"] = ["panels"]
    return schema


# -- what the kinds share --------------------------------------------------------------------


def _kind(name: str, keys: Iterable[str], properties: dict[str, Schema], section: str) -> Schema:
    """A kind's schema: its keys (and ``kind``), no other, checked against its reader's."""
    schema = _object({KIND_KEY: {"const": name}, **properties})
    _check_keys(schema, (KIND_KEY, *keys))
    schema["description"] = f'A {name} study file (docs/commands.md, "{section}").'
    return schema


def _study_figure(keys: Iterable[str], kinds: Iterable[str], own: Mapping[str, Schema]) -> Schema:
    """A study's ``figure``: its ``kind``, ``file`` and ``title``, then its own keys."""
    figure = _object(
        {"kind": {"enum": list(kinds)}, "file": _figure_file(), "title": TEXT, **own}, ["kind"]
    )
    _check_keys(figure, tuple(keys))
    return figure


def _figure_file() -> Schema:
    """A figure's file name (no directory): ``.png``, ``.svg`` or ``.pdf``, in any case."""
    endings = "|".join(_any_case(ending) for ending in ("png", "svg", "pdf"))
    return {"type": "string", "pattern": rf"^[^/]+\.(?:{endings})$"}


def _any_case(text: str) -> str:
    """A pattern of ``text`` in any case (patterns have no flags).

    >>> _any_case("png")
    '[pP][nN][gG]'
    """
    return "".join(f"[{c.lower()}{c.upper()}]" if c.isalpha() else re.escape(c) for c in text)


def _figure_kind_in(kinds: Iterable[str]) -> Schema:
    """A file whose ``figure.kind`` is one of ``kinds``."""
    return {
        "required": ["figure"],
        "properties": {
            "figure": {
                "type": "object",
                "required": ["kind"],
                "properties": {"kind": {"enum": list(kinds)}},
            }
        },
    }


def _object(properties: dict[str, Schema], required: Iterable[str] = ()) -> Schema:
    """An object of these keys and no other (``required`` among them)."""
    schema: Schema = {"type": "object", "properties": properties, "additionalProperties": False}
    if required:
        schema["required"] = list(required)
    return schema


def _check_keys(schema: Schema, keys: Iterable[str]) -> None:
    """Refuse to build a schema whose keys are not exactly its reader's.

    Raises:
        ValueError: naming the keys one has and the other has not (a reader's new key
            needs its schema here).
    """
    have, want = set(schema["properties"]), set(keys)
    if have != want:
        raise ValueError(
            f"the schema's keys differ from the reader's: {sorted(have - want)} are not the "
            f"reader's, {sorted(want - have)} have no schema"
        )


def _ref(name: str) -> Schema:
    return {"$ref": f"#/$defs/{name}"}


def _header(name: str, title: str) -> Schema:
    return {
        "$schema": DIALECT,
        "$id": f"{SCHEMA_BASE}{name}.json",
        "title": title,
    }


def _embedded(schema: Schema) -> Schema:
    """A schema inside another: without its own ``$schema`` and ``$id``."""
    return {key: value for key, value in schema.items() if key not in ("$schema", "$id")}
