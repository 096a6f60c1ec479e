"""Chapter 8's planning studies (``cartpole-q updates``): a study file, its curves, its figure.

Three kinds of study (``figure.kind``), all run outside the engines' training runs:

- ``expected_vs_sample`` (Figure 8.7): for each branching factor ``b`` of ``branching``,
  one problem per seed (:func:`~cartpole_q.rl.planning_updates.sample_update_errors`); the
  RMS error over the problems after ``t = 0, ..., 2b`` computations.
- ``trajectory_sampling`` (Figure 8.8): for each panel (a number of states, its
  branching factors, its updates and how often the start state is valued), one task per
  seed, run with uniform and with on-policy updates
  (:mod:`cartpole_q.engines.trajectory`); each point averaged over the tasks.
- ``until_optimal`` (Example 8.4's figure): for each maze scale ``k`` of ``scales`` (the
  Dyna maze with every cell a ``k`` x ``k`` block, ``47 k²`` open cells) and each algorithm
  of ``methods``, one run per seed until the greedy path from the start is a shortest path
  (:mod:`cartpole_q.engines.until_optimal`); the mean number of updates over the runs, with
  the smallest and the largest.

:func:`write_study` draws the figure with its data beside it (``<figure>.csv``).
"""

from __future__ import annotations

import contextlib
import dataclasses
import functools
import math
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from cartpole_q.config import ConfigError, parse_seeds, read_yaml_mapping, shown_value
from cartpole_q.config.bounds import check_count, check_memory
from cartpole_q.experiments.study import (
    Finished,
    RunHandle,
    RunsKind,
    StudyFile,
    register_kind,
)
from cartpole_q.experiments.sweep_spec import (
    check_top_keys,
    checked_figure_section,
    checked_study,
)
from cartpole_q.progress import Units
from cartpole_q.store.studydir import Cell, RunRecord

STUDY_KEYS = (
    "name", "seeds", "branching", "initial_error", "panels", "actions", "epsilon",
    "termination", "tolerance", "scales", "methods", "alpha", "gamma", "planning_steps", "theta",
    "max_updates", "max_steps", "optimal_within", "figure",
)  # fmt: skip
"""the keys a study file may have"""
KIND_KEYS = {
    "expected_vs_sample": ("branching", "initial_error"),
    "trajectory_sampling": ("panels", "actions", "epsilon", "termination", "tolerance"),
    "until_optimal": (
        "scales", "methods", "alpha", "gamma", "epsilon", "planning_steps", "theta",
        "max_updates", "max_steps", "optimal_within",
    ),
}  # fmt: skip
"""the keys each figure kind takes (beside ``name``, ``seeds`` and ``figure``)"""
FIGURE_KINDS = tuple(KIND_KEYS)
FIGURE_KEYS = ("kind", "file", "title")
PANEL_KEYS = ("states", "branching", "updates", "every")
Z_95 = 1.959963984540054
UNTIL_OPTIMAL_METHODS = ("prioritized_sweeping", "dyna_q", "q_learning")
METHOD_LABELS = {
    "prioritized_sweeping": "Prioritized sweeping",
    "dyna_q": "Dyna-Q",
    "q_learning": "Q-learning",
}


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
    scales: tuple[tuple[int, int], ...] = ()
    """``until_optimal``: the mazes' blocks ``(rows, columns)`` (a scale ``k``: ``(k, k)``)"""
    methods: tuple[str, ...] = ()
    alpha: float = 0.5
    gamma: float = 0.95
    planning_steps: int = 5
    theta: float = 0.0001
    max_updates: int = 10_000_000
    max_steps: int = 20_000_000
    """``until_optimal``: a run gives up after the episode in which it took this many steps"""
    optimal_within: tuple[float, ...] = (1.0,)
    """``until_optimal``: the criteria, each a run's stop when its greedy path is at most
    that many times the shortest (1: a shortest path)"""


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
    seconds: float = 0.0
    """how long :func:`run_study` took (not part of the summary, which a resumed study
    must print byte for byte as one run in one go)"""
    runs: dict[tuple[str, float, tuple[int, int]], list[Any]] | None = None
    """``until_optimal``: per ``(method, criterion, block)`` each seed's
    :class:`~cartpole_q.engines.until_optimal.Result`"""


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
    """Read and check a planning-updates study file.

    Raises:
        ConfigError: naming the file and the key, with what is wrong.
    """
    raw = read_yaml_mapping(path, "study file")
    return read_study(StudyFile(raw, "updates", str(path), path.stem, path.parent))


def read_study(study: StudyFile) -> Study:
    """Check a planning-updates study file.

    Raises:
        ConfigError: naming the file and the key, with what is wrong.
    """
    raw, where, name = checked_study(
        study,
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
        for b in branching:
            check_count(where, "branching", b, MAX_BRANCHING)
            # per problem its b values, and the sample and expected errors after 0..2b updates
            check_memory(where, "branching", len(seeds) * (2 * b + 1) * 8 * 4,
                         f"{len(seeds):,} problems of branching factor {b:,}")  # fmt: skip
    elif kind == "until_optimal":
        return _until_optimal_study(raw, name, seeds, file, title, where)
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
        panels = tuple(
            _panel(entry, index, where, actions) for index, entry in enumerate(panels_raw)
        )
    return Study(
        name, kind, seeds, branching, initial_error, panels, actions, epsilon, termination,
        tolerance, file, title, where,
    )  # fmt: skip


def _until_optimal_study(
    raw: Mapping[str, Any], name: str, seeds: tuple[int, ...], file: str, title: str, where: str
) -> Study:
    from cartpole_q.families.gridworlds.worlds import maze_block

    scales = raw.get("scales")
    blocks: list[tuple[int, int]] = []
    for scale in scales if isinstance(scales, list) else []:
        try:
            blocks.append(maze_block(scale))
        except ValueError:
            blocks = []
            break
    if not blocks or len(set(blocks)) != len(blocks):
        raise ConfigError(
            f"{where}: scales: must be a list of distinct mazes, each a whole number k >= 1 "
            "(every cell of the Dyna maze becomes a k x k block) or [rows, columns] (blocks of "
            f"that many rows and columns), such as [1, 2, [4, 2]], got {shown_value(scales)}."
        )
    methods = raw.get("methods", ["prioritized_sweeping", "dyna_q"])
    if (
        not isinstance(methods, list)
        or not methods
        or not all(isinstance(m, str) and m in UNTIL_OPTIMAL_METHODS for m in methods)
        or len(set(methods)) != len(methods)
    ):
        raise ConfigError(
            f"{where}: methods: must be a list of distinct names among "
            f"{', '.join(UNTIL_OPTIMAL_METHODS)}, got {shown_value(methods)}."
        )
    alpha = _number(raw, "alpha", 0.5, where)
    gamma = _number(raw, "gamma", 0.95, where)
    epsilon = _number(raw, "epsilon", 0.1, where)
    theta = _number(raw, "theta", 0.0001, where)
    for key, value, low, high in (
        ("alpha", alpha, 0.0, 1.0), ("gamma", gamma, 0.0, 1.0), ("epsilon", epsilon, 0.0, 1.0)
    ):  # fmt: skip
        if not low < value <= high:
            raise ConfigError(f"{where}: {key}: must be in (0, 1], got {value:g}.")
    if theta < 0:
        raise ConfigError(f"{where}: theta: must not be negative, got {theta:g}.")
    within = _criteria(raw.get("optimal_within", 1.0), where)
    planning_steps = _whole(raw, "planning_steps", 5, where, 0)
    check_count(where, "planning_steps", planning_steps, MAX_BRANCHING)
    max_updates = _whole(raw, "max_updates", 10_000_000, where, 1)
    check_count(where, "max_updates", max_updates)
    max_steps = _whole(raw, "max_steps", 20_000_000, where, 1)
    check_count(where, "max_steps", max_steps)
    for rows, columns in blocks:
        for side in (rows, columns):
            check_count(where, "scales", side, MAX_SCALE,
                        f"a maze of {maze_states((MAX_SCALE, MAX_SCALE)):,} states; the book's largest has 6,016")  # fmt: skip
        states = maze_states((rows, columns))
        check_memory(where, "scales", states * MAZE_BYTES_PER_STATE,
                     f"the maze of {states:,} states")  # fmt: skip
    return Study(
        name, "until_optimal", seeds, (), 1.0, (), 4, epsilon, 0.0, 0.0, file, title, where,
        tuple(blocks), tuple(methods), alpha, gamma, planning_steps, theta, max_updates,
        max_steps, within,
    )  # fmt: skip


def _criteria(value: Any, where: str) -> tuple[float, ...]:
    """``optimal_within``: one number >= 1, or a list of distinct ones."""
    values = value if isinstance(value, list) else [value]
    numbers: list[float] = []
    for item in values:
        if isinstance(item, str):
            with contextlib.suppress(ValueError):
                item = float(item)
        if (
            isinstance(item, bool)
            or not isinstance(item, (int, float))
            or not (math.isfinite(item) and item >= 1.0)
        ):
            numbers = []
            break
        numbers.append(float(item))
    if not numbers or len(set(numbers)) != len(numbers):
        raise ConfigError(
            f"{where}: optimal_within: a number >= 1 (1: a shortest path; 1.2: at most 20% "
            f"longer), or a list of distinct ones, got {shown_value(value)}."
        )
    return tuple(numbers)


def maze_states(block: tuple[int, int]) -> int:
    """The open cells of the Dyna maze whose cells are ``(rows, columns)`` blocks: 47 r c.

    >>> [maze_states((k, k)) for k in (1, 2, 3)], maze_states((16, 8))
    ([47, 188, 423], 6016)
    """
    return 47 * block[0] * block[1]


@functools.cache
def shortest_path(block: tuple[int, int]) -> int:
    """The fewest steps from the start to the goal of the maze of ``block``."""
    from cartpole_q.families.gridworlds.worlds import DynaMazeEnv
    from cartpole_q.families.gridworlds.worlds import shortest_path as bfs

    return int(bfs(DynaMazeEnv(block)))


def _criterion_text(within: float) -> str:
    """``shortest path`` or ``within 1.2x``."""
    return "shortest path" if within == 1.0 else f"within {within:g}x"


def until_optimal_curves(
    study: Study, runs: Mapping[tuple[str, float, tuple[int, int]], list[Any]]
) -> list[Curve]:
    """Per method (and criterion): the mean updates over the seeds at each size, least, most."""
    curves = []
    x = np.array([float(maze_states(block)) for block in study.scales])
    for within in study.optimal_within:
        for method in study.methods:
            rows = [
                np.array([float(r.updates) for r in runs[(method, within, block)]])
                for block in study.scales
            ]
            mean = np.array([float(np.mean(row)) for row in rows])
            low = np.array([float(np.min(row)) for row in rows])
            high = np.array([float(np.max(row)) for row in rows])
            label = METHOD_LABELS[method]
            if len(study.optimal_within) > 1:
                label += f" ({_criterion_text(within)})"
            curves.append(Curve(label, x, mean, low, high))
    return curves


def _panel(raw: Any, index: int, where: str, actions: int) -> Panel:
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
    key = f"panels[{index}]"
    check_count(where, f"{key}.updates", updates)
    check_count(where, f"{key}.states", states, MAX_TASK_STATES)
    for b in branching:
        check_count(where, f"{key}.branching", b, MAX_BRANCHING)
        # a task's next states (int64) and rewards (float64) per state, action and branch;
        # its values and the curve
        needed = 16 * states * actions * b + 8 * states * actions + 8 * (updates // every + 1)
        check_memory(
            where,
            f"{key}.states",
            needed,
            f"a task of {states:,} states x {actions} actions x branching {b:,}",
        )
    return Panel(states, branching, updates, every)


MAX_BRANCHING = 10_000_000
"""the largest branching factor (and planning steps): far beyond the book's 10,000"""
MAX_TASK_STATES = 100_000_000
"""the most states of a Figure 8.8 task (the book's largest: 10,000)"""
MAX_SCALE = 100
"""the largest maze scale ``k`` of ``until_optimal``"""
MAZE_BYTES_PER_STATE = 4_096
"""what a maze state costs while it is built and played: its transition table in Python
(four lists of one outcome each) and the run's arrays"""


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


def study_runs(study: Study) -> list[dict[str, Cell]]:
    """Every run's key, in run order.

    ``expected_vs_sample``: one run per branching factor (its problems, one per seed);
    ``trajectory_sampling``: one per panel, branching factor and seed (a task, run with
    uniform and on-policy updates); ``until_optimal``: one per maze scale, method and seed.
    """
    if study.kind == "expected_vs_sample":
        return [{"branching": branching} for branching in study.branching]
    if study.kind == "until_optimal":
        return [
            {"rows": rows, "columns": columns, "within": within, "method": method, "seed": seed}
            for rows, columns in study.scales
            for within in study.optimal_within
            for method in study.methods
            for seed in study.seeds
        ]
    return [
        {"panel": index, "branching": branching, "seed": seed}
        for index, panel in enumerate(study.panels)
        for branching in panel.branching
        for seed in study.seeds
    ]


def run_one(
    study: Study,
    key: Mapping[str, Cell],
    stop: Callable[[], bool] | None = None,
    progress: Callable[[int], None] | None = None,
) -> RunRecord | None:
    """One run of :func:`study_runs`; ``None`` when ``stop`` ended it early."""
    if study.kind == "expected_vs_sample":
        from cartpole_q.rl.planning_updates import rms_over_problems, sample_update_errors

        branching = int(key["branching"] or 0)
        sample, expected = sample_update_errors(list(study.seeds), branching, study.initial_error)
        largest = float(np.max(np.abs(expected[:, branching:])))
        return RunRecord({"largest_expected_error": largest}, {"rms": rms_over_problems(sample)})
    if study.kind == "until_optimal":
        from cartpole_q.engines.until_optimal import Settings, maze_arrays, until_optimal
        from cartpole_q.families.gridworlds.worlds import DynaMazeEnv

        maze = maze_arrays(DynaMazeEnv((int(key["rows"] or 1), int(key["columns"] or 1))))
        settings = Settings(
            str(key["method"]), study.alpha, study.gamma, study.epsilon, study.planning_steps,
            study.theta, "random", np.iinfo(np.int64).max, study.max_updates,
            float(key["within"] or 1.0), study.max_steps,
        )  # fmt: skip
        result = until_optimal(maze, settings, int(key["seed"] or 0), should_stop=stop)
        if result is None:
            return None
        return RunRecord(
            {"updates": result.updates, "episodes": result.episodes, "steps": result.steps,
             "reached": result.reached}
        )  # fmt: skip
    from cartpole_q.engines.trajectory import task_curves
    from cartpole_q.rl.planning_updates import Curve, Task

    panel = study.panels[int(key["panel"] or 0)]
    task = Task(panel.states, study.actions, int(key["branching"] or 1), study.termination)
    curve = Curve(panel.updates, panel.every, study.epsilon, study.tolerance)
    curves = task_curves(int(key["seed"] or 0), task, curve, should_stop=stop)
    if curves is None:
        return None
    uniform, on_policy = curves
    return RunRecord({}, {"uniform": uniform, "on_policy": on_policy})


def study_outcome(
    study: Study, keys: Sequence[Mapping[str, Cell]], records: Sequence[RunRecord]
) -> Outcome:
    """The curves of every run's record (in :func:`study_runs` order)."""
    if study.kind == "expected_vs_sample":
        curves = [
            Curve(f"b = {key['branching']}", np.arange(2 * int(key["branching"] or 0) + 1)
                  / int(key["branching"] or 1), record.arrays["rms"], None, None)
            for key, record in zip(keys, records, strict=True)
        ]  # fmt: skip
        largest = max(float(record.row["largest_expected_error"] or 0.0) for record in records)
        return Outcome([curves], largest, 0.0)
    if study.kind == "until_optimal":
        from cartpole_q.engines.until_optimal import Result

        runs: dict[tuple[str, float, tuple[int, int]], list[Any]] = {}
        for key, record in zip(keys, records, strict=True):
            row = record.row
            result = Result(int(row["updates"] or 0), int(row["episodes"] or 0),
                            int(row["steps"] or 0), bool(row["reached"]))  # fmt: skip
            block = (int(key["rows"] or 1), int(key["columns"] or 1))
            runs.setdefault((str(key["method"]), float(key["within"] or 1.0), block), []).append(
                result
            )
        return Outcome([until_optimal_curves(study, runs)], 0.0, 0.0, runs)
    tasks: dict[tuple[int, int], list[RunRecord]] = {}
    for key, record in zip(keys, records, strict=True):
        tasks.setdefault((int(key["panel"] or 0), int(key["branching"] or 1)), []).append(record)
    panels = []
    for index, panel in enumerate(study.panels):
        points = np.arange(panel.updates // panel.every + 1) * panel.every
        curves = []
        for branching in panel.branching:
            found = tasks[(index, branching)]
            for name, label in (("uniform", "uniform"), ("on_policy", "on-policy")):
                rows = np.array([record.arrays[name] for record in found])
                curves.append(_averaged(f"b = {branching}, {label}", points, rows, True))
        panels.append(curves)
    return Outcome(panels, 0.0, 0.0)


def run_study(study: Study, stop: Callable[[], bool] | None = None) -> Outcome | None:
    """Compute every curve in this process; ``None`` when ``stop`` (asked before each run) says so."""
    start = time.perf_counter()
    keys = study_runs(study)
    records = []
    for key in keys:
        if stop is not None and stop():
            return None
        record = run_one(study, key, stop)
        if record is None:
            return None
        records.append(record)
    outcome = study_outcome(study, keys, records)
    return dataclasses.replace(outcome, seconds=time.perf_counter() - start)


def _panel_name(panel: Panel) -> str:
    return f"{panel.states:,} states"


def summary(study: Study, outcome: Outcome) -> list[str]:
    """Lines saying what ran and the key numbers of every curve."""
    seeds = len(study.seeds)
    if study.kind == "expected_vs_sample":
        lines = [
            f"{study.name}: {seeds} problems per branching factor, initial error "
            f"{study.initial_error:g}",
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
    if study.kind == "until_optimal":
        return _until_optimal_summary(study, outcome)
    lines = [
        f"{study.name}: {seeds} tasks per curve, {study.actions} actions, epsilon "
        f"{study.epsilon:g}, termination {study.termination:g}"
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


def _until_optimal_summary(study: Study, outcome: Outcome) -> list[str]:
    assert outcome.runs is not None
    lines = [
        f"{study.name}: {len(study.seeds)} runs per point, alpha {study.alpha:g}, gamma "
        f"{study.gamma:g}, epsilon {study.epsilon:g}, {study.planning_steps} planning steps, "
        f"theta {study.theta:g}",
    ]
    both = "prioritized_sweeping" in study.methods and "dyna_q" in study.methods
    for within in study.optimal_within:
        lines.append(
            f"  updates until the greedy path is {'a ' if within == 1.0 else ''}"
            f"{_criterion_text(within)} (mean over runs [least, most]):"
        )
        for block in study.scales:
            shown = []
            for method in study.methods:
                found = outcome.runs[(method, within, block)]
                updates = [r.updates for r in found]
                missed = sum(not r.reached for r in found)
                note = f", {missed} not reached: at least" if missed else ""
                shown.append(
                    f"{METHOD_LABELS[method]} {np.mean(updates):,.0f} [{min(updates):,}, "
                    f"{max(updates):,}{note}]"
                )
            ratio = ""
            if both:
                sweeping = np.mean(
                    [r.updates for r in outcome.runs[("prioritized_sweeping", within, block)]]
                )
                dyna = np.mean([r.updates for r in outcome.runs[("dyna_q", within, block)]])
                ratio = f"; Dyna-Q / prioritized sweeping {dyna / sweeping:.1f} (book: 5-10)"
            rows, columns = block
            lines.append(
                f"    {rows} x {columns} blocks ({maze_states(block):,} states, shortest path "
                f"{shortest_path(block)} steps): " + "; ".join(shown) + ratio
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
    if study.kind == "until_optimal":
        styles = [  # curves in criterion-then-method order: a colour per method
            (index, within != 1.0)
            for within in study.optimal_within
            for index, _ in enumerate(study.methods)
        ]
        return figures.until_optimal_figure(
            [(c.label, c.x, c.mean, c.low, c.high) for c in outcome.curves[0]], study.title,
            styles,
        )  # fmt: skip
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


class UpdatesKind(RunsKind):
    """``kind: updates``: chapter 8's planning studies (Figures 8.7, 8.8, Example 8.4)."""

    name = "updates"
    figure_kinds = FIGURE_KINDS
    units = Units("updates", "runs", "runs")
    runs_per_task = 4

    def read(self, study: StudyFile) -> Study:
        """Check the file (:func:`read_study`)."""
        return read_study(study)

    def runs(self, spec: Study) -> list[dict[str, Cell]]:
        """The runs (:func:`study_runs`)."""
        return study_runs(spec)

    def describe(self, spec: Study) -> tuple[int, str]:
        """The runs, by what they are made of."""
        runs = len(study_runs(spec))
        seeds = _count(len(spec.seeds), "seed")
        if spec.kind == "expected_vs_sample":
            parts = f"{_count(len(spec.branching), 'branching factor')}, {seeds} of problems each"
        elif spec.kind == "until_optimal":
            parts = (
                f"{_count(len(spec.scales), 'maze size')} x "
                f"{_count(len(spec.optimal_within), 'criterion', 'criteria')} x "
                f"{_count(len(spec.methods), 'method')} x {seeds}"
            )
        else:
            parts = f"{_count(len(spec.panels), 'panel')}' branching factors x {seeds}"
        return runs, f"an updates study ({spec.kind}): {_count(runs, 'run')}: {parts}"

    def result_columns(self, spec: Study) -> tuple[str, ...]:
        """Figure 8.7: the expected update's largest error; Example 8.4: what a run took."""
        if spec.kind == "expected_vs_sample":
            return ("largest_expected_error",)
        if spec.kind == "until_optimal":
            return ("updates", "episodes", "steps", "reached")
        return ()

    def before_runs(self, spec: Study) -> str | None:
        """Figure 8.8's compile notice."""
        if spec.kind != "trajectory_sampling":
            return None
        from cartpole_q.engines.trajectory import compile_notice

        return compile_notice()

    def run_one(self, spec: Study, key: Mapping[str, Cell], handle: RunHandle) -> RunRecord | None:
        """One run (:func:`run_one`)."""
        return run_one(spec, key, handle.should_stop, handle.report)

    def finish(
        self, spec: Study, keys: Sequence[Mapping[str, Cell]], records: Sequence[RunRecord]
    ) -> Finished:
        """The figure and the summary."""
        outcome = study_outcome(spec, keys, records)
        return Finished([(spec.file, study_figure(spec, outcome))], (), summary(spec, outcome))


UPDATES = register_kind(UpdatesKind())
"""the planning-updates kind (registered)"""


def _count(n: int, noun: str, plural: str = "") -> str:
    """``1 seed``, ``2,000 seeds`` (``plural``: when it is not the noun and an s)."""
    return f"{n:,} {noun if n == 1 else plural or noun + 's'}"
