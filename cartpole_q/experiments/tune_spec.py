"""The tune file: a base config, the seeds every trial runs, and ranges of config keys to search.

Checked before any trial starts, like a config: unknown keys (with the closest valid one),
empty or reversed ranges, a ``log`` range touching 0, and choices that are not valid
values for their key are refused, naming the file and the key.
"""

from __future__ import annotations

import contextlib
import difflib
import math
import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from cartpole_q.config import (
    Config,
    ConfigError,
    format_seeds,
    load_config,
    parse_seeds,
    read_yaml_mapping,
    shown,
    shown_value,
)
from cartpole_q.experiments.sweep_spec import (
    FORBIDDEN_AXES,
    check_overlaps,
    check_top_keys,
    checked_name,
    load_base,
    safe_name,
)
from cartpole_q.rl.algorithms import get as get_algorithm
from cartpole_q.store.sweepdir import axis_cell

TUNE_KEYS = ("name", "base", "seeds", "trials", "objective", "space", "sampler", "pruner")
OBJECTIVES = ("success_rate", "iqm_eval_return")
SAMPLERS = ("tpe", "random")
RANGE_KEYS = ("low", "high", "log", "step", "int")
_NAME = re.compile(r"[A-Za-z0-9_-]+")
MAX_TRIALS = 100_000


@dataclass(frozen=True)
class Dimension:
    """One searched key: a float or int range, or a list of choices."""

    key: str
    low: float | None = None
    high: float | None = None
    log: bool = False
    step: float | None = None
    integer: bool = False
    choices: tuple[Any, ...] = ()

    def probes(self) -> tuple[Any, ...]:
        """Values a trial may take, checked against the key before any trial.

        Both ends and one inside, which is not a whole number unless the range is ``int``,
        so that a float range on an integer key is refused at once.
        """
        assert self.low is not None and self.high is not None
        if self.integer:
            return (int(self.low), int(self.high), int((self.low + self.high) // 2))
        return (self.low, self.high, self.low + (self.high - self.low) * 0.37)

    def to_dict(self) -> dict[str, Any]:
        """The dimension as the tune file writes it."""
        if self.choices:
            return {"choices": list(self.choices)}
        out: dict[str, Any] = {"low": self.low, "high": self.high}
        if self.log:
            out["log"] = True
        if self.step is not None:
            out["step"] = self.step
        if self.integer:
            out["int"] = True
        return out


@dataclass(frozen=True)
class TuneSpec:
    """A checked tune file."""

    name: str
    base: dict[str, Any]
    seeds: tuple[int, ...]
    trials: int
    objective: str
    space: tuple[Dimension, ...]
    sampler: dict[str, Any]
    pruner: bool = False
    extra: dict[str, Any] = field(default_factory=dict)

    def config_for(self, values: Mapping[str, Any], where: str = "tune") -> Config:
        """The complete config of a trial: the base with the trial's values."""
        return load_config(self.base, dict(values), source=where, override_source=where)

    def to_dict(self) -> dict[str, Any]:
        """The resolved tune file, as ``tune.yaml`` holds it."""
        return {
            "name": self.name,
            "base": self.base,
            "seeds": format_seeds(self.seeds),
            "trials": self.trials,
            "objective": self.objective,
            "space": {d.key: d.to_dict() for d in self.space},
            "sampler": self.sampler,
            "pruner": self.pruner,
        }


def load_tune(source: Path | Mapping[str, Any], *, label: str | None = None) -> TuneSpec:
    """Read and check a tune file (or a mapping laid out like one).

    Raises:
        ConfigError: naming the file and the key.
    """
    if isinstance(source, Mapping):
        raw: Mapping[str, Any] = source
        where, base_dir, default_name = label or "tune mapping", Path(), "tune"
    else:
        raw = read_yaml_mapping(source, "tune file")
        where, base_dir, default_name = label or str(source), source.parent, safe_name(source.stem)
    check_top_keys(raw, TUNE_KEYS, where)
    name = checked_name(raw, default_name, where)
    loaded = load_base(raw.get("base"), where, base_dir)
    if get_algorithm(loaded.agent.algorithm).predicts:
        raise ConfigError(
            f"{where}: base: agent.algorithm {loaded.agent.algorithm} is a prediction "
            "algorithm: its runs have no greedy policy to score, so tune has nothing to "
            "optimise; a sweep over its keys with figure.metric: rms_error compares them."
        )
    base = loaded.to_dict()
    try:
        seeds = parse_seeds(raw.get("seeds", "0-19"))
    except ValueError as error:
        raise ConfigError(f"{where}: seeds: {error}") from None
    trials = raw.get("trials", 100)
    if isinstance(trials, bool) or not isinstance(trials, int) or not 1 <= trials <= MAX_TRIALS:
        raise ConfigError(
            f"{where}: trials: must be an integer from 1 to {MAX_TRIALS:,}, got {shown_value(trials)}."
        )
    objective = raw.get("objective", "success_rate")
    if objective not in OBJECTIVES:
        raise ConfigError(
            f"{where}: objective: must be one of {', '.join(OBJECTIVES)}, got {shown_value(objective)}."
        )
    sampler = _sampler(raw.get("sampler"), where)
    pruner = raw.get("pruner", False)
    if not isinstance(pruner, bool):
        raise ConfigError(
            f"{where}: pruner: must be true or false (stop a trial once it cannot beat the best)."
        )
    if pruner and objective != "success_rate":
        raise ConfigError(
            f"{where}: pruner: works with objective success_rate only (a trial is stopped when even "
            "all its remaining seeds succeeding could not beat the best trial)."
        )
    space = _space(raw.get("space"), where, base)
    return TuneSpec(name, base, seeds, trials, objective, space, sampler, pruner)


def _sampler(value: Any, where: str) -> dict[str, Any]:
    if value is None:
        return {"type": "tpe", "seed": 0}
    if not isinstance(value, Mapping):
        raise ConfigError(f"{where}: sampler: must be a mapping like {{type: tpe, seed: 0}}.")
    for key in value:
        if key not in ("type", "seed"):
            raise ConfigError(
                f"{where}: sampler: unknown key {shown(key)}; valid keys: type, seed."
            )
    kind = value.get("type", "tpe")
    if kind not in SAMPLERS:
        raise ConfigError(
            f"{where}: sampler.type: must be one of {', '.join(SAMPLERS)}, got {shown_value(kind)}."
        )
    seed = value.get("seed", 0)
    if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
        raise ConfigError(
            f"{where}: sampler.seed: must be a non-negative integer, got {shown_value(seed)}."
        )
    return {"type": kind, "seed": seed}


def _space(value: Any, where: str, base: dict[str, Any]) -> tuple[Dimension, ...]:
    if not isinstance(value, Mapping) or not value:
        raise ConfigError(
            f"{where}: space: must map dotted config keys to ranges or choices, e.g. "
            "space: {agent.alpha: {low: 0.01, high: 1.0, log: true}}."
        )
    dimensions = []
    checked: set[str] = set()
    for key, spec in value.items():
        label = f"{where}: space.{key}"
        if not isinstance(key, str) or key in FORBIDDEN_AXES or key.startswith("train.seeds"):
            raise ConfigError(
                f"{label}: cannot be searched; the tune file's `seeds` say which seeds every trial runs."
            )
        if not isinstance(spec, Mapping):
            raise ConfigError(
                f"{label}: must be a range {{low: 0.1, high: 1.0}} or {{choices: [a, b]}}."
            )
        if "choices" in spec:
            dimension = _choices(key, spec, label)
            tried = dimension.choices
        else:
            dimension = _range(key, spec, label)
            tried = dimension.probes()
        for candidate in tried:
            source = f"{label} ({axis_cell(candidate)})"
            # The base was checked alone: whatever is wrong now comes with this value.
            config = load_config(base, {key: candidate}, source=source, override_source=source)
            check_environment(config, source, checked)
        dimensions.append(dimension)
    check_overlaps([dimension.key for dimension in dimensions], where)
    return tuple(dimensions)


def check_environment(config: Config, source: str, checked: set[str]) -> None:
    """Check a config against its environment (an id, bins of the wrong length, ...).

    ``checked`` remembers what was checked already (the same environment and grid).

    Raises:
        ConfigError: naming ``source`` (the file, the key and the value) and the field.
    """
    from cartpole_q.experiments.run import prepare

    part = repr((config.env, config.discretization, config.engine, config.agent))
    if part not in checked:
        prepare(config, source)
        checked.add(part)


def _choices(key: str, spec: Mapping[str, Any], label: str) -> Dimension:
    if set(spec) != {"choices"}:
        raise ConfigError(
            f"{label}: a choice dimension has only `choices`, got {', '.join(map(str, spec))}."
        )
    choices = spec["choices"]
    if not isinstance(choices, list) or not choices:
        raise ConfigError(f"{label}: choices: must be a non-empty list.")
    if len({axis_cell(choice) for choice in choices}) != len(choices):
        raise ConfigError(f"{label}: choices: has the same value twice.")
    return Dimension(key, choices=tuple(choices))


def _range(key: str, spec: Mapping[str, Any], label: str) -> Dimension:
    for name in spec:
        if name not in RANGE_KEYS:
            close = difflib.get_close_matches(str(name), (*RANGE_KEYS, "choices"), n=1)
            hint = f"; did you mean {close[0]!r}?" if close else ""
            raise ConfigError(f"{label}: unknown key {shown(name)}{hint}")
    if "low" not in spec or "high" not in spec:
        raise ConfigError(f"{label}: a range needs both low and high.")
    low, high = _number(spec["low"], f"{label}.low"), _number(spec["high"], f"{label}.high")
    if low > high:
        raise ConfigError(f"{label}: low ({low:g}) is above high ({high:g}).")
    if low == high:
        raise ConfigError(
            f"{label}: the range is empty (low = high = {low:g}); give the value in base instead."
        )
    log = spec.get("log", False)
    integer = spec.get("int", False)
    if not isinstance(log, bool) or not isinstance(integer, bool):
        raise ConfigError(f"{label}: log and int must be true or false.")
    if log and low <= 0:
        raise ConfigError(f"{label}: a log range must stay above 0, but low is {low:g}.")
    step = spec.get("step")
    if step is not None:
        step = _number(step, f"{label}.step")
        if step <= 0 or log:
            raise ConfigError(f"{label}: step must be above 0, and cannot go with log.")
    if integer and (low != int(low) or high != int(high)):
        raise ConfigError(f"{label}: an int range needs whole low and high.")
    if integer and step is not None and step != int(step):
        raise ConfigError(f"{label}: an int range needs a whole step, got {step:g}.")
    if step is not None:
        steps = (high - low) / step
        if step > high - low or abs(steps - round(steps)) > 1e-9 * max(1.0, steps):
            fitted = low + math.floor(steps + 1e-9) * step
            raise ConfigError(
                f"{label}: step {step:g} does not divide the range {low:g} to {high:g} (Optuna "
                f"would quietly end it at {fitted:g}); give a high of low + k * step."
            )
    return Dimension(key, low, high, log, step, integer)


def _number(value: Any, label: str) -> float:
    if isinstance(value, str):
        with contextlib.suppress(ValueError):
            value = float(value)  # YAML reads 5e-4 as a string
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise ConfigError(f"{label}: must be a number, got {shown_value(value)}.")
    return float(value)
