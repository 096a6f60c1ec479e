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
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from cartpole_q.config import RANDOMIZED_KEYS
from cartpole_q.engines import make_engine
from cartpole_q.envs.gym import inspect_env
from cartpole_q.envs.twins import cartpole
from cartpole_q.errors import UserError
from cartpole_q.evaluation import under_conditions
from cartpole_q.experiments.multiseed import load_seed_runs
from cartpole_q.figures import FIGURE_FORMATS, figure_bytes, robustness_figure
from cartpole_q.store import rundir
from cartpole_q.store.atomic import atomic_write_bytes, atomic_write_text, check_output_file

PRESETS = {
    "rl-generalization": {"force_mag": (5.0, 15.0), "length": (0.25, 0.75), "masspole": (0.05, 0.5)},
    "rl-generalization-extreme": {
        "force_mag": (1.0, 20.0), "length": (0.05, 1.0), "masspole": (0.01, 1.0)
    },
}  # fmt: skip
"""the ranges of sunblaze-ucb's rl-generalization (Packer et al. 2018, "Assessing
Generalization in Deep Reinforcement Learning"): default and extreme"""

DEFAULTS = {
    "gravity": cartpole.GRAVITY, "masscart": cartpole.MASSCART, "masspole": cartpole.MASSPOLE,
    "length": cartpole.LENGTH, "force_mag": cartpole.FORCE_MAG, "tau": cartpole.TAU,
}  # fmt: skip
"""``CartPoleEnv``'s own values, marked when a run kept them"""


@dataclass(frozen=True)
class Axis:
    """One varied physics key and its values."""

    key: str
    values: np.ndarray


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
    if key not in RANDOMIZED_KEYS:
        raise UserError(
            f"--vary {text!r}: {key!r} cannot vary; choose one of {', '.join(RANDOMIZED_KEYS)}."
        )
    try:
        start, stop, count = float(parts[0]), float(parts[1]), int(parts[2])
    except ValueError:
        raise UserError(
            f"--vary {text!r}: START and STOP must be numbers and N an integer."
        ) from None
    if not 1 <= count <= 1000:
        raise UserError(f"--vary {text!r}: N must be between 1 and 1000.")
    return Axis(key, np.linspace(start, stop, count))


def preset_axes(name: str, points: int) -> list[Axis]:
    """The first two ranges of a preset, ``points`` values each (a heatmap)."""
    if name not in PRESETS:
        raise UserError(f"--preset {name!r}: unknown; choose one of {', '.join(PRESETS)}.")
    ranges = list(PRESETS[name].items())[:2]
    return [Axis(key, np.linspace(low, high, points)) for key, (low, high) in ranges]


def measure(
    run_dir: Path, axes: list[Axis], episodes: int, seed: int, max_steps: int | None = None
) -> tuple[np.ndarray, list[float], float | None]:
    """Each seed's greedy mean return at each grid point.

    Returns:
        ``(means, trained, threshold)``: means of shape ``(seeds, *grid)``; each key's
        training value; the threshold at the horizon played (``max_steps``, else the run's).
    """
    runs = load_seed_runs(run_dir) if rundir.is_multi_seed(run_dir) else [rundir.load_run(run_dir)]
    config = runs[0].config
    if config.env.id not in cartpole.ENV_IDS:
        raise UserError(
            f"{run_dir}: robustness varies CartPole's physics; this run is on {config.env.id!r}."
        )
    info = inspect_env(config)
    grid = list(itertools.product(*(axis.values for axis in axes)))
    shape = (len(runs), *(len(axis.values) for axis in axes))
    means = np.empty((len(runs), len(grid)))
    engines = []
    for point in grid:
        physics = {axis.key: float(value) for axis, value in zip(axes, point, strict=True)}
        engines.append(
            make_engine("numba", under_conditions(config, physics, max_steps), info, env_seed=0)
        )
    for r, run in enumerate(runs):
        table = run.q_table.reshape(-1, info.n_actions)
        for p, engine in enumerate(engines):
            means[r, p] = float(np.mean(engine.evaluate(table, episodes, seed)))
    trained = [float(config.env.physics.get(axis.key, DEFAULTS[axis.key])) for axis in axes]
    threshold = inspect_env(under_conditions(config, None, max_steps)).reward_threshold
    return means.reshape(shape), trained, threshold


def robustness(
    run_dir: Path,
    axes: list[Axis],
    episodes: int,
    seed: int,
    out: Path,
    force: bool = False,
    max_steps: int | None = None,
) -> tuple[Path, Path]:
    """Measure, then write the figure ``out`` and ``out`` with ``.csv``; return both paths.

    Raises:
        UserError: bad axes (one or two keys, no repeat), or the run is not CartPole's.
        WriteError: the files cannot be written (checked before measuring).
    """
    if not 1 <= len(axes) <= 2 or len({axis.key for axis in axes}) != len(axes):
        raise UserError("--vary: give one key (a curve) or two different keys (a heatmap).")
    suffix = check_output_file(out, "--out", tuple(FIGURE_FORMATS), force)
    table_path = out.with_suffix(".csv")
    check_output_file(table_path, "--out (its .csv)", (".csv",), force)
    means, trained, threshold = measure(run_dir, axes, episodes, seed, max_steps)
    atomic_write_text(table_path, _csv(axes, means))
    horizon = "" if max_steps is None else f" of {max_steps} steps"
    title = f"Robustness of {run_dir.name}: greedy mean over {episodes} episodes{horizon}"
    figure = robustness_figure([(a.key, a.values) for a in axes], means, trained, threshold, title)
    atomic_write_bytes(out, figure_bytes(figure, FIGURE_FORMATS[suffix]))
    return out, table_path


def _csv(axes: list[Axis], means: np.ndarray) -> str:
    """One row per grid point and seed index: the keys' values, ``seed_index``, ``mean``."""
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow([*(axis.key for axis in axes), "seed_index", "mean"])
    for index in np.ndindex(*means.shape):
        seed_index, *point = index
        values = [repr(float(axis.values[i])) for axis, i in zip(axes, point, strict=True)]
        writer.writerow([*values, seed_index, repr(float(means[index]))])
    return buffer.getvalue()
