"""How a trained policy holds up when CartPole's physics change: a grid of physics values.

For each value (or pair of values) of the varied keys, the greedy policy plays
``episodes`` episodes on the compiled twin under that physics (bit-identical to
``gymnasium.make`` with the same ``env.physics``, and far faster), seeded with ``seed``.
A multi-seed run gives one mean per seed and point; the figure shows their median.
"""

from __future__ import annotations

import csv
import io
import itertools
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from cartpole_q.engines import make_engine
from cartpole_q.envs.gym import config_threshold
from cartpole_q.envs.registry import twin_for
from cartpole_q.errors import UserError
from cartpole_q.evaluation import under_conditions
from cartpole_q.families import Physics, profile_for
from cartpole_q.figures import robustness_figure
from cartpole_q.progress import NullSweepProgress, SweepProgress
from cartpole_q.store.atomic import atomic_write_text, check_output_file
from cartpole_q.store.figure_file import check_figure_file, write_figure
from cartpole_q.store.runsets import RunSet, check_tables, load_run_set

PRESETS = {
    "rl-generalization": {"force_mag": (5.0, 15.0), "length": (0.25, 0.75), "masspole": (0.05, 0.5)},
    "rl-generalization-extreme": {
        "force_mag": (1.0, 20.0), "length": (0.05, 1.0), "masspole": (0.01, 1.0)
    },
}  # fmt: skip
"""the ranges of sunblaze-ucb's rl-generalization (Packer et al. 2018, "Assessing
Generalization in Deep Reinforcement Learning"): default and extreme"""


@dataclass(frozen=True)
class Axis:
    """One varied physics key and its values."""

    key: str
    values: np.ndarray


@dataclass(frozen=True)
class Measurement:
    """What ``robustness`` plays: a grid of physics, and at each point the greedy episodes."""

    axes: list[Axis]
    """one varied key (a curve) or two (a heatmap)"""
    episodes: int
    """greedy episodes per seed and grid point"""
    seed: int
    """the first episode's reset seed (the next ones count up)"""
    max_steps: int | None = None
    """play with this time limit (default: the run's)"""


def parse_vary(text: str) -> Axis:
    """Parse ``--vary KEY=START:STOP:N`` (``N`` values from START to STOP, both included).

    >>> axis = parse_vary("length=0.25:0.75:3")
    >>> axis.key, axis.values.tolist()
    ('length', [0.25, 0.5, 0.75])

    Raises:
        UserError: not of that form, a key that cannot vary, or fewer than 1 value.
    """
    key, equals, spec = text.partition("=")
    parts = spec.split(":")
    if not equals or len(parts) != 3:
        raise UserError(f"--vary {text!r}: expected KEY=START:STOP:N, e.g. length=0.25:0.75:11.")
    if not key:
        raise UserError(f"--vary {text!r}: expected KEY=START:STOP:N, e.g. length=0.25:0.75:11.")
    try:
        start, stop, count = float(parts[0]), float(parts[1]), int(parts[2])
    except ValueError:
        raise UserError(
            f"--vary {text!r}: START and STOP must be numbers and N an integer."
        ) from None
    if not 1 <= count <= 1000:
        raise UserError(f"--vary {text!r}: N must be between 1 and 1000.")
    return Axis(key, grid_values(start, stop, count))


def preset_axes(name: str, points: int) -> list[Axis]:
    """The first two ranges of a preset, ``points`` values each (a heatmap)."""
    if name not in PRESETS:
        raise UserError(f"--preset {name!r}: unknown; choose one of {', '.join(PRESETS)}.")
    ranges = list(PRESETS[name].items())[:2]
    return [Axis(key, grid_values(low, high, points)) for key, (low, high) in ranges]


def grid_values(start: float, stop: float, count: int) -> np.ndarray:
    """``count`` values from ``start`` to ``stop``, rounded to 12 significant digits.

    ``np.linspace(0.1, 0.5, 5)`` gives ``0.30000000000000004``; the value meant is 0.3.

    >>> grid_values(0.1, 0.5, 5).tolist()
    [0.1, 0.2, 0.3, 0.4, 0.5]
    """
    return np.array([float(f"{value:.12g}") for value in np.linspace(start, stop, count)])


MAX_EVALUATIONS = 5_000_000
"""``robustness`` asks for ``--yes`` above this many greedy episodes (seeds x points x episodes)"""


def measure(
    run_set: RunSet, measurement: Measurement, progress: SweepProgress | None = None
) -> tuple[np.ndarray, list[float], float | None]:
    """Each seed's greedy mean return at each grid point (its values checked: :func:`check_values`).

    Returns:
        ``(means, trained, threshold)``: means of shape ``(seeds, *grid)``; each key's
        training value; the threshold at the horizon played (``max_steps``, else the run's).
    """
    progress = progress or NullSweepProgress()
    axes, max_steps = measurement.axes, measurement.max_steps
    episodes, seed = measurement.episodes, measurement.seed
    runs = run_set.runs
    config = run_set.config
    spec = varied_physics(run_set, axes)
    info = check_tables(run_set)
    grid = list(itertools.product(*(axis.values for axis in axes)))
    shape = (len(runs), *(len(axis.values) for axis in axes))
    means = np.empty((len(runs), len(grid)))
    tables = [run.q_table.reshape(-1, info.n_actions) for run in runs]
    progress.start(len(runs) * len(grid), 0, len(grid), 0)
    try:
        for p, point in enumerate(grid):
            physics = {axis.key: float(value) for axis, value in zip(axes, point, strict=True)}
            conditions = under_conditions(config, physics, max_steps, source="--vary")
            engine = make_engine("numba", conditions, info, env_seed=0)
            for r, table in enumerate(tables):
                means[r, p] = float(np.mean(engine.evaluate(table, episodes, seed)))
            progress.advance(len(runs) * (p + 1), p + 1)
    finally:
        progress.close()
    trained = [float(config.env.physics.get(axis.key, spec.defaults[axis.key])) for axis in axes]
    threshold = config_threshold(under_conditions(config, None, max_steps))
    return means.reshape(shape), trained, threshold


def check_values(run_set: RunSet, axes: list[Axis], max_steps: int | None) -> None:
    """Check every value of every axis before any point is played.

    A value out of range at the end of the grid is refused at once, not after the points
    before it have been played. Each physics key's range is its own (no key's bounds
    depend on another's), so checking each axis's values alone checks every point.

    Raises:
        ConfigError: a value is not one the physics key accepts (naming ``--vary``).
    """
    for axis in axes:
        for value in dict.fromkeys(axis.values.tolist()):
            under_conditions(run_set.config, {axis.key: value}, max_steps, source="--vary")


def varied_physics(run_set: RunSet, axes: list[Axis]) -> Physics:
    """The physics of the run's environment, when the axes are keys it lets vary.

    Raises:
        UserError: the environment has no physics to vary (or no twin to play them fast),
            or an axis is not one of its keys.
    """
    config = run_set.config
    physics = profile_for(config.env.id).physics
    if physics is None or twin_for(config.env.id) is None:
        raise UserError(
            f"{run_set.path}: robustness varies an environment's physics on its compiled twin; "
            f"this run's environment ({config.env.id!r}) has no physics to vary."
        )
    for axis in axes:
        if axis.key not in physics.randomizable:
            raise UserError(
                f"--vary {axis.key}: cannot vary; choose one of {', '.join(physics.randomizable)}."
            )
    return physics


def check_size(run_set: RunSet, axes: list[Axis], episodes: int, yes: bool) -> None:
    """Refuse more than :data:`MAX_EVALUATIONS` greedy episodes without ``--yes``."""
    points = int(np.prod([len(axis.values) for axis in axes]))
    total = len(run_set.runs) * points * episodes
    if total > MAX_EVALUATIONS and not yes:
        raise UserError(
            f"{run_set.path}: {len(run_set.runs):,} seeds x {points:,} grid points x "
            f"{episodes:,} episodes = {total:,} greedy episodes, more than "
            f"{MAX_EVALUATIONS:,}; pass --yes to play them all (or use fewer points or episodes)."
        )


def robustness(
    run_dir: Path,
    measurement: Measurement,
    out: Path,
    *,
    force: bool = False,
    yes: bool = False,
    progress: SweepProgress | None = None,
    on_note: Callable[[str], None] | None = None,
) -> tuple[Path, Path]:
    """Measure, then write the figure ``out`` with its data, and the seeds' table.

    The figure's data (what it draws: the median across seeds, its interquartile range) goes
    beside it as ``<stem>.csv``, as every figure's; the table of every seed's mean at every
    grid point as ``<stem>_seeds.csv`` (:func:`seeds_table_path`).

    Returns:
        The figure's path and the table's.

    Raises:
        UserError: bad axes (one or two keys, no repeat), the run is not CartPole's, or
            more greedy episodes than :data:`MAX_EVALUATIONS` without ``yes``.
        WriteError: the files cannot be written (checked before measuring).
    """
    axes, episodes, max_steps = measurement.axes, measurement.episodes, measurement.max_steps
    if not 1 <= len(axes) <= 2 or len({axis.key for axis in axes}) != len(axes):
        raise UserError("--vary: give one key (a curve) or two different keys (a heatmap).")
    run_set = load_run_set(run_dir)
    varied_physics(run_set, axes)
    check_values(run_set, axes, max_steps)  # every value, before any file or episode
    check_size(run_set, axes, episodes, yes)
    check_figure_file(out, "--out", force)
    table_path = seeds_table_path(out)
    check_output_file(table_path, "--out (its _seeds.csv)", (".csv",), force)
    for note in run_set.notes:
        if on_note is not None:
            on_note(note)
    means, trained, threshold = measure(run_set, measurement, progress)
    seeds = [run.config.seed for run in run_set.runs]
    atomic_write_text(table_path, _csv(axes, means, seeds))
    horizon = "" if max_steps is None else f" of {max_steps} steps"
    title = f"Robustness of {run_dir.name}: greedy mean over {episodes} episodes{horizon}"
    figure = robustness_figure([(a.key, a.values) for a in axes], means, trained, threshold, title)
    return write_figure(out, figure), table_path


def seeds_table_path(out: Path) -> Path:
    """Where ``robustness`` writes every seed's mean: ``<stem>_seeds.csv`` beside the figure.

    Not ``<stem>.csv``: that is the figure's data, as beside every figure.

    >>> seeds_table_path(Path("runs/a/robustness.png")).as_posix()
    'runs/a/robustness_seeds.csv'
    """
    return out.with_name(f"{out.stem}_seeds.csv")


def _csv(axes: list[Axis], means: np.ndarray, seeds: list[int]) -> str:
    """One row per grid point and seed: the keys' values, the run's ``seed``, ``mean``."""
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow([*(axis.key for axis in axes), "seed", "mean"])
    for index in np.ndindex(*means.shape):
        seed_index, *point = index
        values = [repr(float(axis.values[i])) for axis, i in zip(axes, point, strict=True)]
        writer.writerow([*values, seeds[seed_index], repr(float(means[index]))])
    return buffer.getvalue()
