"""The ``plot`` command's work: load runs, draw them with :mod:`cartpole_q.figures`, write.

Nothing is drawn before the output file is known to be writable.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from cartpole_q.errors import UserError
from cartpole_q.experiments.multiseed import load_seed_runs
from cartpole_q.figures import (
    FIGURE_FORMATS,
    Curve,
    SeedBand,
    action_names,
    default_dims,
    dimension_names,
    figure_bytes,
    policy_figure,
    reward_curve_figure,
)
from cartpole_q.store import rundir
from cartpole_q.store.atomic import atomic_write_bytes, check_output_file


def plot_rewards(run_dirs: Sequence[Path], out: Path, force: bool = False) -> Path:
    """Draw the reward curves of single and multi-seed runs on one figure; write ``out``.

    Args:
        run_dirs: run directories, single or multi-seed.
        out: a ``.png``, ``.svg`` or ``.pdf`` file.
        force: replace ``out`` if it exists.

    Raises:
        RunError: a directory is not a complete run.
        WriteError: ``out`` cannot be written (checked before the figure is drawn).
    """
    items: list[Curve | SeedBand] = []
    for path in run_dirs:
        if rundir.is_multi_seed(path):
            runs = load_seed_runs(path)
            thresholds = {run.summary.get("reward_threshold") for run in runs}
            items.append(SeedBand(
                path.name, [run.metrics.returns for run in runs],
                [run.summary.get("solved_episode") for run in runs],
                threshold=thresholds.pop() if len(thresholds) == 1 else None,
                interrupted=sum(bool(run.summary.get("interrupted")) for run in runs),
            ))  # fmt: skip
        else:
            run = rundir.load_run(path)
            items.append(Curve(
                path.name, run.metrics.returns, run.summary.get("solved_episode"),
                threshold=run.summary.get("reward_threshold"),
                interrupted=bool(run.summary.get("interrupted")),
            ))  # fmt: skip
    suffix = check_output_file(out, "--out", tuple(FIGURE_FORMATS), force)
    title = "Training reward" if len(items) > 1 else f"Training reward: {run_dirs[0].name}"
    if len(items) == 1 and isinstance(items[0], Curve) and items[0].interrupted:
        title += " (interrupted)"
    figure = reward_curve_figure(items, None, title)
    atomic_write_bytes(out, figure_bytes(figure, FIGURE_FORMATS[suffix]))
    return out


def plot_policy(run_dir: Path, out: Path, dims_text: str | None, force: bool = False) -> Path:
    """Draw one run's policy map over two binned dimensions; write ``out``.

    Raises:
        RunError: the directory is not a complete run.
        UserError: ``dims_text`` does not name two distinct dimensions of the grid.
        WriteError: ``out`` cannot be written (checked before the figure is drawn).
    """
    run = rundir.load_run(run_dir)
    bins = run.config.discretization.bins
    dims = parse_dims(dims_text, bins) if dims_text else default_dims(bins)
    suffix = check_output_file(out, "--out", tuple(FIGURE_FORMATS), force)
    env_id = run.config.env.id
    title = f"Policy of {run_dir.name}"
    if run.summary.get("interrupted"):
        title += f" (training interrupted at episode {run.summary.get('episodes')})"
    figure = policy_figure(
        run.q_table, run.visits, dims, run.config.discretization.low,
        run.config.discretization.high, dimension_names(env_id, len(bins)), title,
        action_names=action_names(env_id, run.q_table.shape[-1]),
    )  # fmt: skip
    atomic_write_bytes(out, figure_bytes(figure, FIGURE_FORMATS[suffix]))
    return out


def parse_dims(text: str, bins: Sequence[int]) -> tuple[int, int]:
    """Parse ``--dims`` such as ``2,3``.

    Raises:
        UserError: not two distinct dimension numbers of the grid.
    """
    parts = [part.strip() for part in text.split(",")]
    if len(parts) != 2 or not all(part.isdigit() for part in parts):
        raise UserError(f"--dims: expected two dimension numbers like 2,3, got {text!r}.")
    first, second = int(parts[0]), int(parts[1])
    if first == second or max(first, second) >= len(bins):
        raise UserError(
            f"--dims: expected two different dimensions between 0 and {len(bins) - 1}, got {text!r}."
        )
    return first, second
