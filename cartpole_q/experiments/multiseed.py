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
from pathlib import Path
from typing import Any

import numpy as np

from cartpole_q.config import format_seeds, load_config
from cartpole_q.errors import RunError
from cartpole_q.experiments.run import Prepared, execute_run, prepare
from cartpole_q.experiments.workers import (
    JobHandle,
    chunk_size,
    default_workers,
    execute,
    map_jobs,
)
from cartpole_q.progress import NullReporter, Reporter
from cartpole_q.results import MultiSeedSummary, SeedEntry, SeedResult
from cartpole_q.store import rundir
from cartpole_q.store.atomic import write_json
from cartpole_q.store.runsets import RunSet, seed_dir


def run_seeds(
    prepared: Prepared,
    parent: Path,
    *,
    workers: int,
    reporter: Reporter | None = None,
    should_stop: Callable[[], bool] | None = None,
    resume: bool = False,
    seed_plots: bool = False,
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
            child.mkdir(parents=True, exist_ok=True)
            rundir.write_config(child, config.for_seed(seed))
        jobs.append((seed, child, child_resume))

    finished: list[int] = []

    def on_item(index: int, item: tuple[int, bool]) -> None:
        seed, interrupted = item
        if not interrupted:
            finished.append(seed)

    # Several seeds per job: a worker loads the config and the compiled loop once per
    # job, not once per seed.
    items = [(str(child), seed, child_resume) for seed, child, child_resume in jobs]
    size = chunk_size(len(items), workers)
    chunks = [(items[i : i + size], seed_plots) for i in range(0, len(items), size)]
    execute(
        _train_seeds, chunks, on_item, workers=workers, should_stop=should_stop, reporter=reporter
    )
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
    env_info = None
    reporter = handle.reporter()
    for child, seed, resume in items:
        if handle.should_stop():
            return
        path = Path(child)
        config = load_config(path / rundir.CONFIG_FILE)
        if env_info is None:
            prepared = prepare(config, str(path / rundir.CONFIG_FILE))
            env_info = prepared.env_info
        else:
            prepared = dataclasses.replace(prepared, config=config)
        outcome = execute_run(
            path, prepared, resume=resume, should_stop=handle.should_stop, reporter=reporter,
            key=f"worker {os.getpid()}", label=f"seed {seed}", plot=plot,
        )  # fmt: skip
        yield seed, outcome.result.interrupted


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


def _evaluate_one(
    handle: JobHandle | None,
    name: str,
    config_mapping: dict[str, Any],
    q_table: np.ndarray,
    episodes: int | None,
    seed: int | None,
    physics: dict[str, Any] | None = None,
    max_steps: int | None = None,
) -> dict[str, Any]:
    """Job: one seed's greedy evaluation in ``gymnasium.make`` (and its exact figures)."""
    from cartpole_q.evaluation import evaluate, exact_report, under_conditions

    trained = load_config(config_mapping)
    config = under_conditions(trained, physics, max_steps)
    report = evaluate(q_table, config, episodes=episodes, seed=seed)
    result = {"run_seed": trained.seed, "path": name, **report.to_dict()}
    exact = exact_report(config, q_table)
    if not isinstance(exact, str):
        result["exact"] = exact.to_dict()
    return result


def exact_summary(results: list[dict[str, Any]]) -> dict[str, Any] | None:
    """The seeds' exact greedy returns against the optimum (``None`` without a model).

    ``within_0.01`` counts the seeds whose gap is at most 0.01, ``within_1%`` those within
    1% of the optimum's magnitude (both as the issue's acceptance states them).
    """
    exact = [result["exact"] for result in results if "exact" in result]
    if not exact:
        return None
    optimum = exact[0]["optimum"]["return"]
    greedy = np.array([item["greedy"]["return"] for item in exact])
    gaps = optimum - greedy
    tolerance = 1e-9 * max(1.0, abs(optimum))  # the same value, up to rounding
    return {
        "note": exact[0]["note"],
        "optimum": optimum,
        "greedy_median": float(np.median(greedy)),
        "greedy_min": float(np.min(greedy)),
        "gap_max": float(np.max(gaps)),
        "within_0.01": int(np.sum(gaps <= 0.01 + tolerance)),
        "within_1%": int(np.sum(gaps <= 0.01 * abs(optimum) + tolerance)),
        "optimal": int(np.sum(gaps <= tolerance)),
        "seeds": len(exact),
    }


def evaluate_seeds(
    run_set: RunSet,
    *,
    episodes: int | None = None,
    seed: int | None = None,
    workers: int | None = None,
    physics: dict[str, Any] | None = None,
    max_steps: int | None = None,
) -> dict[str, Any]:
    """Evaluate every finished seed of a multi-seed run or sweep point, in parallel.

    ``physics`` and ``max_steps`` play under other conditions (see ``under_conditions``).

    Returns:
        ``runs`` (one ``eval --json`` object per finished seed, with ``run_seed`` and
        ``path``), ``successes`` (means at or above the threshold), ``reward_threshold``,
        ``episodes``, the ``mean`` and ``min`` of the seeds' means, ``seeds`` (how many
        the run has), ``missing`` and ``unfinished`` (seeds left out), ``conditions`` (the physics and time limit played under, when changed),
        ``notes`` (what was left out or is unfinished) and ``note`` (them as one line, or
        None).
    """
    from cartpole_q.envs.gym import inspect_env
    from cartpole_q.evaluation import under_conditions

    runs = run_set.runs
    workers = workers or default_workers(len(runs))
    jobs = [
        (run.path.name, run.config.to_dict(), run.q_table, episodes, seed, physics, max_steps)
        for run in runs
    ]
    results = map_jobs(_evaluate_one, jobs, workers)
    reward_threshold = run_set.reward_threshold
    if physics or max_steps is not None:  # the horizon may scale CartPole's threshold
        conditions = under_conditions(run_set.config, physics, max_steps)
        reward_threshold = inspect_env(conditions).reward_threshold
    means = [result["mean"] for result in results]
    exact = exact_summary(results)
    return {
        **({"exact": exact} if exact else {}),
        "runs": results,
        "successes": sum(
            1 for m in means if reward_threshold is not None and m >= reward_threshold
        ),
        "reward_threshold": reward_threshold,
        "episodes": results[0]["episodes"],
        "mean": float(np.mean(means)),
        "min": float(np.min(means)),
        "seeds": run_set.seeds,
        "missing": list(run_set.missing),
        "unfinished": list(run_set.unfinished),
        "conditions": conditions_of(physics, max_steps),
        "notes": list(run_set.notes),
        "note": " ".join(run_set.notes) or None,
    }


def conditions_of(physics: dict[str, Any] | None, max_steps: int | None) -> dict[str, Any]:
    """The changed conditions an evaluation played under, as ``eval --json`` echoes them.

    >>> conditions_of({"length": 0.75}, None), conditions_of(None, None)
    ({'physics': {'length': 0.75}}, {})
    """
    conditions: dict[str, Any] = {}
    if physics:
        conditions["physics"] = dict(physics)
    if max_steps is not None:
        conditions["max_steps"] = max_steps
    return conditions
