"""Chapter 8's planning studies (``cartpole-q updates``): a study file, its curves, its figure.

Two kinds of study (``figure.kind``), both run outside the episode loop:

- ``expected_vs_sample`` (Figure 8.7): for each branching factor ``b`` of ``branching``,
  one problem per seed (:func:`~cartpole_q.rl.planning_updates.sample_update_errors`); the
  RMS error over the problems after ``t = 0, ..., 2b`` computations.
- ``trajectory_sampling`` (Figure 8.8): for each panel (a number of states, its
  branching factors, its updates and how often the start state is valued), one task per
  seed, run with uniform and with on-policy updates
  (:mod:`cartpole_q.engines.trajectory`); each point averaged over the tasks.

:func:`write_study` draws the figure with its data beside it (``<figure>.csv``).
"""

from __future__ import annotations

import contextlib
import math
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from cartpole_q.config import ConfigError, parse_seeds, shown_value
from cartpole_q.experiments.sweep_spec import (
    check_top_keys,
    checked_figure_section,
    read_study_file,
)

STUDY_KEYS = (
    "name", "seeds", "branching", "initial_error", "panels", "actions", "epsilon",
    "termination", "tolerance", "figure",
)  # fmt: skip
"""the keys a study file may have"""
KIND_KEYS = {
    "expected_vs_sample": ("branching", "initial_error"),
    "trajectory_sampling": ("panels", "actions", "epsilon", "termination", "tolerance"),
}
"""the keys each figure kind takes (beside ``name``, ``seeds`` and ``figure``)"""
FIGURE_KINDS = tuple(KIND_KEYS)
FIGURE_KEYS = ("kind", "file", "title")
PANEL_KEYS = ("states", "branching", "updates", "every")
Z_95 = 1.959963984540054


@dataclass(frozen=True)
class Panel:
    """A panel of Figure 8.8: tasks of ``states`` states, one curve pair per branching."""

    states: int
    branching: tuple[int, ...]
    updates: int
    """expected updates per run"""
    every: int
    """the start state is valued after every ``every`` updates (and before the first)"""


@dataclass(frozen=True)
class Study:
    """A checked study file."""

    name: str
    kind: str
    seeds: tuple[int, ...]
    branching: tuple[int, ...]
    """``expected_vs_sample``: the branching factors"""
    initial_error: float
    panels: tuple[Panel, ...]
    """``trajectory_sampling``: the panels"""
    actions: int
    epsilon: float
    termination: float
    tolerance: float
    file: str
    title: str
    where: str


@dataclass(frozen=True)
class Curve:
    """A curve averaged over seeds: its points' x, mean, and 95% interval (or none)."""

    label: str
    x: np.ndarray
    mean: np.ndarray
    low: np.ndarray | None
    high: np.ndarray | None


@dataclass(frozen=True)
class Outcome:
    """What a study computed."""

    curves: list[list[Curve]]
    """per panel (``expected_vs_sample``: one), its curves (``trajectory_sampling``: uniform
    then on-policy for each branching)"""
    largest_expected_error: float
    """``expected_vs_sample``: the largest ``|error|`` of the expected update after ``b``
    computations, over every problem (0 exactly)"""
    seconds: float


def _number(raw: Mapping[str, Any], key: str, default: float, where: str) -> float:
    value = raw.get(key, default)
    if isinstance(value, str):  # YAML reads 1e-10 as a string
        with contextlib.suppress(ValueError):
            value = float(value)
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise ConfigError(f"{where}: {key}: must be a number, got {shown_value(value)}.")
    return float(value)


def _whole(raw: Mapping[str, Any], key: str, default: int | None, where: str, least: int) -> int:
    value = raw.get(key, default)
    if isinstance(value, bool) or not isinstance(value, int) or value < least:
        raise ConfigError(
            f"{where}: {key}: must be a whole number >= {least}, got {shown_value(value)}."
        )
    return value


def _branching(raw: Mapping[str, Any], where: str, least: int) -> tuple[int, ...]:
    value = raw.get("branching")
    if (
        not isinstance(value, list)
        or not value
        or not all(isinstance(b, int) and not isinstance(b, bool) and b >= least for b in value)
    ):
        raise ConfigError(
            f"{where}: branching: must be a list of whole numbers >= {least} (such as [2, 10, "
            f"100]), got {shown_value(value)}."
        )
    return tuple(value)


def load_study(path: Path) -> Study:
    """Read and check a study file.

    Raises:
        ConfigError: naming the file and the key, with what is wrong.
    """
    raw, where, name = read_study_file(
        path,
        STUDY_KEYS,
        "`seeds`, `figure` and the figure kind's keys",
        "examples/book/fig8_7_expected_vs_sample.yaml",
    )
    kind, file, title = checked_figure_section(
        raw.get("figure"), name, where, FIGURE_KEYS, FIGURE_KINDS
    )
    for key in raw:
        if key in STUDY_KEYS and key not in ("name", "seeds", "figure", *KIND_KEYS[kind]):
            raise ConfigError(
                f"{where}: {key}: {'an' if kind[0] in 'aeiou' else 'a'} {kind} study takes no {key} (it takes "
                f"{', '.join(KIND_KEYS[kind])})."
            )
    if "seeds" not in raw:
        raise ConfigError(
            f"{where}: seeds: is missing; one problem (or task) per seed, such as 0-99."
        )
    try:
        seeds = parse_seeds(raw["seeds"])
    except ValueError as error:
        raise ConfigError(f"{where}: seeds: {error}") from None
    branching: tuple[int, ...] = ()
    panels: tuple[Panel, ...] = ()
    initial_error = _number(raw, "initial_error", 1.0, where)
    if initial_error < 0:
        raise ConfigError(f"{where}: initial_error: must not be negative, got {initial_error:g}.")
    actions = _whole(raw, "actions", 2, where, 1)
    epsilon = _number(raw, "epsilon", 0.1, where)
    termination = _number(raw, "termination", 0.1, where)
    tolerance = _number(raw, "tolerance", 1e-9, where)
    if kind == "expected_vs_sample":
        branching = _branching(raw, where, 2)
    else:
        if not 0.0 <= epsilon <= 1.0:
            raise ConfigError(f"{where}: epsilon: must be in [0, 1], got {epsilon:g}.")
        if not 0.0 < termination <= 1.0:
            raise ConfigError(
                f"{where}: termination: must be in (0, 1] (the evaluation needs episodes to "
                f"end), got {termination:g}."
            )
        if tolerance <= 0:
            raise ConfigError(f"{where}: tolerance: must be positive, got {tolerance:g}.")
        panels_raw = raw.get("panels")
        if not isinstance(panels_raw, list) or not panels_raw:
            raise ConfigError(
                f"{where}: panels: must be a list such as [{{states: 1000, branching: [1, 3], "
                f"updates: 20000, every: 500}}], got {shown_value(panels_raw)}."
            )
        panels = tuple(_panel(entry, index, where) for index, entry in enumerate(panels_raw))
    return Study(
        name, kind, seeds, branching, initial_error, panels, actions, epsilon, termination,
        tolerance, file, title, where,
    )  # fmt: skip


def _panel(raw: Any, index: int, where: str) -> Panel:
    here = f"{where}: panels[{index}]"
    if not isinstance(raw, Mapping):
        raise ConfigError(
            f"{here}: must be a mapping {{states, branching, updates, every}}, got "
            f"{shown_value(raw)}."
        )
    check_top_keys(raw, PANEL_KEYS, here)
    for key in PANEL_KEYS:
        if key not in raw:
            raise ConfigError(f"{here}.{key}: is missing.")
    states = _whole(raw, "states", None, here, 1)
    branching = _branching(raw, here, 1)
    updates = _whole(raw, "updates", None, here, 1)
    every = _whole(raw, "every", None, here, 1)
    if updates % every:
        raise ConfigError(f"{here}.every: must divide updates ({updates:,}), got {every:,}.")
    return Panel(states, branching, updates, every)


def _averaged(label: str, x: np.ndarray, rows: np.ndarray, interval: bool) -> Curve:
    """The mean over the rows (summed in order from 0.0) and, with ``interval``, mean ± z·s/√n."""
    total = np.zeros(rows.shape[1])
    for row in rows:
        total = total + row
    count = rows.shape[0]
    mean = total / count
    if not interval or count < 2:
        return Curve(label, x, mean, None, None)
    squares = np.zeros(rows.shape[1])
    for row in rows:
        squares = squares + (row - mean) * (row - mean)
    half = Z_95 * np.sqrt(squares / (count - 1)) / math.sqrt(count)
    return Curve(label, x, mean, mean - half, mean + half)


def run_study(study: Study, stop: Callable[[], bool] | None = None) -> Outcome | None:
    """Compute every curve; ``None`` when ``stop`` (asked before each task) says so."""
    start = time.perf_counter()
    if study.kind == "expected_vs_sample":
        from cartpole_q.rl.planning_updates import rms_over_problems, sample_update_errors

        curves, largest = [], 0.0
        for branching in study.branching:
            if stop is not None and stop():
                return None
            sample, expected = sample_update_errors(
                list(study.seeds), branching, study.initial_error
            )
            largest = max(largest, float(np.max(np.abs(expected[:, branching:]))))
            x = np.arange(2 * branching + 1) / branching
            curves.append(Curve(f"b = {branching}", x, rms_over_problems(sample), None, None))
        return Outcome([curves], largest, time.perf_counter() - start)
    from cartpole_q.engines.trajectory import task_curves

    panels = []
    for panel in study.panels:
        points = np.arange(panel.updates // panel.every + 1) * panel.every
        curves = []
        for branching in panel.branching:
            uniform, on_policy = [], []
            for seed in study.seeds:
                if stop is not None and stop():
                    return None
                one, other = task_curves(
                    seed, panel.states, study.actions, branching, panel.updates, panel.every,
                    study.termination, study.epsilon, study.tolerance,
                )  # fmt: skip
                uniform.append(one)
                on_policy.append(other)
            curves.append(_averaged(f"b = {branching}, uniform", points, np.array(uniform), True))
            curves.append(
                _averaged(f"b = {branching}, on-policy", points, np.array(on_policy), True)
            )
        panels.append(curves)
    return Outcome(panels, 0.0, time.perf_counter() - start)


def _panel_name(panel: Panel) -> str:
    return f"{panel.states:,} states"


def summary(study: Study, outcome: Outcome) -> list[str]:
    """Lines saying what ran and the key numbers of every curve."""
    seeds = len(study.seeds)
    if study.kind == "expected_vs_sample":
        lines = [
            f"{study.name}: {seeds} problems per branching factor, initial error "
            f"{study.initial_error:g}, {outcome.seconds:.1f} s",
            "  RMS error of sample updates after t computations; the book's sqrt((b-1)/(b t)) "
            "in brackets:",
        ]
        for branching, curve in zip(study.branching, outcome.curves[0], strict=True):
            shown = []
            for t in sorted({1, max(1, branching // 10), branching, 2 * branching}):
                formula = math.sqrt((branching - 1) / (branching * t))
                shown.append(f"t = {_t_text(t, branching)}: {curve.mean[t]:.4f} [{formula:.4f}]")
            lines.append(f"  b = {branching:,}: " + "; ".join(shown))
        lines.append(
            "  expected updates: error "
            f"{study.initial_error:g} until b computations, then "
            f"{outcome.largest_expected_error:g} (the largest |error| over every problem)"
        )
        return lines
    lines = [
        f"{study.name}: {seeds} tasks per curve, {study.actions} actions, epsilon "
        f"{study.epsilon:g}, termination {study.termination:g}, {outcome.seconds:.1f} s"
    ]
    for panel, curves in zip(study.panels, outcome.curves, strict=True):
        lines.append(f"  {_panel_name(panel)} (start state's greedy value, mean over tasks):")
        marks = sorted({panel.updates // 10, panel.updates // 4, panel.updates // 2, panel.updates})
        marks = [m - m % panel.every for m in marks]
        for index in range(0, len(curves), 2):
            uniform, on_policy = curves[index], curves[index + 1]
            label = uniform.label.partition(",")[0]
            values = "; ".join(
                f"{m:,}: {on_policy.mean[m // panel.every]:.3f} vs {uniform.mean[m // panel.every]:.3f}"
                for m in marks
            )
            lines.append(
                f"    {label}, on-policy vs uniform at {values}; {_crossing(uniform, on_policy)}"
            )
    return lines


def _t_text(t: int, branching: int) -> str:
    if t == branching:
        return "b"
    if t == 2 * branching:
        return "2b"
    if t * 10 == branching:
        return "b/10"
    return f"{t:,}"


def _crossing(uniform: Curve, on_policy: Curve) -> str:
    """Where uniform catches up: the first point from which it stays at or above on-policy."""
    below = np.flatnonzero(uniform.mean[1:] < on_policy.mean[1:])
    if below.size == 0:
        return "uniform at or above on-policy throughout"
    last = int(below[-1]) + 1
    if last == uniform.mean.shape[0] - 1:
        return "on-policy still above at the end"
    return f"uniform at or above on-policy from {int(uniform.x[last + 1]):,} updates on"


def study_figure(study: Study, outcome: Outcome) -> Any:
    """The study's figure (a :class:`~cartpole_q.figures.DataFigure`)."""
    from cartpole_q import figures

    if study.kind == "expected_vs_sample":
        return figures.expected_vs_sample_figure(
            [(b, curve.mean) for b, curve in zip(study.branching, outcome.curves[0], strict=True)],
            study.initial_error,
            study.title,
        )
    panels = []
    for panel, curves in zip(study.panels, outcome.curves, strict=True):
        drawn = [
            figures.TrajectoryCurve(
                curve.label, curve.x, curve.mean, curve.low, curve.high, "on-policy" in curve.label
            )
            for curve in curves
        ]
        panels.append((_panel_name(panel), drawn))
    return figures.trajectory_sampling_figure(panels, study.title)


def write_study(study: Study, outcome: Outcome, out: Path) -> Path:
    """Write the figure with its data (``<figure>.csv``) beside it."""
    from cartpole_q.store.figure_file import write_figure

    return write_figure(out, study_figure(study, outcome))


def check_outputs(out: Path, force: bool) -> None:
    """Refuse, before any work, outputs that exist (without ``force``) or cannot be written."""
    from cartpole_q.store.figure_file import check_figure_file

    check_figure_file(out, "--out", force)


def default_out(study: Study) -> Path:
    """The figure file when ``--out`` is not given: the study's ``figure.file`` here."""
    return Path(study.file)
