"""Many seeds in one command: one contract run per seed, in parallel, and an aggregate.

The parent directory holds the config (with ``train.seeds``), one ``seed-NNN``
subdirectory per seed (each a complete single run whose ``config.yaml`` reproduces it
alone), and an aggregate ``summary.json`` written last. Seeds run in worker processes,
one per core; a seed's results do not depend on which worker ran it, or when.
"""

from __future__ import annotations

import dataclasses
import os
import time
from collections.abc import Callable, Iterator, Sequence
from contextlib import suppress
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from cartpole_q.config import format_seeds, load_config
from cartpole_q.engines.plan import Plan, keep_plan, planned, planning
from cartpole_q.errors import RunError
from cartpole_q.experiments.compiling import compile_ahead
from cartpole_q.experiments.run import (
    Reporting,
    check_resumable,
    execute_run,
    outcome_line,
)
from cartpole_q.experiments.workers import (
    JobHandle,
    chunk_size,
    execute,
)
from cartpole_q.progress import NullReporter, Reporter
from cartpole_q.results import MultiSeedSummary, SeedEntry, SeedResult
from cartpole_q.store import rundir
from cartpole_q.store.atomic import atomic_write_bytes, make_directory, write_json
from cartpole_q.store.checkpoint import CHECKPOINT_FILE, load_checkpoint
from cartpole_q.store.runsets import seed_dir
from cartpole_q.training import Checkpoint, TrainResult


@planning()  # one plan for every seed
def run_seeds(
    prepared: Plan,
    parent: Path,
    *,
    workers: int,
    reporter: Reporter | None = None,
    should_stop: Callable[[], bool] | None = None,
    resume: bool = False,
    seed_plots: bool = False,
    backend: str = "local",
    address: str | None = None,
) -> MultiSeedSummary:
    """Train every seed of ``prepared.config`` under ``parent`` and write the aggregate.

    Args:
        prepared: the checked multi-seed config.
        parent: the parent run directory, holding the multi-seed ``config.yaml``.
        workers: worker processes; 1 trains in this process, one seed after another.
        reporter: receives each worker's progress and each seed's outcome.
        should_stop: polled while waiting; when true, workers stop at the end of their
            current episode and unstarted seeds are left for ``--resume``.
        resume: keep finished seeds, resume interrupted ones, start the rest.
        seed_plots: draw each seed's ``reward_curve.png`` (about 0.15 s per seed) and the
            parent's, which shows every seed with a band. Without it no figure is drawn,
            so that many seeds train in seconds (``cartpole-q plot DIR`` draws it later).
        backend: ``local`` (workers write their seed's directory, checkpoints included)
            or ``ray`` (tasks, maybe on other machines, train in memory and send each
            finished seed back, which this process writes; an interrupted seed's
            checkpoint goes with its task).
        address: a running Ray cluster's address (``ray`` only).

    Returns:
        The aggregate summary (also written as ``parent/summary.json``).
    """
    reporter = reporter or NullReporter()
    config = prepared.config
    seeds = config.train.seeds
    assert seeds is not None
    started = time.perf_counter()
    if resume:
        (parent / rundir.SUMMARY_FILE).unlink(missing_ok=True)
    jobs: list[tuple[int, Path, bool]] = []
    for seed in seeds:
        child = seed_dir(parent, seed, seeds)
        if resume and _finished(child):
            continue
        # A started seed resumes from its checkpoint (or from episode 0 if it has none).
        child_resume = resume and (child / rundir.CONFIG_FILE).is_file()
        if not child_resume:
            make_directory(child)
            rundir.write_config(child, config.for_seed(seed))
        jobs.append((seed, child, child_resume))

    finished: list[int] = []
    if backend == "ray":
        _train_remotely(
            prepared, jobs, finished, workers, address, should_stop, reporter, seed_plots
        )
    else:

        def on_item(index: int, item: tuple[int, bool]) -> None:
            seed, interrupted = item
            if not interrupted:
                finished.append(seed)

        # Several seeds per job: a worker loads the config and the compiled loop once per
        # job, not once per seed.
        items = [(str(child), seed, child_resume) for seed, child, child_resume in jobs]
        size = chunk_size(len(items), workers)
        chunks = [(items[i : i + size], seed_plots) for i in range(0, len(items), size)]
        keep_plan(prepared)  # the seeds' jobs here and in forked workers share it
        if len(chunks) > 1:  # compiled once before the workers start, not once per worker
            compile_ahead([prepared], workers, should_stop)
        execute(
            _train_seeds, chunks, on_item,
            workers=workers, should_stop=should_stop, reporter=reporter,
        )  # fmt: skip
    interrupted = len(finished) < len(jobs)

    summary = aggregate(parent, seeds, time.perf_counter() - started, interrupted)
    if seed_plots:
        _plot_seeds(parent)
    write_json(parent / rundir.SUMMARY_FILE, summary.to_json())
    return summary


def _plot_seeds(parent: Path) -> None:
    """Draw the parent's ``reward_curve.png``: every finished seed's returns, with a band."""
    from cartpole_q.experiments.plots import plot_rewards

    with suppress(RunError):  # no seed has finished: there is nothing to draw
        plot_rewards([parent], parent / rundir.CURVE_FILE, force=True)


def _train_seeds(
    handle: JobHandle, items: Sequence[tuple[str, int, bool]], plot: bool
) -> Iterator[tuple[int, bool]]:
    """Job: train seeds into their directories, one after another.

    Each item is (seed directory, seed, resume). The seeds share one config but their
    seed, so it is checked against its environment once.

    Yields:
        ``(seed, interrupted)`` as each started seed ends; a stop leaves the rest out.
    """
    reporter = handle.reporter()
    for child, seed, resume in items:
        if handle.should_stop():
            return
        path = Path(child)
        config = load_config(path / rundir.CONFIG_FILE)
        plan = planned(config, str(path / rundir.CONFIG_FILE))
        reporting = Reporting(reporter, f"worker {os.getpid()}", f"seed {seed}")
        outcome = execute_run(
            path, plan, resume=resume, should_stop=handle.should_stop, reporting=reporting,
            plot=plot,
        )  # fmt: skip
        yield seed, outcome.result.interrupted


@dataclass(frozen=True)
class _TrainedSeed:
    """A seed trained by a Ray task: its result without the config, and its last checkpoint."""

    seed: int
    result: dict[str, Any]
    """the :class:`~cartpole_q.training.TrainResult` fields but ``config`` (a config holds
    read-only mappings, which do not pickle; the parent has it)"""
    checkpoint: bytes | None
    """the last ``checkpoint.npz`` the run wrote, as bytes"""


def _train_remotely(
    prepared: Plan,
    jobs: Sequence[tuple[int, Path, bool]],
    finished: list[int],
    workers: int,
    address: str | None,
    should_stop: Callable[[], bool] | None,
    reporter: Reporter,
    seed_plots: bool,
) -> None:
    """Train seeds as Ray tasks and write each finished seed's directory here."""
    config = prepared.config
    items = []
    for seed, child, child_resume in jobs:
        path = child / CHECKPOINT_FILE
        checkpoint = None
        if child_resume and path.is_file():
            # checked here, as a local worker checks it, before a task takes it anywhere
            check_resumable(child, load_checkpoint(child), config.for_seed(seed))
            checkpoint = path.read_bytes()
        if child_resume:
            # config.yaml says what the run now is; the run is unfinished until its summary
            rundir.write_config(child, config.for_seed(seed))
            (child / rundir.SUMMARY_FILE).unlink(missing_ok=True)
        items.append((seed, checkpoint))
    size = chunk_size(len(items), workers)
    chunks = [(config.to_dict(), items[i : i + size]) for i in range(0, len(items), size)]
    directories = {seed: child for seed, child, _ in jobs}

    def on_item(index: int, trained: _TrainedSeed) -> None:
        child = directories[trained.seed]
        result = TrainResult(config=config.for_seed(trained.seed), **trained.result)
        if trained.checkpoint is not None:
            atomic_write_bytes(child / CHECKPOINT_FILE, trained.checkpoint)
        summary = rundir.write_run(child, result, overwrite=True, plot=seed_plots)
        label = f"seed {trained.seed}"  # no bar: Ray tasks send no progress, only results
        reporter.finish(label, outcome_line(label, summary.result()))
        finished.append(trained.seed)

    execute(
        _train_seeds_in_memory, chunks, on_item,
        backend="ray", workers=workers, address=address, should_stop=should_stop,
    )  # fmt: skip


def _train_seeds_in_memory(
    handle: JobHandle, mapping: dict[str, Any], items: Sequence[tuple[int, bytes | None]]
) -> Iterator[_TrainedSeed]:
    """Job (Ray): train seeds of one config in memory, each from its checkpoint if it has one.

    Yields:
        Each seed as it finishes.
    """
    from cartpole_q.engines.plan import plan_run
    from cartpole_q.store.checkpoint import checkpoint_bytes, checkpoint_from_bytes
    from cartpole_q.training import train

    plan = plan_run(load_config(mapping))
    for seed, checkpoint in items:
        last: list[bytes] = []

        def keep(snapshot: Checkpoint, kept: list[bytes] = last) -> None:
            kept[:] = [checkpoint_bytes(snapshot)]

        resume = None if checkpoint is None else checkpoint_from_bytes(checkpoint, f"seed {seed}")
        result = train(plan.for_seed(seed), resume=resume, on_checkpoint=keep)
        fields = {
            field.name: getattr(result, field.name)
            for field in dataclasses.fields(result)
            if field.name != "config"
        }
        yield _TrainedSeed(seed, fields, last[0] if last else checkpoint)


def _finished(child: Path) -> bool:
    summary = rundir.read_summary(child)
    return summary is not None and not summary.interrupted


def aggregate(
    parent: Path, seeds: tuple[int, ...], wall_seconds: float, interrupted: bool
) -> MultiSeedSummary:
    """Summarise the seeds' runs: success rate, solve episodes and env steps, eval means.

    Every statistic (``success_rate`` included) is over the finished seeds (``finished`` of
    ``runs``); the others are counted in ``unfinished`` and named in ``interrupted_seeds``
    (stopped early, listed in ``per_seed`` too) and ``no_result_seeds`` (not started, or
    killed before writing a result), both in ``--seeds`` syntax. The ``statistics`` are a
    sweep point's, from the same function.
    """
    entries: dict[str, tuple[SeedEntry, SeedResult, str | None]] = {}
    for seed in seeds:
        child = seed_dir(parent, seed, seeds)
        summary = rundir.read_summary(child)
        if summary is not None:
            entry = SeedEntry.of(child.name, summary)
            entries[str(seed)] = (entry, summary.result(seed), summary.engine)
    return MultiSeedSummary.of_seeds(
        seeds=format_seeds(seeds),
        runs=len(seeds),
        entries=entries,
        wall_seconds=wall_seconds,
        interrupted=interrupted,
        versions=rundir.versions(),
        interrupted_seeds=format_seeds(
            [seed for seed in seeds if str(seed) in entries and entries[str(seed)][1].interrupted]
        ),
        no_result_seeds=format_seeds([seed for seed in seeds if str(seed) not in entries]),
    )
