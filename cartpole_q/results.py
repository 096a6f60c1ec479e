"""Typed results: one seed's outcome, a run's ``summary.json``, many seeds' summary.

Built once, read everywhere: :class:`SeedResult` is what one (config, seed) achieved, made
from the :class:`~cartpole_q.training.TrainResult` when it ends, or read back from a run's
``summary.json`` or a sweep's ``results.csv`` row. :class:`RunSummary` and
:class:`MultiSeedSummary` are the two forms of ``summary.json`` (design.md, "Run
directory"); they read old files (keys added since are optional) and keep keys they do not
know. :func:`summarize_seeds` gives the statistics of many seeds of one config, the same
for a multi-seed run, a sweep point and a tune trial.

Strings live only in :mod:`cartpole_q.store`, where CSV is written and read; JSON
(``to_json``/``from_json``) is plain data here, ready for :func:`json.dumps`.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any

import numpy as np

from cartpole_q.config import shown
from cartpole_q.errors import RunError
from cartpole_q.evaluation import EvalReport
from cartpole_q.statistics import PointStatistics, summarize_point
from cartpole_q.training import TrainResult

JsonObject = dict[str, Any]
"""a JSON object as :mod:`json` reads and writes it (the edge where ``Any`` is honest)"""


def is_success(eval_mean: float | None, threshold: float | None) -> bool | None:
    """Whether a greedy eval mean reached the threshold; ``None`` when either is missing.

    The one definition of success, everywhere.

    >>> is_success(480.0, 475.0), is_success(480.0, None)
    (True, None)
    """
    if eval_mean is None or threshold is None:
        return None
    return eval_mean >= threshold


@dataclass(frozen=True)
class SeedResult:
    """What one run (a config and a seed) achieved: the ``results.csv`` row's figures."""

    seed: int
    episodes: int
    """episodes trained"""
    env_steps: int
    """environment steps of training"""
    solved_episode: int | None
    """first episode whose 100-episode average return reached the threshold"""
    env_steps_to_solve: int | None
    """environment steps through the solve episode"""
    first_greedy_success_env_steps: int | None
    """environment steps at the first periodic greedy evaluation that reached the threshold"""
    eval_mean: float | None
    """the final greedy evaluation's mean return (``None``: interrupted before it)"""
    success: bool | None
    """``eval_mean >= reward_threshold`` (``None`` without either)"""
    reward_threshold: float | None = None
    """the solve threshold (not a ``results.csv`` column: the config gives it)"""
    train_seconds: float = 0.0
    """seconds spent in training episodes"""
    interrupted: bool = False
    """stopped before ``train.episodes`` (or the solve point)"""
    mean_return: float | None = None
    """the mean training return over all the run's episodes (:func:`mean_return`; ``None``:
    not recorded, as in a ``results.csv`` written before the column)"""
    rms_error: float | None = None
    """a prediction run's RMS error after its last episode (``None``: a control run, a
    world without a model to measure it, or a ``results.csv`` written before the column)"""
    predicts: bool = False
    """a prediction run (it learnt ``V``; not a ``results.csv`` column)"""

    @classmethod
    def of_train(cls, result: TrainResult) -> SeedResult:
        """The figures of a finished (or interrupted) training."""
        eval_mean = None if result.eval is None else float(result.eval.mean)
        greedy = result.first_greedy_success()
        return cls(
            seed=result.config.seed,
            episodes=result.episodes,
            env_steps=result.env_steps,
            solved_episode=result.solved_episode,
            env_steps_to_solve=env_steps_to_solve(result),
            first_greedy_success_env_steps=None if greedy is None else greedy["env_steps"],
            eval_mean=eval_mean,
            success=is_success(eval_mean, result.reward_threshold),
            reward_threshold=result.reward_threshold,
            train_seconds=round(result.train_seconds, 6),
            interrupted=result.interrupted,
            mean_return=mean_return(result.returns),
            rms_error=final_error(result.errors),
            predicts=result.predicts,
        )


def final_error(errors: np.ndarray | None) -> float | None:
    """A prediction run's RMS error after its last episode (``None``: none measured).

    >>> final_error(np.array([0.3, 0.2])), final_error(None), final_error(np.zeros(0))
    (0.2, None, None)
    """
    if errors is None or not len(errors):
        return None
    return float(errors[-1])


def mean_return(returns: Sequence[float] | np.ndarray) -> float | None:
    """The mean of a run's training returns, exactly rounded (``None`` for no episode).

    The sum is :func:`math.fsum` (correctly rounded, whatever the order), divided once by
    the number of episodes: the same number from ``metrics.csv``'s ``return`` column.

    >>> mean_return([-13.0, -100.0, 0.1, 0.2]), mean_return([])
    (-28.175, None)
    """
    values = np.asarray(returns, dtype=np.float64)
    if not len(values):
        return None
    return math.fsum(values.tolist()) / len(values)


def env_steps_to_solve(result: TrainResult) -> int | None:
    """Environment steps through the solve episode (``None`` if it did not solve)."""
    solved = result.solved_episode
    return None if solved is None else int(result.lengths[:solved].sum())


@dataclass(frozen=True)
class Spread:
    """The median and quartiles of a figure over seeds."""

    median: float
    q25: float
    q75: float

    @classmethod
    def of(cls, values: Sequence[float]) -> Spread | None:
        """The spread of ``values`` (``None`` when there are none).

        >>> Spread.of([1, 2, 3, 4])
        Spread(median=2.5, q25=1.75, q75=3.25)
        """
        if not values:
            return None
        q25, median, q75 = np.percentile(values, [25, 50, 75])
        return cls(float(median), float(q25), float(q75))

    def to_json(self) -> JsonObject:
        """``{"median", "q25", "q75"}``."""
        return {"median": self.median, "q25": self.q25, "q75": self.q75}

    @classmethod
    def from_json(cls, data: object, where: str) -> Spread | None:
        """Read what :meth:`to_json` wrote (``None`` for null)."""
        if data is None:
            return None
        reader = _Reader(data, where)
        return cls(reader.number("median"), reader.number("q25"), reader.number("q75"))


@dataclass(frozen=True)
class EvalFigures:
    """A greedy evaluation as ``eval --json`` prints it (``summary.json``'s ``eval``)."""

    mean: float
    std: float
    min: float
    max: float
    episodes: int
    seed: int
    played_in: str | None = None
    """``twin`` (the numba engine's compiled environment) or ``gymnasium``"""
    interrupted: bool = False
    """a stop cut the evaluation short: ``episodes`` counts those played (written only
    when true, so files without the key read as whole evaluations)"""

    @classmethod
    def of_report(
        cls, report: EvalReport, played_in: str | None = None, interrupted: bool = False
    ) -> EvalFigures:
        """The figures of an evaluation's returns."""
        data = report.to_dict()
        return cls(
            data["mean"], data["std"], data["min"], data["max"], data["episodes"],
            data["seed"], played_in, interrupted,
        )  # fmt: skip

    def to_json(self) -> JsonObject:
        """The JSON object, in ``eval --json``'s key order."""
        data: JsonObject = {
            "mean": self.mean, "std": self.std, "min": self.min, "max": self.max,
            "episodes": self.episodes, "seed": self.seed,
        }  # fmt: skip
        if self.played_in is not None:
            data["played_in"] = self.played_in
        if self.interrupted:
            data["interrupted"] = True
        return data

    @classmethod
    def from_json(cls, data: object, where: str) -> EvalFigures | None:
        """Read what :meth:`to_json` wrote (``None`` for null)."""
        if data is None:
            return None
        reader = _Reader(data, where)
        return cls(
            reader.number("mean"), reader.number("std"), reader.number("min"),
            reader.number("max"), reader.integer("episodes"), reader.integer("seed"),
            reader.optional_text("played_in"), reader.flag("interrupted", default=False),
        )  # fmt: skip


@dataclass(frozen=True)
class GreedySuccess:
    """The first periodic greedy evaluation that reached the threshold."""

    episode: int | None
    """the episode after which it ran (``None`` where only the steps were kept)"""
    env_steps: int
    played_in: str | None = None

    def to_json(self) -> JsonObject:
        """``{"episode", "env_steps"[, "played_in"]}``."""
        data: JsonObject = {"episode": self.episode, "env_steps": self.env_steps}
        if self.played_in is not None:
            data["played_in"] = self.played_in
        return data

    @classmethod
    def from_json(cls, data: object, where: str) -> GreedySuccess | None:
        """Read what :meth:`to_json` wrote (``None`` for null)."""
        if data is None:
            return None
        reader = _Reader(data, where)
        return cls(
            reader.optional_integer("episode"),
            reader.integer("env_steps"),
            reader.optional_text("played_in"),
        )


_RUN_KEYS = (
    "episodes", "env_steps", "wall_seconds", "train_seconds", "steps_per_second",
    "solved_episode", "env_steps_to_solve", "reward_threshold", "q_table", "v_table",
    "rms_error", "eval", "first_greedy_success", "engine", "seed", "interrupted", "versions",
    "finished_at",
)  # fmt: skip


@dataclass(frozen=True)
class RunSummary:
    """One run's ``summary.json``.

    Files written before a key existed read with its default (``None``, or ``False`` for
    ``interrupted``); keys this version does not know are kept in :attr:`extra` and
    written back after the known ones. A prediction run names its kept table ``v_table``
    (its file is ``v_table.npy``) and writes ``rms_error``, the error after its last episode.
    """

    episodes: int
    env_steps: int
    wall_seconds: float
    steps_per_second: float
    solved_episode: int | None
    eval: EvalFigures | None
    engine: str | None
    seed: int | None
    versions: Mapping[str, str]
    train_seconds: float | None = None
    env_steps_to_solve: int | None = None
    reward_threshold: float | None = None
    kept_episode: int | None = None
    """the episode after which ``q_table.npy`` was taken"""
    kept_from: str | None = None
    """``solve point`` or ``last episode``"""
    first_greedy_success: GreedySuccess | None = None
    interrupted: bool = False
    finished_at: str | None = None
    predicts: bool = False
    """a prediction run: its table is ``V`` (``v_table``), its figure ``rms_error``"""
    rms_error: float | None = None
    """a prediction run's RMS error after its last episode (``None``: not measured)"""
    extra: Mapping[str, Any] = field(default_factory=lambda: MappingProxyType({}))
    """keys of the file this version does not know, kept as they were"""

    @classmethod
    def of_train(
        cls, result: TrainResult, versions: Mapping[str, str], finished_at: str
    ) -> RunSummary:
        """The summary of a training result."""
        # The numba engine plays its evaluations on the compiled twin (bit-identical to
        # Gymnasium's environment); `cartpole-q eval` always plays in gymnasium.make.
        played_in = "twin" if result.engine == "numba" else "gymnasium"
        report = result.eval
        greedy = result.first_greedy_success()
        return cls(
            episodes=result.episodes,
            env_steps=result.env_steps,
            wall_seconds=round(result.wall_seconds, 6),
            train_seconds=round(result.train_seconds, 6),
            steps_per_second=round(result.steps_per_second, 1),
            solved_episode=result.solved_episode,
            env_steps_to_solve=env_steps_to_solve(result),
            reward_threshold=result.reward_threshold,
            kept_episode=result.kept_episode,
            kept_from="solve point" if result.solved_episode is not None else "last episode",
            eval=None
            if report is None
            else EvalFigures.of_report(report, played_in, result.eval_interrupted),
            first_greedy_success=None
            if greedy is None
            else GreedySuccess(greedy["episode"], greedy["env_steps"], played_in),
            engine=result.engine,
            seed=result.config.seed,
            interrupted=result.interrupted,
            versions=MappingProxyType(dict(versions)),
            finished_at=finished_at,
            predicts=result.predicts,
            rms_error=final_error(result.errors),
        )

    def result(self, seed: int | None = None) -> SeedResult:
        """The run's figures as a :class:`SeedResult` (``seed`` when the file has none)."""
        eval_mean = None if self.eval is None else self.eval.mean
        steps = self.first_greedy_success
        return SeedResult(
            seed=self.seed if self.seed is not None else (seed or 0),
            episodes=self.episodes,
            env_steps=self.env_steps,
            solved_episode=self.solved_episode,
            env_steps_to_solve=self.env_steps_to_solve,
            first_greedy_success_env_steps=None if steps is None else steps.env_steps,
            eval_mean=eval_mean,
            success=is_success(eval_mean, self.reward_threshold),
            reward_threshold=self.reward_threshold,
            train_seconds=self.train_seconds or 0.0,
            interrupted=self.interrupted,
            rms_error=self.rms_error,
            predicts=self.predicts,
        )

    def to_json(self) -> JsonObject:
        """The JSON object, keys in the order this version writes them."""
        kept = {"episode": self.kept_episode, "source": self.kept_from}
        table: JsonObject = {"q_table": kept}
        if self.predicts:
            table = {"v_table": kept, "rms_error": self.rms_error}
        return {
            "episodes": self.episodes,
            "env_steps": self.env_steps,
            "wall_seconds": self.wall_seconds,
            "train_seconds": self.train_seconds,
            "steps_per_second": self.steps_per_second,
            "solved_episode": self.solved_episode,
            "env_steps_to_solve": self.env_steps_to_solve,
            "reward_threshold": self.reward_threshold,
            **table,
            "eval": None if self.eval is None else self.eval.to_json(),
            "first_greedy_success": None
            if self.first_greedy_success is None
            else self.first_greedy_success.to_json(),
            "engine": self.engine,
            "seed": self.seed,
            "interrupted": self.interrupted,
            "versions": dict(self.versions),
            "finished_at": self.finished_at,
            **self.extra,
        }

    @classmethod
    def from_json(cls, data: object, where: str) -> RunSummary:
        """Read a ``summary.json`` object of a single run.

        Raises:
            RunError: a key design.md requires is missing, or a value has the wrong type;
                the message names the file and the key.
        """
        reader = _Reader(data, where)
        predicts = reader.get("v_table") is not None
        kept = reader.optional_object("v_table" if predicts else "q_table")
        return cls(
            episodes=reader.integer("episodes"),
            env_steps=reader.integer("env_steps"),
            wall_seconds=reader.number("wall_seconds"),
            steps_per_second=reader.number("steps_per_second"),
            solved_episode=reader.optional_integer("solved_episode"),
            eval=EvalFigures.from_json(reader.get("eval"), f"{where}: eval"),
            engine=reader.optional_text("engine"),
            seed=reader.optional_integer("seed"),
            versions=MappingProxyType(reader.text_mapping("versions")),
            train_seconds=reader.optional_number("train_seconds"),
            env_steps_to_solve=reader.optional_integer("env_steps_to_solve"),
            reward_threshold=reader.optional_number("reward_threshold"),
            kept_episode=None if kept is None else kept.optional_integer("episode"),
            kept_from=None if kept is None else kept.optional_text("source"),
            first_greedy_success=GreedySuccess.from_json(
                reader.get("first_greedy_success"), f"{where}: first_greedy_success"
            ),
            interrupted=reader.flag("interrupted", default=False),
            finished_at=reader.optional_text("finished_at"),
            predicts=predicts,
            rms_error=reader.optional_number("rms_error"),
            extra=MappingProxyType(reader.others(_RUN_KEYS)),
        )


@dataclass(frozen=True)
class SeedEntry:
    """One seed in a multi-seed ``summary.json``'s ``per_seed``."""

    path: str
    """the seed's directory name (``seed-007``)"""
    episodes: int
    solved_episode: int | None
    env_steps_to_solve: int | None
    eval_mean: float | None
    first_greedy_success: GreedySuccess | None
    interrupted: bool

    @classmethod
    def of(cls, path: str, summary: RunSummary) -> SeedEntry:
        """The entry of a seed whose directory holds ``summary``."""
        return cls(
            path=path,
            episodes=summary.episodes,
            solved_episode=summary.solved_episode,
            env_steps_to_solve=summary.env_steps_to_solve,
            eval_mean=None if summary.eval is None else summary.eval.mean,
            first_greedy_success=summary.first_greedy_success,
            interrupted=summary.interrupted,
        )

    def to_json(self) -> JsonObject:
        """The JSON object."""
        greedy = self.first_greedy_success
        return {
            "path": self.path,
            "solved_episode": self.solved_episode,
            "env_steps_to_solve": self.env_steps_to_solve,
            "eval_mean": self.eval_mean,
            "first_greedy_success": None if greedy is None else greedy.to_json(),
            "episodes": self.episodes,
            "interrupted": self.interrupted,
        }

    @classmethod
    def from_json(cls, data: object, where: str) -> SeedEntry:
        """Read what :meth:`to_json` wrote."""
        reader = _Reader(data, where)
        return cls(
            path=reader.text("path"),
            episodes=reader.integer("episodes"),
            solved_episode=reader.optional_integer("solved_episode"),
            env_steps_to_solve=reader.optional_integer("env_steps_to_solve"),
            eval_mean=reader.optional_number("eval_mean"),
            first_greedy_success=GreedySuccess.from_json(
                reader.get("first_greedy_success"), f"{where}: first_greedy_success"
            ),
            interrupted=reader.flag("interrupted", default=False),
        )


@dataclass(frozen=True)
class EvalMeans:
    """The seeds' greedy eval means: their mean, lowest and median."""

    mean: float
    min: float
    median: float

    def to_json(self) -> JsonObject:
        """``{"mean", "min", "median"}``."""
        return {"mean": self.mean, "min": self.min, "median": self.median}


_MULTI_KEYS = (
    "seeds", "runs", "finished", "unfinished", "interrupted_seeds", "no_result_seeds",
    "interrupted", "engine", "reward_threshold", "successes", "success_rate", "solved_runs",
    "solved_episode", "env_steps_to_solve", "first_greedy_success_env_steps", "eval_mean",
    "statistics", "wall_seconds", "per_seed", "versions",
)  # fmt: skip


@dataclass(frozen=True)
class MultiSeedSummary:
    """A multi-seed run's ``summary.json`` (the parent directory's).

    Every statistic is over the finished seeds (``finished`` of ``runs``); the others are
    counted in ``unfinished`` and named in ``interrupted_seeds`` (stopped early, listed in
    ``per_seed`` too) and ``no_result_seeds`` (not started, or killed before writing a
    result), both in ``--seeds`` syntax.
    """

    seeds: str
    """the run's seeds in ``--seeds`` syntax"""
    runs: int
    finished: int
    unfinished: int
    interrupted_seeds: str
    no_result_seeds: str
    interrupted: bool
    engine: str | None
    reward_threshold: float | None
    successes: int
    success_rate: float | None
    solved_runs: int
    solved_episode: Spread | None
    env_steps_to_solve: Spread | None
    first_greedy_success_env_steps: Spread | None
    eval_mean: EvalMeans | None
    wall_seconds: float
    per_seed: Mapping[str, SeedEntry]
    versions: Mapping[str, str]
    statistics: PointStatistics | None = None
    """the sweep point's statistics of the finished seeds (``None`` in older files)"""
    extra: Mapping[str, Any] = field(default_factory=lambda: MappingProxyType({}))

    @classmethod
    def of_seeds(
        cls,
        seeds: str,
        runs: int,
        entries: Mapping[str, tuple[SeedEntry, SeedResult, str | None]],
        wall_seconds: float,
        interrupted: bool,
        versions: Mapping[str, str],
        no_result_seeds: str,
        interrupted_seeds: str,
    ) -> MultiSeedSummary:
        """Summarise the seeds that have a result.

        Args:
            seeds: all the run's seeds, in ``--seeds`` syntax.
            runs: how many seeds the run has.
            entries: by seed, its entry, its result and the engine that ran it.
            wall_seconds: the command's time.
            interrupted: the command was stopped.
            versions: the versions of the packages.
            no_result_seeds: the seeds without a result, in ``--seeds`` syntax.
            interrupted_seeds: the seeds stopped early, in ``--seeds`` syntax.
        """
        results = [result for _, result, _ in entries.values()]
        finished = [result for result in results if not result.interrupted]
        threshold = next((r.reward_threshold for r in reversed(results) if r.reward_threshold is not None), None)  # fmt: skip
        engine = next((e for _, _, e in reversed(list(entries.values())) if e is not None), None)
        means = [r.eval_mean for r in finished if r.eval_mean is not None]
        successes = sum(1 for r in finished if r.eval_mean is not None and r.success)
        solved = [r.solved_episode for r in finished if r.solved_episode is not None]
        steps = [r.env_steps_to_solve for r in finished if r.env_steps_to_solve is not None]
        greedy = [
            r.first_greedy_success_env_steps
            for r in finished
            if r.first_greedy_success_env_steps is not None
        ]
        return cls(
            seeds=seeds,
            runs=runs,
            finished=len(finished),
            unfinished=runs - len(finished),
            interrupted_seeds=interrupted_seeds,
            no_result_seeds=no_result_seeds,
            interrupted=interrupted or len(finished) < runs,
            engine=engine,
            reward_threshold=threshold,
            successes=successes,
            success_rate=successes / len(finished) if finished else None,
            solved_runs=len(solved),
            solved_episode=Spread.of(solved),
            env_steps_to_solve=Spread.of(steps),
            first_greedy_success_env_steps=Spread.of(greedy),
            eval_mean=None
            if not means
            else EvalMeans(float(np.mean(means)), float(np.min(means)), float(np.median(means))),
            statistics=summarize_seeds(finished),
            wall_seconds=round(wall_seconds, 3),
            per_seed=MappingProxyType({seed: entry for seed, (entry, _, _) in entries.items()}),
            versions=MappingProxyType(dict(versions)),
        )

    def to_json(self) -> JsonObject:
        """The JSON object, keys in the order this version writes them."""

        def spread(value: Spread | None) -> JsonObject | None:
            return None if value is None else value.to_json()

        return {
            "seeds": self.seeds,
            "runs": self.runs,
            "finished": self.finished,
            "unfinished": self.unfinished,
            "interrupted_seeds": self.interrupted_seeds,
            "no_result_seeds": self.no_result_seeds,
            "interrupted": self.interrupted,
            "engine": self.engine,
            "reward_threshold": self.reward_threshold,
            "successes": self.successes,
            "success_rate": self.success_rate,
            "solved_runs": self.solved_runs,
            "solved_episode": spread(self.solved_episode),
            "env_steps_to_solve": spread(self.env_steps_to_solve),
            "first_greedy_success_env_steps": spread(self.first_greedy_success_env_steps),
            "eval_mean": None if self.eval_mean is None else self.eval_mean.to_json(),
            "statistics": None if self.statistics is None else self.statistics.as_row(),
            "wall_seconds": self.wall_seconds,
            "per_seed": {seed: entry.to_json() for seed, entry in self.per_seed.items()},
            "versions": dict(self.versions),
            **self.extra,
        }

    @classmethod
    def from_json(cls, data: object, where: str) -> MultiSeedSummary:
        """Read a multi-seed ``summary.json`` object.

        Raises:
            RunError: a key is missing or has the wrong type (naming the file and key).
        """
        reader = _Reader(data, where)
        means = reader.optional_object("eval_mean")
        statistics = reader.optional_object("statistics")
        per_seed = reader.optional_object("per_seed")
        return cls(
            seeds=reader.text("seeds"),
            runs=reader.integer("runs"),
            finished=reader.integer("finished"),
            unfinished=reader.optional_integer("unfinished")
            or reader.integer("runs") - reader.integer("finished"),
            interrupted_seeds=reader.optional_text("interrupted_seeds") or "",
            no_result_seeds=reader.optional_text("no_result_seeds") or "",
            interrupted=reader.flag("interrupted", default=False),
            engine=reader.optional_text("engine"),
            reward_threshold=reader.optional_number("reward_threshold"),
            successes=reader.optional_integer("successes") or 0,
            success_rate=reader.optional_number("success_rate"),
            solved_runs=reader.optional_integer("solved_runs") or 0,
            solved_episode=Spread.from_json(
                reader.get("solved_episode"), f"{where}: solved_episode"
            ),
            env_steps_to_solve=Spread.from_json(
                reader.get("env_steps_to_solve"), f"{where}: env_steps_to_solve"
            ),
            first_greedy_success_env_steps=Spread.from_json(
                reader.get("first_greedy_success_env_steps"),
                f"{where}: first_greedy_success_env_steps",
            ),
            eval_mean=None
            if means is None
            else EvalMeans(means.number("mean"), means.number("min"), means.number("median")),
            statistics=None
            if statistics is None
            else PointStatistics(
                statistics.integer("seeds"),
                # a statistic of no finished seed is NaN: written so, read back so
                *(
                    statistics.optional_number(name, finite=False)
                    for name in PointStatistics.columns()[1:]
                ),
            ),
            wall_seconds=reader.optional_number("wall_seconds") or 0.0,
            per_seed=MappingProxyType(
                {}
                if per_seed is None
                else {
                    key: SeedEntry.from_json(per_seed.get(key), f"{where}: per_seed: {key}")
                    for key in per_seed.names()
                }
            ),
            versions=MappingProxyType(reader.text_mapping("versions")),
            extra=MappingProxyType(reader.others(_MULTI_KEYS)),
        )

    def interrupted_eval_means(self) -> list[float]:
        """The greedy eval means the interrupted seeds had reached."""
        return [
            entry.eval_mean
            for entry in self.per_seed.values()
            if entry.interrupted and entry.eval_mean is not None
        ]


def summarize_seeds(results: Sequence[SeedResult]) -> PointStatistics:
    """The statistics of many seeds of one config: a multi-seed run, a sweep point, a trial.

    ``seeds`` counts every result; the evaluation's statistics are over the seeds with a
    final greedy evaluation, the RMS error's over the prediction runs that measured one.
    The success rate is ``None`` when some seed has no success (no reward threshold).

    >>> result = SeedResult(0, 10, 900, 5, 400, None, 480.0, True)
    >>> summarize_seeds([result]).success_rate
    1.0
    """
    evaluated = [result for result in results if result.eval_mean is not None]
    statistics = summarize_point(
        [result.eval_mean for result in evaluated if result.eval_mean is not None],
        [bool(result.success) for result in evaluated],
        [result.solved_episode for result in evaluated],
        [result.env_steps_to_solve for result in evaluated],
        rms_errors=[result.rms_error for result in results if result.rms_error is not None],
    )
    # `seeds` counts every seed with a result (a prediction run has no greedy evaluation).
    statistics = dataclasses.replace(statistics, seeds=len(results))
    if any(result.success is None for result in evaluated):
        # no reward threshold: there is no success to count
        return dataclasses.replace(
            statistics, success_rate=None, success_rate_low=None, success_rate_high=None
        )
    return statistics


class _Reader:
    """Typed access to a JSON object, with errors naming the file and the key."""

    def __init__(self, data: object, where: str) -> None:
        if not isinstance(data, dict):
            raise RunError(f"{where}: must be a JSON object.")
        self._data: dict[str, Any] = data
        self._where = where

    def get(self, key: str) -> object:
        return self._data.get(key)

    def names(self) -> list[str]:
        return list(self._data)

    def others(self, known: Sequence[str]) -> dict[str, Any]:
        return {key: value for key, value in self._data.items() if key not in known}

    def _wrong(self, key: str, kind: str) -> RunError:
        return RunError(f"{self._where}: {key}: must be {kind}, got {shown(self._data.get(key))}.")

    def _required(self, key: str) -> object:
        if key not in self._data:
            raise RunError(f"{self._where}: misses the key {key}.")
        return self._data[key]

    def number(self, key: str, *, finite: bool = True) -> float:
        """A number; NaN and infinities (JSON's ``NaN``, ``Infinity``) only when not ``finite``.

        A run's figures are finite: a NaN would pass every comparison silently (and make
        statistics fail far from the file that holds it).
        """
        value = self._required(key)
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise self._wrong(key, "a number")
        if finite and not math.isfinite(value):
            raise self._wrong(key, "a finite number")
        return float(value)

    def optional_number(self, key: str, *, finite: bool = True) -> float | None:
        return None if self._data.get(key) is None else self.number(key, finite=finite)

    def integer(self, key: str) -> int:
        value = self._required(key)
        if isinstance(value, bool) or not isinstance(value, int):
            raise self._wrong(key, "an integer")
        return value

    def optional_integer(self, key: str) -> int | None:
        return None if self._data.get(key) is None else self.integer(key)

    def text(self, key: str) -> str:
        value = self._required(key)
        if not isinstance(value, str):
            raise self._wrong(key, "a string")
        return value

    def optional_text(self, key: str) -> str | None:
        return None if self._data.get(key) is None else self.text(key)

    def flag(self, key: str, *, default: bool) -> bool:
        value = self._data.get(key, default)
        if not isinstance(value, bool):
            raise self._wrong(key, "true or false")
        return value

    def text_mapping(self, key: str) -> dict[str, str]:
        value = self._data.get(key) or {}
        if not isinstance(value, dict):
            raise self._wrong(key, "an object")
        return {str(name): str(item) for name, item in value.items()}

    def optional_object(self, key: str) -> _Reader | None:
        value = self._data.get(key)
        return None if value is None else _Reader(value, f"{self._where}: {key}")
