"""The runs behind a path: one run, the seeds of a multi-seed run, or the seeds of a sweep point.

``eval``, ``plot`` and ``compare`` take any of the three. A multi-seed run's seeds are its
``seed-NNN`` directories; a sweep point's (``<sweep>/points/<p>``) are its rows of
``results.csv``, its tables in ``q_tables.npz`` and its learning curves in
``curves.npz``. Either way the seeds come back as :class:`~cartpole_q.store.rundir.Run`
records, so that the commands treat them alike, with notes naming what is unfinished
(interrupted, not started) so that no command uses it without saying so.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from cartpole_q.config import Config, Schedule, config_differences, shown_value
from cartpole_q.engines.base import EpisodeMetrics
from cartpole_q.errors import RunError
from cartpole_q.rl.algorithms import get as get_algorithm
from cartpole_q.store import rundir, sweepdir

if TYPE_CHECKING:
    from cartpole_q.envs.gym import EnvInfo


def seed_dir(parent: Path, seed: int, seeds: tuple[int, ...]) -> Path:
    """The subdirectory of one seed: ``seed-007`` when the largest seed has up to 3 digits."""
    width = max(3, len(str(max(seeds))))
    return parent / f"seed-{seed:0{width}d}"


@dataclass(frozen=True)
class RunSet:
    """The finished runs behind a path, and what was left out."""

    path: Path
    kind: str
    """``run``, ``multi-seed run`` or ``sweep point``"""
    runs: list[rundir.Run]
    """one per seed with a result, in seed order"""
    notes: list[str] = field(default_factory=list)
    """sentences naming unfinished or missing seeds (empty when every seed finished)"""
    missing: list[str] = field(default_factory=list)
    """the seeds left out because they have no result (``seed-001``, ...)"""
    unfinished: list[str] = field(default_factory=list)
    """the seeds left out because their training was interrupted"""

    @property
    def seeds(self) -> int:
        """How many seeds the run has, left out ones included."""
        return len(self.runs) + len(self.missing) + len(self.unfinished)

    @property
    def config(self) -> Config:
        """The config of the first seed (the seeds differ only in their seed)."""
        return self.runs[0].config

    @property
    def reward_threshold(self) -> float | None:
        """The threshold the seeds were judged by (``None`` without one)."""
        return self.runs[0].result.reward_threshold


def load_run_set(path: Path) -> RunSet:
    """Load a run directory, a multi-seed run or a sweep point.

    Raises:
        RunError: ``path`` is none of them, or none of its seeds has a result.
    """
    path = Path(path)
    point = sweepdir.point_results(path)
    if point is not None:
        return _sweep_point(path, point)
    if rundir.is_multi_seed(path):
        return _multi_seed(path)
    run = rundir.load_run(path)
    notes = []
    if run.result.interrupted:
        notes.append(
            f"{path}: training was interrupted after episode {run.result.episodes} of "
            f"{run.config.train.episodes}; its table at that point is used (finish it with "
            f"`cartpole-q train --resume {path}`)."
        )
    return RunSet(path, "run", [run], notes)


def _multi_seed(parent: Path) -> RunSet:
    """A multi-seed run's finished seeds; interrupted and missing ones are named, left out."""
    config = rundir.read_config_file(parent / rundir.CONFIG_FILE)
    seeds = config.train.seeds
    assert seeds is not None
    runs: list[rundir.Run] = []
    missing: list[str] = []
    unfinished: list[str] = []
    for seed in seeds:
        child = seed_dir(parent, seed, seeds)
        summary = rundir.read_summary(child)
        if summary is None:
            (unfinished if child.is_dir() else missing).append(child.name)
        elif summary.interrupted:
            unfinished.append(child.name)
        else:
            run = rundir.load_run(child)
            check_seed_config(parent, child, config.for_seed(seed), run.config)
            runs.append(run)
    note = _left_out(parent, len(seeds), missing, unfinished)
    if not runs:
        raise RunError(f"{parent}: none of its seed runs has finished; {note}")
    return RunSet(parent, "multi-seed run", runs, [note] if note else [], missing, unfinished)


def check_tables(run_set: RunSet) -> EnvInfo:
    """The environment's facts, once every seed's Q-table is checked to fit them.

    A run's ``config.yaml`` replaced by another world's would otherwise have its table
    drawn (or played) as that world's: its states and actions must be the environment's.

    Raises:
        ConfigError: the environment cannot be made.
        RunError: a table's shape is not ``(*states, n_actions)`` of the environment, or the
            run is a prediction run (its ``V`` is no policy to play or draw).
    """
    from cartpole_q.engines.plan import env_facts
    from cartpole_q.evaluation import check_q_table_shape

    if any(run.predicts for run in run_set.runs):
        measured = all(run.errors is not None for run in run_set.runs)
        errors = (
            f"`cartpole-q plot {run_set.path} --metric rms_error` draws its error (metrics.csv's "
            "rms_error)"
            if measured
            else f"`cartpole-q plot {run_set.path}` draws its curves (its world has no model, "
            "so no error was measured)"
        )
        raise RunError(
            f"{run_set.path}: is a prediction run ({run_set.config.agent.algorithm}): it "
            "learnt the state values V of agent.policy (v_table.npy), not a policy, so there "
            f"is no greedy policy to evaluate, map or test. {errors}."
        )
    info = env_facts(run_set.config, str(run_set.path / rundir.CONFIG_FILE))
    for run in run_set.runs:
        file = run.path / rundir.Q_TABLE_FILE  # a sweep point's seeds have none of their own
        where = str(file) if file.is_file() else f"{run.path}: its Q-table"
        check_q_table_shape(run.q_table.shape, info.state_shape, info.n_actions, where)
    return info


NEUTRAL_KEYS = frozenset(
    {"name", "engine", "train.episodes", "train.checkpoint_every", "train.tensorboard"}
)
"""config keys in which a multi-seed run's seeds may differ: the run name, the engine
(bit-identical results), how often checkpoints and TensorBoard files are written, and
``train.episodes`` (one seed may be extended with ``train --resume seed-NNN --episodes N``)"""


def check_seed_config(parent: Path, child: Path, expected: Config, found: Config) -> None:
    """Refuse a seed directory whose run is not the multi-seed run's config with its seed.

    A directory copied in from another run (another environment, algorithm, or seed)
    would otherwise be averaged with the others as if it were one of them.

    Raises:
        RunError: naming the seed directory and each key that differs, with both values.
    """
    differences = [
        (key, old, new)
        for key, old, new in config_differences(expected, found)
        if key not in NEUTRAL_KEYS
    ]
    if not differences:
        return
    differences.sort(key=lambda difference: difference[0] != "env.id")  # the telling one first
    shown = "; ".join(
        f"{key} is {shown_value(new)} in {child.name} but {shown_value(old)} in "
        f"{parent / rundir.CONFIG_FILE}"
        for key, old, new in differences[:3]
    )
    more = f" (and {len(differences) - 3} more keys)" if len(differences) > 3 else ""
    raise RunError(
        f"{child}: is not a seed of the multi-seed run {parent}: its config differs in what "
        f"changes results: {shown}{more}. A multi-seed run's seeds share one config but "
        f"their seed, so that their figures can be put together; move {child.name} out of "
        f"{parent} (it is then named as missing), or use it as a run of its own."
    )


def _left_out(parent: Path, total: int, missing: list[str], unfinished: list[str]) -> str:
    """``PARENT: 2 of 3 seeds left out: seed-001 is missing; seed-002 has not finished (...)``."""
    if not missing and not unfinished:
        return ""
    parts = []
    if missing:
        parts.append(f"{_names(missing)} {'is' if len(missing) == 1 else 'are'} missing")
    if unfinished:
        verb = "has" if len(unfinished) == 1 else "have"
        parts.append(f"{_names(unfinished)} {verb} not finished")
    return (
        f"{parent}: {len(missing) + len(unfinished)} of {total} seeds left out: "
        f"{'; '.join(parts)} (finish them with `cartpole-q train --resume {parent}`)"
    )


def _names(names: list[str], limit: int = 8) -> str:
    shown = ", ".join(names[:limit])
    return shown if len(names) <= limit else f"{shown} and {len(names) - limit} more"


def _sweep_point(point_dir: Path, rows: list[sweepdir.ResultRow]) -> RunSet:
    """A sweep point's seeds as runs: rows, tables and (when kept) learning curves."""
    sweep = point_dir.parent.parent
    config = rundir.read_config_file(point_dir / rundir.CONFIG_FILE)
    grid = config.discretization
    tables = sweepdir.read_tables(
        sweep, point_dir.name, rundir.table_check(None if grid is None else grid.table_shape)
    )
    curves = sweepdir.read_curves(sweep, point_dir.name)
    records = sweepdir.read_records(sweep, point_dir.name)
    visits = sweepdir.read_visits(sweep, point_dir.name)
    info_column = f"{rundir.INFO_COLUMN_PREFIX}{config.train.info_metric}"
    predicts = get_algorithm(config.agent.algorithm).predicts
    threshold = rundir.config_threshold(config)
    seeds = sweepdir.sweep_seeds(sweep)
    runs = []
    for row in rows:
        seed = row.result.seed
        key = sweepdir.seed_key(seed, seeds)
        if key not in tables:
            raise RunError(
                f"{sweepdir.tables_path(sweep, point_dir.name)}: has no table {key} for the "
                f"finished run of seed {seed}; the sweep directory is damaged."
            )
        seed_config = config.for_seed(seed)
        returns, lengths = curves.get(key, (np.zeros(0), np.zeros(0, dtype=np.int64)))
        runs.append(
            rundir.Run(
                path=point_dir / key,
                config=seed_config,
                q_table=tables[key],
                visits=visits.get(key),
                metrics=_metrics(seed_config, returns, lengths),
                result=dataclasses.replace(row.result, reward_threshold=threshold),
                info=records.get(key, {}).get(info_column),
                errors=records.get(key, {}).get(rundir.ERRORS_COLUMN),
                predicts=predicts,
            )
        )
    total = len(seeds)
    notes = []
    if len(runs) < total:
        notes.append(
            f"{point_dir}: {len(runs)} of its {total} seeds have finished; the others are left "
            f"out (finish the sweep with `cartpole-q sweep --resume {sweep}`)."
        )
    return RunSet(point_dir, "sweep point", runs, notes)


def _metrics(config: Config, returns: np.ndarray, lengths: np.ndarray) -> EpisodeMetrics:
    """Per-episode metrics from a kept curve; epsilon and alpha from the config's schedules."""
    from cartpole_q.rl.schedules import CONSTANT, schedule_value

    def rates(schedule: Schedule) -> np.ndarray:
        code, start, end, rate = schedule.code, schedule.start, schedule.end, schedule.rate
        if code == CONSTANT:  # (most sweeps: millions of episodes, one value)
            return np.full(len(returns), start, dtype=np.float64)
        return np.array(
            [schedule_value(code, start, end, rate, e) for e in range(len(returns))],
            dtype=np.float64,
        )

    return EpisodeMetrics(
        np.asarray(returns, dtype=np.float64),
        np.asarray(lengths, dtype=np.int64),
        rates(config.agent.epsilon),
        rates(config.agent.alpha),
    )
