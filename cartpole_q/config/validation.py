"""Validation: the merged raw mapping becomes a :class:`Config`, or a :class:`ConfigError`.

Each field is read by its :class:`~cartpole_q.config.schema.Key`: a reader per kind checks
the value and its range, and its message names the source (the file, or the overrides) and
the field: ``blog.yaml: agent.gamma: must be in [0, 1], got 1.5.`` The rules that look at
more than one key are small functions below: the grid against itself, the physics against
the environment's profile, an algorithm's own keys against its
:class:`~cartpole_q.rl.algorithm.Param` declarations (which the same readers check).
"""

from __future__ import annotations

import copy
import dataclasses
import math
import os
import re
from collections import Counter
from collections.abc import Mapping
from types import MappingProxyType
from typing import Any

from cartpole_q.config.messages import shown, unknown_key
from cartpole_q.config.overrides import Provenance
from cartpole_q.config.schema import (
    EXACT_INTEGER,
    MAX_SEED,
    MAX_SEEDS,
    SAMPLE_AVERAGE_KIND,
    SCHEDULE_FORMS,
    AgentConfig,
    Config,
    DiscretizationConfig,
    EnvConfig,
    EvalConfig,
    Key,
    Schedule,
    TrainConfig,
    format_seeds,
    key_of,
)
from cartpole_q.errors import ConfigError
from cartpole_q.families import Physics, PhysicsRange, all_profiles, profile_for
from cartpole_q.learning_curves import INFO_KEY_PATTERN
from cartpole_q.rl.algorithm import Param, ParamValue
from cartpole_q.rl.algorithms import get as get_algorithm
from cartpole_q.rl.algorithms import names as algorithm_names
from cartpole_q.rl.prediction import RUN_POLICIES
from cartpole_q.rl.schedules import SCHEDULE_KINDS, smallest_positive_value

_NAME_PATTERN = re.compile(r"^[A-Za-z0-9_-]{1,64}$")
_NUMBER_PATTERN = re.compile(r"^[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?$")

_RULED = ("section", "physics", "randomize", "params")
"""kinds that the rules below read, since they depend on other keys"""


Spec = Key | Param
"""What a value is: a config key's :class:`Key`, or an algorithm's own key's :class:`Param`."""
Bounds = Key | Param | PhysicsRange
"""A range: a :class:`Key`'s, a :class:`Param`'s, or a physics key's (its profile's)."""


def read_config(raw: dict[str, Any], source: Provenance) -> Config:
    """Check the merged raw mapping and build the frozen config.

    Raises:
        ConfigError: the first key whose value is invalid, blamed on whoever gave it.
    """
    reader = _Reader(raw, source)
    for item in dataclasses.fields(Config):
        key = key_of(item)
        if key.kind != "section" or (key.nullable and raw.get(item.name) is None):
            continue  # (no grid: Discrete observations, checked against the env later)
        if not isinstance(raw.get(item.name), dict):
            raise reader.error(item.name, "must be a mapping of keys to values.")
    name = reader.field(Config, "", "name")
    # The grid is checked before the other keys: a config with several mistakes has always
    # been told about the grid's first.
    discretization = _discretization(reader)
    tilings = discretization.tilings if discretization is not None else 1
    agent = AgentConfig(
        **reader.fields(AgentConfig, "agent.", ranges=_tile_ranges(tilings)),
        params=_algorithm_params(reader),
    )
    if tilings > 1:
        _check_on_tiles(reader, agent.algorithm)
    if agent.alpha.averages:
        _check_sample_average(reader, agent.algorithm, tilings)
    train = TrainConfig(**reader.fields(TrainConfig, "train."))
    _check_epsilon_floor(reader, agent, train.episodes)
    env = _env(reader)
    _check_named_policy(reader, agent, env.id, tiled=tilings > 1)
    _check_initial_values(reader, agent, tilings)
    return Config(
        name=name,
        **reader.fields(Config, "", skip=("name",)),
        env=env,
        discretization=discretization,
        agent=agent,
        train=train,
        eval=EvalConfig(**reader.fields(EvalConfig, "eval.")),
    )


# -- the rules that look at more than one key ---------------------------------------------


def _discretization(reader: _Reader) -> DiscretizationConfig | None:
    """The grid: as many low and high edges as bins, every low edge below its high edge."""
    if reader.raw["discretization"] is None:
        return None
    grid = DiscretizationConfig(**reader.fields(DiscretizationConfig, "discretization."))
    for field, values in (("discretization.low", grid.low), ("discretization.high", grid.high)):
        if len(values) != len(grid.bins):
            raise reader.error(
                field,
                f"has {len(values)} entries but discretization.bins has {len(grid.bins)}; "
                "give one per observation dimension.",
            )
    for d, (lo, hi) in enumerate(zip(grid.low, grid.high, strict=True)):
        if not lo < hi:
            raise reader.error(
                "discretization.low",
                f"entry {d} ({lo}) must be below discretization.high entry {d} ({hi}).",
            )
    return grid


def _tile_ranges(tilings: int) -> dict[str, Key]:
    """On tiles ``agent.alpha`` is Q's step, up to ``T``: a tile's step ``alpha / T`` <= 1."""
    if tilings == 1:
        return {}
    alpha = next(item for item in dataclasses.fields(AgentConfig) if item.name == "alpha")
    return {"alpha": dataclasses.replace(key_of(alpha), high=float(tilings))}


def _check_on_tiles(reader: _Reader, algorithm: str) -> None:
    """Tile coding takes the algorithms whose memory holds no state across episodes."""
    reason = get_algorithm(algorithm).not_on_tiles
    if reason:
        raise reader.error(
            "discretization.tilings",
            f"tile coding (tilings > 1) does not run agent.algorithm {algorithm}: {reason}. "
            "Use tilings: 1, or a one-step, n-step or trace algorithm.",
        )


def _check_sample_average(reader: _Reader, algorithm: str, tilings: int) -> None:
    """Sample averages count updates of table entries: an algorithm that makes them, no tiles."""
    reason = get_algorithm(algorithm).no_sample_average
    if reason:
        raise reader.error(
            "agent.alpha",
            f"sample_average does not apply to agent.algorithm {algorithm}: {reason}. Give "
            "alpha a number or a schedule, or use an algorithm that averages (docs/algorithms.md, "
            '"Sample averages": one-step and n-step TD, Dyna, prioritized sweeping, on-policy '
            "Monte Carlo, the offline lambda-return, SARSA(lambda), Watkins's Q(lambda), "
            "TD(lambda)).",
        )
    if tilings > 1:
        raise reader.error(
            "agent.alpha",
            "sample_average counts the updates of each table entry, and on tiles "
            "(discretization.tilings > 1) a state is not one entry but its tiles, shared with "
            "other states. Give alpha a number or a schedule, or use tilings: 1.",
        )


def _check_named_policy(reader: _Reader, agent: AgentConfig, env_id: str, tiled: bool) -> None:
    """A named ``agent.policy`` (not ``random``) is a rule of the world, or a run's policy.

    Either gives an action per table row (the worlds that declare a rule have Discrete
    observations: no grid, no tiles); ``agent.policy_run`` is read by a run's policy alone.
    """
    if not get_algorithm(agent.algorithm).predicts:
        return
    name = str(agent.params.get("policy", "random"))
    problem = named_policy_problem(name, str(agent.params.get("policy_run", "")), env_id, tiled)
    if problem is not None:
        raise reader.error(*problem)


def named_policy_problem(name: str, run: str, env_id: str, tiled: bool) -> tuple[str, str] | None:
    """What is wrong with evaluating the policy ``name`` (from ``run``) on ``env_id``, if anything.

    A prediction config's ``agent.policy`` and ``optimum --policy`` are checked alike.

    Returns:
        ``None``, or the key to blame (``agent.policy`` or ``agent.policy_run``) and why.
    """
    from cartpole_q.families import profile_for

    if name in RUN_POLICIES:
        return _policy_run_problem(name, run, tiled)
    if run:
        return (
            "agent.policy_run",
            f"{run} is read only with agent.policy greedy or epsilon_greedy (agent.policy is "
            f"{name}); remove it, or set agent.policy: greedy.",
        )
    if name == "random":
        return None
    declared = profile_for(env_id).policies
    if name not in declared:
        rules = ", ".join(declared) or "none"
        return (
            "agent.policy",
            f"{name} is not a rule {env_id} declares (it declares {rules}). Use random, "
            f"greedy or epsilon_greedy (a run's), or a rule of its world; {_rule_owners(name)}",
        )
    return None


def _check_initial_values(reader: _Reader, agent: AgentConfig, tilings: int) -> None:
    """``agent.initial_values`` starts a prediction run's ``V`` state by state, never on tiles.

    Its length is checked against the table once the world is made
    (:func:`~cartpole_q.envs.gym.inspect_env`).
    """
    if agent.initial_values is None:
        return
    if not get_algorithm(agent.algorithm).predicts:
        raise reader.error(
            "agent.initial_values",
            f"starts the values a prediction algorithm learns (V, one per state), and "
            f"{agent.algorithm} learns action values; set it to null and give agent.q_init, "
            "or use a prediction algorithm (td, mc_prediction, ...).",
        )
    if tilings > 1:
        raise reader.error(
            "agent.initial_values",
            "gives one value per state, and on tiles (discretization.tilings > 1) a state's "
            "value is the sum of its tiles' weights, shared with other states; set it to null "
            "or use tilings: 1.",
        )


def _rule_owners(name: str) -> str:
    """Which worlds declare the rule ``name``, or every world's rules when none does.

    >>> _rule_owners("left")
    'left is the rule of cartpole_q/OneState-v0.'
    """
    owners = [profile.ids[0] for profile in all_profiles() if name in profile.policies]
    if owners:
        return f"{name} is the rule of {', '.join(owners)}."
    rules = [
        f"{rule} ({profile.ids[0]})" for profile in all_profiles() for rule in profile.policies
    ]
    return f"no world declares {name}; the worlds' rules: {', '.join(rules)}."


def _policy_run_problem(name: str, run: str, tiled: bool) -> tuple[str, str] | None:
    """A run's policy needs the run's directory (a table policy: not on tiles).

    The directory itself is read and checked when a run is prepared, not here: a config
    is also read back from a run directory long after, from anywhere, when the evaluated
    run may have moved.
    """
    if tiled:
        return (
            "agent.policy",
            f"{name} takes a run's table policy, one action per table row; on tiles there are "
            "no rows. Use discretization.tilings: 1.",
        )
    if not run:
        return (
            "agent.policy_run",
            f"agent.policy {name} evaluates a control run's policy: give its run directory "
            "(agent.policy_run: runs/NAME).",
        )
    return None


def _check_epsilon_floor(reader: _Reader, agent: AgentConfig, episodes: int) -> None:
    """An algorithm undefined for tiny positive epsilons refuses a schedule that reaches one."""
    floor = get_algorithm(agent.algorithm).epsilon_floor
    schedule = agent.epsilon
    smallest = smallest_positive_value(
        schedule.code, schedule.start, schedule.end, schedule.rate, episodes
    )
    if floor <= 0.0 or smallest is None or smallest[0] >= floor:
        return
    value, episode = smallest
    raise reader.error(
        "agent.epsilon",
        f"{agent.algorithm} divides by the probability epsilon / n with which the behaviour "
        f"policy explores, and this epsilon is {value!r} at episode {episode + 1}, so small "
        "that the probability can round to 0 and the method is undefined. Keep every "
        f"positive epsilon at least {floor:g} (0 itself is allowed): a larger constant, or "
        "a schedule's end of 0 replaced by a floor such as 0.001.",
    )


def _env(reader: _Reader) -> EnvConfig:
    """The environment: its physics and their ranges are what its profile allows."""
    env_id = reader.field(EnvConfig, "env.", "id")
    physics = _physics(reader, env_id)
    randomize = _randomize(reader, env_id)
    return EnvConfig(
        id=env_id,
        physics=physics,
        randomize=randomize,
        **reader.fields(EnvConfig, "env.", skip=("id",)),
    )


def _physics_mapping(
    reader: _Reader, field: str, env_id: str, kind: str
) -> tuple[dict[str, Any], Physics | None]:
    """The raw ``env.physics`` or ``env.randomize`` mapping, and the env's physics."""
    value = reader.value_at(field)
    if value is None or value == {}:
        return {}, None
    if not isinstance(value, dict):
        raise reader.error(field, f"must be a mapping of keys to values, got {shown(value)}.")
    physics = profile_for(env_id).physics
    if physics is None:
        with_physics = [p.ids[0] for p in all_profiles() if p.physics is not None]
        raise reader.error(
            field,
            f"applies to environments with physics to set ({', '.join(with_physics)}), but "
            f"env.id is {shown(env_id)}.",
        )
    keys = physics.keys if kind == "physics" else physics.randomizable
    for key in value:
        if key not in keys:
            raise reader.unknown(field, key, list(keys))
    return value, physics


def _physics(reader: _Reader, env_id: str) -> Mapping[str, float | str]:
    value, spec = _physics_mapping(reader, "env.physics", env_id, "physics")
    physics: dict[str, float | str] = {}
    if spec is None:
        return MappingProxyType(physics)
    for key in spec.keys:  # canonical order
        if key not in value:
            continue
        field = f"env.physics.{key}"
        if key in spec.choices:
            physics[key] = reader.choice(field, value[key], spec.choices[key])
        else:
            physics[key] = reader.number(field, value[key], spec.ranges[key])
    return MappingProxyType(physics)


def _randomize(reader: _Reader, env_id: str) -> Mapping[str, tuple[float, float]]:
    value, spec = _physics_mapping(reader, "env.randomize", env_id, "randomize")
    ranges: dict[str, tuple[float, float]] = {}
    if spec is None:
        return MappingProxyType(ranges)
    for key in spec.randomizable:  # the order of the draws
        if key not in value:
            continue
        field = f"env.randomize.{key}"
        pair = value[key]
        if not isinstance(pair, list) or len(pair) != 2:
            raise reader.error(field, f"must be [low, high], got {shown(pair)}.")
        low = reader.number(f"{field}[0]", pair[0], spec.ranges[key])
        high = reader.number(f"{field}[1]", pair[1], spec.ranges[key])
        if low > high:
            raise reader.error(field, f"low ({low}) must not be above high ({high}).")
        ranges[key] = (low, high)
    return MappingProxyType(ranges)


def _algorithm_params(reader: _Reader) -> Mapping[str, ParamValue]:
    """The chosen algorithm's own keys, defaults filled; other algorithms' keys ignored.

    A key of another algorithm does not apply to this one (a sweep or a study may vary
    ``agent.algorithm`` over a base that sets ``agent.lambda``), so it is left out of the
    config; a key of no algorithm was refused as unknown already.
    """
    agent = reader.raw["agent"]
    algorithm = get_algorithm(agent["algorithm"])  # valid: it was read before
    values: dict[str, ParamValue] = {}
    for param in algorithm.params:
        given = agent.get(param.key, param.default)
        if param.kind == "str" and given in ("", None):  # text left out (a path not given)
            values[param.key] = ""
            continue
        values[param.key] = reader.value(f"agent.{param.key}", given, param)
        if param.kind == "str":  # a path: kept absolute, as given from the current directory
            values[param.key] = os.path.abspath(os.path.expanduser(str(values[param.key])))
    return MappingProxyType(values)


# -- one value of one kind ------------------------------------------------------------------


class _Reader:
    """Typed, range-checked access to the merged raw mapping, with precise error messages."""

    def __init__(self, raw: dict[str, Any], source: Provenance) -> None:
        self.raw = raw
        self._source = source

    def error(self, field: str, problem: str) -> ConfigError:
        return ConfigError(f"{self._source.of(field)}: {field}: {problem}")

    def unknown(self, field: str, key: Any, valid: list[str]) -> ConfigError:
        return ConfigError(f"{self._source.of(field)}: {unknown_key(key, valid, f'{field}.')}")

    def value_at(self, field: str) -> Any:
        section, _, key = field.rpartition(".")
        return (self.raw[section] if section else self.raw)[key]

    def fields(
        self,
        record: type,
        prefix: str,
        *,
        only: tuple[str, ...] = (),
        skip: tuple[str, ...] = (),
        ranges: Mapping[str, Key] | None = None,
    ) -> dict[str, Any]:
        """Read a record's fields in declaration order (or ``only`` some), but ``skip``.

        The kinds a rule above reads (sections, physics, the algorithm's own keys) are left
        to the rule. ``ranges`` replaces some fields' keys (a range another key widens).
        """
        values: dict[str, Any] = {}
        for item in dataclasses.fields(record):
            key = (ranges or {}).get(item.name) or key_of(item)
            if (only and item.name not in only) or item.name in skip or key.kind in _RULED:
                continue
            field = f"{prefix}{item.name}"
            value = self.value_at(field)
            values[item.name] = (
                None if key.nullable and value is None else self.value(field, value, key)
            )
        return values

    def field(self, record: type, prefix: str, name: str) -> Any:
        """Read one field of a section."""
        return self.fields(record, prefix, only=(name,))[name]

    def value(self, field: str, value: Any, spec: Spec) -> Any:
        """Check one value of the kind ``spec`` names (a :class:`Key`'s, a ``Param``'s)."""
        match spec.kind:
            case "name":
                return self.run_name(field, value)
            case "str":
                return self.string(field, value)
            case "int":
                return self.integer(field, value, spec.low, spec.high)
            case "float":
                return self.number(field, value, spec)
            case "bool":
                return self.boolean(field, value)
            case "choice":
                return self.choice(field, value, spec.choices)
            case "algorithm":
                return self.choice(field, value, algorithm_names())
            case "schedule":
                return self.schedule(field, value, spec)
            case "seeds":
                return self.seeds(field, value)
            case "bins":
                return self.bins(field, value)
            case "floats":
                return self.number_list(field, value)
            case "kwargs":
                return self.kwargs(field, value)
            case "info_key":
                return self.info_key(field, value)
        raise ValueError(f"{field}: no reader for the kind {spec.kind!r}")

    # -- scalars ------------------------------------------------------------------------

    def number(self, field: str, value: Any, bounds: Bounds | None = None) -> float:
        number = _as_number(value)
        if number is None:
            raise self.error(field, f"must be a number, got {shown(value)}.")
        if not math.isfinite(number):
            raise self.error(field, f"must be a finite number, got {shown(value)}.")
        if bounds is not None:
            low = -math.inf if bounds.low is None else bounds.low
            high = math.inf if bounds.high is None else bounds.high
            too_low = number <= low if bounds.low_open else number < low
            if too_low or number > high:
                raise self.error(field, f"must be in {bounds.interval}, got {shown(value)}.")
        return number

    def integer(
        self, field: str, value: Any, minimum: float | None, maximum: float | None = None
    ) -> int:
        # Written as digits (10), as a float (10.0, 1e3) or as a string YAML left (5e3):
        # the same integer, within the same range. No field's range reaches 2^53, so a
        # float inside it is an integer exactly, and one outside it is refused the same
        # way, however large, as the integer it would stand for.
        highest = EXACT_INTEGER - 1 if maximum is None else min(int(maximum), EXACT_INTEGER - 1)
        number = _as_number(value)
        if number is None or not math.isfinite(number) or number != int(number):
            raise self.error(field, f"must be an integer, got {shown(value)}.")
        if minimum is not None and number < minimum:
            raise self.error(field, f"must be at least {int(minimum)}, got {shown(value)}.")
        if (value if isinstance(value, int) else number) > highest:
            raise self.error(
                field, f"must be an integer no larger than {highest}, got {shown(value)}."
            )
        return int(value) if isinstance(value, int) else int(number)

    def boolean(self, field: str, value: Any) -> bool:
        if not isinstance(value, bool):
            raise self.error(field, f"must be true or false, got {shown(value)}.")
        return value

    def info_key(self, field: str, value: Any) -> str:
        if not isinstance(value, str) or not INFO_KEY_PATTERN.match(value):
            raise self.error(
                field,
                f"must be a key of the environment's info such as left_from_a (a letter or "
                f"_, then letters, digits or _; at most 64), got {shown(value)}.",
            )
        return value

    def string(self, field: str, value: Any) -> str:
        if not isinstance(value, str) or not value:
            raise self.error(field, f"must be a non-empty string, got {shown(value)}.")
        return value

    def run_name(self, field: str, value: Any) -> str:
        name = self.string(field, value)
        if not _NAME_PATTERN.fullmatch(name):
            raise self.error(
                field,
                f"must be 1-64 letters, digits, '-' or '_' (it names a directory; no path "
                f"separators or '..'), got {shown(name)}.",
            )
        return name

    def choice(self, field: str, value: Any, choices: tuple[str, ...]) -> str:
        if value not in choices:
            raise self.error(field, f"must be one of {', '.join(choices)}; got {shown(value)}.")
        return str(value)

    # -- composites ---------------------------------------------------------------------

    def number_list(self, field: str, values: Any) -> tuple[float, ...]:
        if not isinstance(values, list) or not values:
            raise self.error(field, f"must be a non-empty list of numbers, got {shown(values)}.")
        return tuple(self.number(f"{field}[{i}]", v) for i, v in enumerate(values))

    def bins(self, field: str, values: Any) -> tuple[int, ...]:
        if not isinstance(values, list) or not values:
            raise self.error(
                field, f"must be a non-empty list of positive integers, got {shown(values)}."
            )
        result = []
        for i, value in enumerate(values):
            number = _as_number(value)
            if number is None or not math.isfinite(number) or number != int(number):
                raise self.error(
                    field, f"entry {i} must be a positive integer, got {shown(value)}."
                )
            if number < 1:
                raise self.error(field, f"entry {i} must be at least 1, got {shown(value)}.")
            result.append(int(number))
        return tuple(result)

    def schedule(self, field: str, value: Any, bounds: Spec) -> Schedule:
        """A number (a constant) or a mapping with a ``type`` and that type's keys.

        A step size (a :class:`Key` with ``sample_average``) may also be ``sample_average``,
        written alone or as ``{type: sample_average}``.
        """
        if value == SAMPLE_AVERAGE_KIND or (
            isinstance(value, dict) and value.get("type") == SAMPLE_AVERAGE_KIND
        ):
            if not (isinstance(bounds, Key) and bounds.sample_average):
                raise self.error(
                    field,
                    "cannot be sample_average: only agent.alpha, a step size, can (a step of "
                    "1 / N per update); give a number or a schedule.",
                )
            for key in value if isinstance(value, dict) else ():
                if key != "type":
                    raise self.unknown(field, key, ["type"])
            return Schedule(SAMPLE_AVERAGE_KIND, 0.0, 0.0)
        if not isinstance(value, dict):
            constant = self.number(field, value, bounds)
            return Schedule("constant", constant, constant)
        kind = value.get("type")
        kinds = ", ".join(SCHEDULE_KINDS)
        if isinstance(bounds, Key) and bounds.sample_average:
            kinds += f" (or {SAMPLE_AVERAGE_KIND})"
        if kind is None:
            raise self.error(
                field,
                f"a schedule mapping needs 'type' ({kinds}), got {shown(value)}; a number is a "
                "constant.",
            )
        if kind not in SCHEDULE_KINDS:
            raise self.error(f"{field}.type", f"must be one of {kinds}; got {shown(kind)}.")
        form = SCHEDULE_FORMS[kind]
        names = ["type", *(schedule_key.name for schedule_key in form)]
        for key in value:
            if key not in names:
                raise self.unknown(field, key, names)
        for schedule_key in form:
            if schedule_key.default is None and schedule_key.name not in value:
                raise self.error(field, f"a {kind} schedule needs '{schedule_key.name}'.")
        values: dict[str, float] = {}
        # End first, then start, then the rate: the order messages have always come in.
        for schedule_key in sorted(form, key=lambda k: ("end", "start", "rate").index(k.field)):
            values[schedule_key.field] = self.number(
                f"{field}.{schedule_key.name}",
                value.get(schedule_key.name, schedule_key.default),
                schedule_key.bounds or bounds,
            )
        values.setdefault("end", values["start"])  # a constant ends where it starts
        return Schedule(kind, **values)

    def seeds(self, field: str, value: Any) -> tuple[int, ...]:
        try:
            return parse_seeds(value)
        except ValueError as error:
            raise self.error(field, str(error)) from None

    def kwargs(self, field: str, value: Any) -> Mapping[str, Any]:
        if value is None:
            return MappingProxyType({})
        if not isinstance(value, dict) or not all(isinstance(key, str) for key in value):
            raise self.error(
                field, f"must be a mapping of argument names to values, got {shown(value)}."
            )
        if "render_mode" in value:
            # Training never draws, and a window opened with no display fails only after
            # the environment is made; the commands that draw set the mode themselves.
            raise self.error(
                f"{field}.render_mode",
                "cannot be set in a config: training never renders, and cartpole-q sets the "
                "render mode itself where it draws. Watch a policy with `cartpole-q eval RUN "
                "--render` (needs a display), record it with `cartpole-q eval RUN --video "
                "FILE.gif`, or use `train --watch N` or `--video-every N` while training.",
            )
        steps = value.get("max_episode_steps")
        if "max_episode_steps" in value and (
            isinstance(steps, bool) or not isinstance(steps, int) or steps < 1
        ):
            raise self.error(
                f"{field}.max_episode_steps",
                f"the time limit must be a positive whole number of steps, got {shown(steps)}.",
            )
        return MappingProxyType(copy.deepcopy(value))


def parse_seeds(value: Any) -> tuple[int, ...]:
    """Parse a seed list: an integer, a list of integers, or a string like ``"0-9,20"``.

    Returns:
        The seeds in ascending order.

    Raises:
        ValueError: the value is not a seed list, a seed is negative or given twice (a
            typo more likely than a wish to run it once), or there are too many.

    >>> parse_seeds("0-3,7")
    (0, 1, 2, 3, 7)
    >>> parse_seeds("0-9,5")
    Traceback (most recent call last):
    ...
    ValueError: seed 5 is given twice; each seed is one run, so give it once.
    """
    seeds: list[int] = []
    if isinstance(value, bool):
        raise ValueError(f"must be seeds like '0-99' or [0, 1, 2], got {shown(value)}.")
    if isinstance(value, int):
        seeds = [value]
    elif isinstance(value, list) and value:
        for item in value:
            if isinstance(item, bool) or not isinstance(item, int):
                raise ValueError(f"every seed must be an integer, got {shown(item)}.")
            seeds.append(item)
    elif isinstance(value, str) and value.strip():
        for part in value.split(","):
            match = re.fullmatch(r"\s*(\d+)\s*(?:-\s*(\d+)\s*)?", part)
            if not match:
                raise ValueError(f"must be seeds like '0-99' or '0,5,10-19', got {shown(value)}.")
            first, last = int(match[1]), int(match[2] or match[1])
            if last < first:
                raise ValueError(f"range '{part.strip()}' runs backwards.")
            if last - first >= MAX_SEEDS:
                raise ValueError(f"at most {MAX_SEEDS} seeds, got range '{part.strip()}'.")
            seeds.extend(range(first, last + 1))
    else:
        raise ValueError(f"must be seeds like '0-99' or [0, 1, 2], got {shown(value)}.")
    if any(seed < 0 for seed in seeds):
        raise ValueError("seeds must be non-negative.")
    if any(seed > MAX_SEED for seed in seeds):
        raise ValueError(f"seeds must be at most {MAX_SEED:,}.")
    unique = sorted(set(seeds))
    if len(unique) < len(seeds):
        repeated = sorted(seed for seed, count in Counter(seeds).items() if count > 1)
        named = (
            f"seed {repeated[0]} is"
            if len(repeated) == 1
            else f"seeds {format_seeds(repeated)} are"
        )
        raise ValueError(f"{named} given twice; each seed is one run, so give it once.")
    if len(unique) > MAX_SEEDS:
        raise ValueError(f"at most {MAX_SEEDS} seeds, got {len(unique)}.")
    return tuple(unique)


def _as_number(value: Any) -> float | None:
    """Return ``value`` as a float if it is a number or a numeric string like ``5e-4``."""
    if isinstance(value, bool):
        return None
    if isinstance(value, int | float):
        return float(value)
    if isinstance(value, str) and _NUMBER_PATTERN.fullmatch(value.strip()):
        return float(value)
    return None
