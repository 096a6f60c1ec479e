"""Many seeds in one command: one contract run per seed, in parallel, and an aggregate.

The parent directory holds the config (with ``train.seeds``), one ``seed-NNN``
subdirectory per seed (each a complete single run whose ``config.yaml`` reproduces it
alone), and an aggregate ``summary.json`` written last. Seeds run in worker processes,
one per core; a seed's results do not depend on which worker ran it, or when.
"""

from __future__ import annotations

import dataclasses
import json
import multiprocessing
import os
import queue as queue_module
import signal
import time
from collections.abc import Callable
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from pathlib import Path
from typing import Any

import numpy as np

from cartpole_q import rundir
from cartpole_q.config import format_seeds, load_config
from cartpole_q.progress import NullReporter, Reporter
from cartpole_q.runner import Prepared, execute_run, prepare
from cartpole_q.training import Progress

_worker_stop: Any = None
_worker_queue: Any = None


def seed_dir(parent: Path, seed: int, seeds: tuple[int, ...]) -> Path:
    """The subdirectory of one seed: ``seed-007`` when the largest seed has up to 3 digits."""
    width = max(3, len(str(max(seeds))))
    return parent / f"seed-{seed:0{width}d}"


def default_workers(n_seeds: int) -> int:
    """One worker per core, never more than there are seeds."""
    return max(1, min(os.cpu_count() or 1, n_seeds))


def run_seeds(
    prepared: Prepared,
    parent: Path,
    *,
    workers: int,
    reporter: Reporter | None = None,
    should_stop: Callable[[], bool] | None = None,
    resume: bool = False,
) -> dict[str, Any]:
    """Train every seed of ``prepared.config`` under ``parent`` and write the aggregate.

    Args:
        prepared: the checked multi-seed config.
        parent: the parent run directory, holding the multi-seed ``config.yaml``.
        workers: worker processes; 1 trains in this process, one seed after another.
        reporter: receives each worker's progress and each seed's outcome.
        should_stop: polled while waiting; when true, workers stop at the end of their
            current episode and unstarted seeds are left for ``--resume``.
        resume: keep finished seeds, resume interrupted ones, start the rest.

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

    interrupted = False
    if workers <= 1:
        for seed, child, child_resume in jobs:
            if should_stop is not None and should_stop():
                interrupted = True
                break
            outcome = execute_run(
                child, prepare(config.for_seed(seed), str(child / rundir.CONFIG_FILE)),
                resume=child_resume, should_stop=should_stop, reporter=reporter,
                key="run", label=f"seed {seed}",
            )  # fmt: skip
            interrupted = interrupted or outcome.result.interrupted
    else:
        interrupted = _run_pool(jobs, workers, reporter, should_stop)

    summary = aggregate(parent, seeds, time.perf_counter() - started, interrupted)
    rundir.write_json(parent / rundir.SUMMARY_FILE, summary)
    return summary


def _run_pool(
    jobs: list[tuple[int, Path, bool]],
    workers: int,
    reporter: Reporter,
    should_stop: Callable[[], bool] | None,
) -> bool:
    """Run the jobs in spawned worker processes; return whether training was interrupted."""
    context = multiprocessing.get_context("spawn")
    stop_event = context.Event()
    messages = context.Queue()
    interrupted = False
    with ProcessPoolExecutor(
        max_workers=workers, mp_context=context, initializer=_init_worker,
        initargs=(stop_event, messages),
    ) as pool:  # fmt: skip
        pending: set[Future[Any]] = {
            pool.submit(_train_seed, str(child), seed, child_resume)
            for seed, child, child_resume in jobs
        }
        try:
            while pending:
                done, pending = wait(pending, timeout=0.1, return_when=FIRST_COMPLETED)
                _relay(messages, reporter)
                for future in done:
                    interrupted = interrupted or bool(future.result())
                if should_stop is not None and should_stop() and not stop_event.is_set():
                    stop_event.set()
                    for future in pending:
                        future.cancel()
                    interrupted = True
        finally:
            stop_event.set()
            for future in pending:
                future.cancel()
        _relay(messages, reporter)
    _relay(messages, reporter)
    return interrupted


def _relay(messages: Any, reporter: Reporter) -> None:
    """Pass the workers' queued progress messages on to the reporter."""
    while True:
        try:
            kind, key, *payload = messages.get_nowait()
        except queue_module.Empty:
            return
        if kind == "start":
            reporter.start(key, *payload)
        elif kind == "update":
            reporter.update(key, Progress(*payload))
        else:
            reporter.finish(key, *payload)


def _init_worker(stop_event: Any, messages: Any) -> None:
    """Worker set-up: the parent decides when to stop, so Ctrl-C is ignored here."""
    global _worker_stop, _worker_queue
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    _worker_stop, _worker_queue = stop_event, messages


class _QueueReporter:
    """Forwards a worker's progress to the parent process (throttled)."""

    def __init__(self, messages: Any, min_interval: float = 0.2) -> None:
        self._messages = messages
        self._min_interval = min_interval
        self._last = 0.0

    def start(self, key: Any, label: str, episodes: int) -> None:
        self._messages.put(("start", key, label, episodes))

    def update(self, key: Any, progress: Progress) -> None:
        now = time.monotonic()
        if now - self._last >= self._min_interval:
            self._last = now
            self._messages.put(("update", key, *dataclasses.astuple(progress)))

    def finish(self, key: Any, line: str) -> None:
        self._messages.put(("finish", key, line))

    def close(self) -> None:
        """Nothing to close."""


def _train_seed(child: str, seed: int, resume: bool) -> bool:
    """Worker task: train one seed into its directory; return whether it was interrupted."""
    if _worker_stop is not None and _worker_stop.is_set():
        return True
    path = Path(child)
    prepared = prepare(load_config(path / rundir.CONFIG_FILE), str(path / rundir.CONFIG_FILE))
    outcome = execute_run(
        path, prepared, resume=resume,
        should_stop=None if _worker_stop is None else _worker_stop.is_set,
        reporter=_QueueReporter(_worker_queue) if _worker_queue is not None else None,
        key=f"worker {os.getpid()}", label=f"seed {seed}",
    )  # fmt: skip
    return outcome.result.interrupted


def _finished(child: Path) -> bool:
    summary = _read_json(child / rundir.SUMMARY_FILE)
    return summary is not None and not summary.get("interrupted", True)


def _read_json(path: Path) -> dict[str, Any] | None:
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    return data if isinstance(data, dict) else None


def _spread(values: list[float]) -> dict[str, float] | None:
    if not values:
        return None
    q25, median, q75 = np.percentile(values, [25, 50, 75])
    return {"median": float(median), "q25": float(q25), "q75": float(q75)}


def aggregate(
    parent: Path, seeds: tuple[int, ...], wall_seconds: float, interrupted: bool
) -> dict[str, Any]:
    """Summarise the seeds' runs: success rate, solve episodes and env steps, eval means."""
    per_seed: dict[str, dict[str, Any]] = {}
    threshold = None
    engine = None
    for seed in seeds:
        child = seed_dir(parent, seed, seeds)
        summary = _read_json(child / rundir.SUMMARY_FILE)
        if summary is None:
            continue
        threshold = summary.get("reward_threshold", threshold)
        engine = summary.get("engine", engine)
        per_seed[str(seed)] = {
            "path": child.name,
            "solved_episode": summary.get("solved_episode"),
            "env_steps_to_solve": summary.get("env_steps_to_solve"),
            "eval_mean": (summary.get("eval") or {}).get("mean"),
            "first_greedy_success": summary.get("first_greedy_success"),
            "episodes": summary.get("episodes"),
            "interrupted": summary.get("interrupted", False),
        }
    finished = [run for run in per_seed.values() if not run["interrupted"]]
    eval_means = [run["eval_mean"] for run in finished if run["eval_mean"] is not None]
    successes = sum(1 for mean in eval_means if threshold is not None and mean >= threshold)
    solved = [run["solved_episode"] for run in finished if run["solved_episode"] is not None]
    steps = [run["env_steps_to_solve"] for run in finished if run["env_steps_to_solve"] is not None]
    greedy = [
        run["first_greedy_success"]["env_steps"] for run in finished if run["first_greedy_success"]
    ]
    return {
        "seeds": format_seeds(seeds),
        "runs": len(seeds),
        "finished": len(finished),
        "interrupted": interrupted or len(finished) < len(seeds),
        "engine": engine,
        "reward_threshold": threshold,
        "successes": successes,
        "success_rate": successes / len(seeds),
        "solved_runs": len(solved),
        "solved_episode": _spread(solved),
        "env_steps_to_solve": _spread(steps),
        "first_greedy_success_env_steps": _spread(greedy),
        "eval_mean": (
            None
            if not eval_means
            else {
                "mean": float(np.mean(eval_means)),
                "min": float(np.min(eval_means)),
                "median": float(np.median(eval_means)),
            }
        ),
        "wall_seconds": round(wall_seconds, 3),
        "per_seed": per_seed,
        "versions": rundir.versions(),
    }


def load_seed_runs(parent: Path) -> list[rundir.Run]:
    """Load every finished seed run of a multi-seed parent directory.

    Raises:
        RunError: no seed run of ``parent`` is complete.
    """
    config = load_config(parent / rundir.CONFIG_FILE)
    seeds = config.train.seeds
    assert seeds is not None
    runs = [
        rundir.load_run(seed_dir(parent, seed, seeds))
        for seed in seeds
        if (seed_dir(parent, seed, seeds) / rundir.SUMMARY_FILE).is_file()
    ]
    if not runs:
        raise rundir.RunError(f"{parent}: none of its seed runs has finished.")
    return runs


def _evaluate_one(path: str, episodes: int | None, seed: int | None) -> dict[str, Any]:
    from cartpole_q.evaluation import evaluate

    run = rundir.load_run(path)
    report = evaluate(run.q_table, run.config, episodes=episodes, seed=seed)
    return {"run_seed": run.config.seed, "path": run.path.name, **report.to_dict()}


def evaluate_seeds(
    parent: Path,
    *,
    episodes: int | None = None,
    seed: int | None = None,
    workers: int | None = None,
) -> dict[str, Any]:
    """Evaluate every finished seed of a multi-seed run in ``gymnasium.make``, in parallel.

    Returns:
        ``runs`` (one ``eval --json`` object per seed, with ``run_seed`` and ``path``),
        ``successes`` (means at or above the threshold), ``reward_threshold``,
        ``episodes``, and the ``mean`` and ``min`` of the seeds' means.

    Raises:
        RunError: a seed directory is damaged, or none has finished.
    """
    paths = [str(run.path) for run in load_seed_runs(parent)]
    workers = workers or default_workers(len(paths))
    if workers <= 1:
        results = [_evaluate_one(path, episodes, seed) for path in paths]
    else:
        context = multiprocessing.get_context("spawn")
        with ProcessPoolExecutor(max_workers=workers, mp_context=context) as pool:
            results = list(
                pool.map(_evaluate_one, paths, [episodes] * len(paths), [seed] * len(paths))
            )
    threshold = _read_json(Path(paths[0]) / rundir.SUMMARY_FILE) or {}
    reward_threshold = threshold.get("reward_threshold")
    means = [result["mean"] for result in results]
    return {
        "runs": results,
        "successes": sum(
            1 for m in means if reward_threshold is not None and m >= reward_threshold
        ),
        "reward_threshold": reward_threshold,
        "episodes": results[0]["episodes"],
        "mean": float(np.mean(means)),
        "min": float(np.min(means)),
    }
