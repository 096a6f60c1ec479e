"""Many seeds in one command: one contract run per seed, in parallel, and an aggregate.

The parent directory holds the config (with ``train.seeds``), one ``seed-NNN``
subdirectory per seed (each a complete single run whose ``config.yaml`` reproduces it
alone), and an aggregate ``summary.json`` written last. Seeds run in worker processes,
one per core; a seed's results do not depend on which worker ran it, or when.
"""

from __future__ import annotations

import dataclasses
import math
import multiprocessing
import os
import pickle
import signal
import sys
import threading
import time
import traceback
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager, suppress
from multiprocessing.connection import Connection
from multiprocessing.connection import wait as wait_connections
from multiprocessing.process import BaseProcess
from pathlib import Path
from typing import Any

import numpy as np

from cartpole_q.config import format_seeds, load_config
from cartpole_q.errors import RunError, UserError
from cartpole_q.experiments.run import Prepared, execute_run, prepare
from cartpole_q.progress import NullReporter, Reporter
from cartpole_q.store import rundir
from cartpole_q.store.atomic import write_json
from cartpole_q.training import Progress


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
    seed_plots: bool = False,
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

    interrupted = False
    if workers <= 1:
        for seed, child, child_resume in jobs:
            if should_stop is not None and should_stop():
                interrupted = True
                break
            outcome = execute_run(
                child, prepare(config.for_seed(seed), str(child / rundir.CONFIG_FILE)),
                resume=child_resume, should_stop=should_stop, reporter=reporter,
                key="run", label=f"seed {seed}", plot=seed_plots,
            )  # fmt: skip
            interrupted = interrupted or outcome.result.interrupted
    else:
        # Several seeds per job: a worker loads the config and the compiled loop once per
        # job, not once per seed; four jobs per worker keep the workers busy to the end.
        size = max(1, math.ceil(len(jobs) / (4 * workers)))
        items = [(str(child), seed, child_resume) for seed, child, child_resume in jobs]
        chunks = [(items[i : i + size], seed_plots) for i in range(0, len(items), size)]
        results = run_in_workers(
            _train_seeds, chunks, workers, reporter=reporter, should_stop=should_stop
        )
        interrupted = any(
            result is NOT_STARTED or len(result) < len(chunk[0]) or any(result)
            for result, chunk in zip(results, chunks, strict=True)
        )

    summary = aggregate(parent, seeds, time.perf_counter() - started, interrupted)
    if seed_plots:
        _plot_seeds(parent)
    write_json(parent / rundir.SUMMARY_FILE, summary)
    return summary


def _plot_seeds(parent: Path) -> None:
    """Draw the parent's ``reward_curve.png``: every finished seed's returns, with a band."""
    from cartpole_q.experiments.plots import plot_rewards

    with suppress(RunError):  # no seed has finished: there is nothing to draw
        plot_rewards([parent], parent / rundir.CURVE_FILE, force=True)


# -- worker processes: one helper for training and evaluating seeds ---------------------
#
# Workers ignore SIGINT and SIGTERM from their first instruction on (the parent blocks both
# while it spawns them, the child inherits the mask, sets them to SIG_IGN and only then
# unblocks them), so a signal to the whole process group reaches the parent alone, and the
# parent decides. Each worker talks to the parent through its own pipe: no queue, no feeder
# thread, no lock, nothing an exit handler could wait on. A worker whose parent dies is
# killed by the kernel on Linux (PR_SET_PDEATHSIG); elsewhere it stops when its pipe closes.

NOT_STARTED: Any = object()
"""The result of a job that never started because a stop was requested first."""

_STOP = "stop"
_JOIN_SECONDS = 5.0


class WorkerError(RuntimeError):
    """A worker process failed in a way that cannot be passed on as its own exception."""


def run_in_workers(
    function: Callable[..., Any],
    jobs: Sequence[tuple[Any, ...]],
    workers: int,
    *,
    reporter: Reporter | None = None,
    should_stop: Callable[[], bool] | None = None,
    on_result: Callable[[int, Any], None] | None = None,
) -> list[Any]:
    """Call ``function(worker, *job)`` for every job in spawned worker processes.

    Args:
        function: a module-level function, called as ``function(worker, *job)`` with the
            job's :class:`Worker` (to poll ``should_stop`` and report progress).
        jobs: the argument tuples, started in this order.
        workers: at most this many processes (never more than there are jobs).
        reporter: receives the workers' progress.
        should_stop: polled about ten times a second; once true, no job starts any more
            and the running ones are asked to stop (their results are still awaited).
        on_result: called in this process with each job's index and result as it
            arrives (e.g. to save finished work while the rest runs).

    Returns:
        The results in job order; :data:`NOT_STARTED` for the jobs a stop left out.

    Raises:
        KeyboardInterrupt: raised here (by a signal handler) while waiting: every worker
            is killed at once, then it propagates. A worker's exception propagates the
            same way after the other workers are killed.
    """
    reporter = reporter or NullReporter()
    results: list[Any] = [NOT_STARTED] * len(jobs)
    if not jobs:
        return results
    context: Any = multiprocessing.get_context(_start_method())
    if os.name == "posix":
        # Started lazily by the first worker, multiprocessing's resource tracker unblocks
        # SIGINT and SIGTERM once it runs; start it first so the block below holds.
        from multiprocessing import resource_tracker

        resource_tracker.ensure_running()
    processes: list[BaseProcess] = []
    conns: list[Connection] = []
    try:
        with _signals_blocked():
            for number in range(min(workers, len(jobs))):
                parent_end, child_end = context.Pipe()
                process = context.Process(
                    target=_worker_main, args=(child_end, os.getpid()),
                    name=f"cartpole-q worker {number}", daemon=True,
                )  # fmt: skip
                processes.append(process)
                conns.append(parent_end)
                process.start()
                child_end.close()
        _dispatch(function, jobs, conns, processes, results, reporter, should_stop, on_result)
    except BaseException:
        _end_workers(processes, conns, kill=True)
        raise
    _end_workers(processes, conns, kill=False)
    return results


def _start_method() -> str:
    """``fork`` where it is safe and cheap, else ``spawn``.

    A forked worker starts in milliseconds with everything this process has imported and
    compiled; a spawned one imports numpy, numba and gymnasium and loads the compiled
    loop again (about 1.5 s), which would dominate a quick multi-seed run. Forking is
    safe on Linux while this process has no other thread (a live progress bar has one;
    a thread holding a lock at the fork would leave that lock held in the child).
    """
    if sys.platform.startswith("linux") and threading.active_count() == 1:
        return "fork"
    return "spawn"


def _dispatch(
    function: Callable[..., Any],
    jobs: Sequence[tuple[Any, ...]],
    conns: list[Connection],
    processes: list[BaseProcess],
    results: list[Any],
    reporter: Reporter,
    should_stop: Callable[[], bool] | None,
    on_result: Callable[[int, Any], None] | None = None,
) -> None:
    """Hand out the jobs to idle workers and collect their messages until none is busy."""
    idle = list(range(len(conns)))
    busy: dict[int, int] = {}  # worker -> job
    arrived: list[int] = []  # finished jobs whose results on_result has not seen yet
    next_job = 0
    stopping = False
    while True:
        if not stopping and should_stop is not None and should_stop():
            stopping = True
            for worker in busy:
                _send(conns[worker], _STOP)
        while idle and not stopping and next_job < len(jobs):
            worker = idle.pop(0)
            conns[worker].send(("job", function, jobs[next_job]))
            busy[worker] = next_job
            next_job += 1
        # Only now, with every idle worker busy again, hand results on (saving them takes time).
        for job in arrived:
            if on_result is not None:
                on_result(job, results[job])
        arrived.clear()
        if not busy:
            return
        wait_connections([conns[worker] for worker in busy], timeout=0.1)
        for worker in list(busy):
            conn = conns[worker]
            while worker in busy and conn.poll():
                try:
                    kind, *payload = conn.recv()
                except (EOFError, OSError):
                    processes[worker].join(_JOIN_SECONDS)
                    raise WorkerError(
                        f"a worker process ended unexpectedly (exit code "
                        f"{processes[worker].exitcode}) while it ran {jobs[busy[worker]]!r}."
                    ) from None
                if kind == "result":
                    job = busy.pop(worker)
                    results[job] = payload[0]
                    idle.append(worker)
                    arrived.append(job)
                elif kind == "error":
                    raise _worker_exception(*payload)
                elif kind == "start":
                    reporter.start(*payload)
                elif kind == "update":
                    key, *fields = payload
                    reporter.update(key, Progress(*fields))
                else:
                    reporter.finish(*payload)


def _send(conn: Connection, message: Any) -> None:
    with suppress(OSError):  # the other end is gone; reading the pipe says so
        conn.send(message)


def _worker_exception(pickled: bytes | None, text: str) -> BaseException:
    """The worker's exception as the worker raised it (else a ``WorkerError`` with its text)."""
    if pickled is not None:
        try:
            error = pickle.loads(pickled)
        except Exception:  # any failure to rebuild it: fall back to the text
            error = None
        if isinstance(error, BaseException):
            if not isinstance(error, UserError):
                error.__cause__ = WorkerError(f"in a worker process:\n{text}")
            return error
    return WorkerError(f"in a worker process:\n{text}")


def _end_workers(processes: list[BaseProcess], conns: list[Connection], *, kill: bool) -> None:
    """End every worker: politely after a normal end, at once (SIGKILL) otherwise.

    Further SIGINT and SIGTERM are ignored meanwhile (this takes milliseconds), so a third
    Ctrl-C cannot break the clean-up half-way and leave processes behind.
    """
    with _signals_ignored():
        for process, conn in zip(processes, conns, strict=False):
            if kill:
                if process.pid is not None and process.exitcode is None:
                    process.kill()
            else:
                _send(conn, None)
        deadline = time.monotonic() + _JOIN_SECONDS
        for process in processes:
            if process.pid is None:
                continue  # never started
            process.join(max(0.0, deadline - time.monotonic()))
            if process.exitcode is None:
                process.kill()
                process.join(_JOIN_SECONDS)
        for conn in conns:
            conn.close()


@contextmanager
def _signals_blocked() -> Iterator[None]:
    """Hold SIGINT and SIGTERM back in this thread; the processes it spawns inherit the mask."""
    if not hasattr(signal, "pthread_sigmask"):
        yield
        return
    previous = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT, signal.SIGTERM})
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, previous)


@contextmanager
def _signals_ignored() -> Iterator[None]:
    """Ignore SIGINT and SIGTERM (main thread only; elsewhere handlers cannot change)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = {signum: signal.signal(signum, signal.SIG_IGN) for signum in _SIGNALS}
    try:
        yield
    finally:
        for signum, handler in previous.items():
            signal.signal(signum, handler)


_SIGNALS = (signal.SIGINT, signal.SIGTERM)


def _worker_main(conn: Connection, parent_pid: int) -> None:
    """A worker's life: ignore signals, die with the parent, run jobs until told to end."""
    for signum in _SIGNALS:
        signal.signal(signum, signal.SIG_IGN)  # also discards one that arrived while blocked
    if hasattr(signal, "pthread_sigmask"):
        signal.pthread_sigmask(signal.SIG_UNBLOCK, set(_SIGNALS))
    _die_with_parent(parent_pid)
    while True:
        try:
            message = conn.recv()
        except (EOFError, OSError):
            return  # the parent is gone
        if message is None:
            return
        if message == _STOP:
            continue  # the job it was meant for has already ended
        _, function, args = message
        try:
            value = function(Worker(conn), *args)
        except BaseException as error:  # every failure goes to the parent
            text = traceback.format_exc()
            try:
                pickled: bytes | None = pickle.dumps(error)
            except Exception:  # it cannot travel as itself
                pickled = None
            reply: tuple[Any, ...] = ("error", pickled, text)
        else:
            reply = ("result", value)
        try:
            conn.send(reply)
        except OSError:
            return


def _die_with_parent(parent_pid: int) -> None:
    """On Linux, ask the kernel to SIGKILL this process when its parent dies."""
    if not sys.platform.startswith("linux"):
        return
    try:
        import ctypes

        ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGKILL, 0, 0, 0)  # PR_SET_PDEATHSIG
    except (OSError, AttributeError):
        return
    if os.getppid() != parent_pid:
        os._exit(1)  # the parent died before the request took effect


class Worker:
    """A job's link to the parent process: stop requests in, progress out."""

    def __init__(self, conn: Connection) -> None:
        self._conn = conn
        self._stopped = False

    def should_stop(self) -> bool:
        """Whether the parent asked this job to stop (or is gone)."""
        if not self._stopped:
            try:
                while self._conn.poll():
                    if self._conn.recv() in (_STOP, None):
                        self._stopped = True
            except (EOFError, OSError):
                self._stopped = True  # the parent is gone
        return self._stopped

    def reporter(self) -> Reporter:
        """A reporter whose messages reach the parent's."""
        return _PipeReporter(self._conn)


class _PipeReporter:
    """Forwards a worker's progress to the parent process (throttled)."""

    def __init__(self, conn: Connection, min_interval: float = 0.2) -> None:
        self._conn = conn
        self._min_interval = min_interval
        self._last = 0.0
        self._unsent: Progress | None = None

    def start(self, key: Any, label: str, episodes: int) -> None:
        _send(self._conn, ("start", key, label, episodes))

    def update(self, key: Any, progress: Progress) -> None:
        now = time.monotonic()
        self._unsent = progress
        if now - self._last >= self._min_interval:
            self._last = now
            self._send_update(key)

    def _send_update(self, key: Any) -> None:
        if self._unsent is not None:
            _send(self._conn, ("update", key, *dataclasses.astuple(self._unsent)))
            self._unsent = None

    def finish(self, key: Any, line: str) -> None:
        # the last update may have been throttled: the bar must end on the real count
        self._send_update(key)
        _send(self._conn, ("finish", key, line))

    def close(self) -> None:
        """Nothing to close."""


def _train_seeds(worker: Worker, items: Sequence[tuple[str, int, bool]], plot: bool) -> list[bool]:
    """Worker job: train seeds into their directories, one after another.

    Each item is (seed directory, seed, resume). The seeds share one config but their
    seed, so it is checked against its environment once.

    Returns:
        Whether each started seed was interrupted; seeds a stop left out have no entry.
    """
    interrupted: list[bool] = []
    env_info = None
    reporter = worker.reporter()
    for child, seed, resume in items:
        if worker.should_stop():
            break
        path = Path(child)
        config = load_config(path / rundir.CONFIG_FILE)
        if env_info is None:
            prepared = prepare(config, str(path / rundir.CONFIG_FILE))
            env_info = prepared.env_info
        else:
            prepared = dataclasses.replace(prepared, config=config)
        outcome = execute_run(
            path, prepared, resume=resume, should_stop=worker.should_stop, reporter=reporter,
            key=f"worker {os.getpid()}", label=f"seed {seed}", plot=plot,
        )  # fmt: skip
        interrupted.append(outcome.result.interrupted)
    return interrupted


def _finished(child: Path) -> bool:
    summary = rundir.read_summary(child)
    return summary is not None and not summary.get("interrupted", True)


def _spread(values: list[float]) -> dict[str, float] | None:
    if not values:
        return None
    q25, median, q75 = np.percentile(values, [25, 50, 75])
    return {"median": float(median), "q25": float(q25), "q75": float(q75)}


def aggregate(
    parent: Path, seeds: tuple[int, ...], wall_seconds: float, interrupted: bool
) -> dict[str, Any]:
    """Summarise the seeds' runs: success rate, solve episodes and env steps, eval means.

    Every statistic (``success_rate`` included) is over the finished seeds (``finished`` of
    ``runs``); the others are counted in ``unfinished`` and named in ``interrupted_seeds``
    (stopped early, listed in ``per_seed`` too) and ``no_result_seeds`` (not started, or
    killed before writing a result), both in ``--seeds`` syntax.
    """
    per_seed: dict[str, dict[str, Any]] = {}
    threshold = None
    engine = None
    for seed in seeds:
        child = seed_dir(parent, seed, seeds)
        summary = rundir.read_summary(child)
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
    interrupted_seeds = [seed for seed in seeds if per_seed.get(str(seed), {}).get("interrupted")]
    no_result = [seed for seed in seeds if str(seed) not in per_seed]
    return {
        "seeds": format_seeds(seeds),
        "runs": len(seeds),
        "finished": len(finished),
        "unfinished": len(seeds) - len(finished),
        "interrupted_seeds": format_seeds(interrupted_seeds),
        "no_result_seeds": format_seeds(no_result),
        "interrupted": interrupted or len(finished) < len(seeds),
        "engine": engine,
        "reward_threshold": threshold,
        "successes": successes,
        "success_rate": successes / len(finished) if finished else None,
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
    """Load every seed run of a multi-seed parent directory that has a result.

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
        raise RunError(f"{parent}: none of its seed runs has finished.")
    return runs


@dataclasses.dataclass(frozen=True)
class SeedStatus:
    """Which seeds of a multi-seed run have finished, and why the others have not."""

    finished: list[tuple[int, Path]]
    missing: list[tuple[int, Path]]  # no directory
    unfinished: list[tuple[int, Path]]  # not started, interrupted or killed

    def note(self, parent: Path) -> str | None:
        """One line naming the seeds left out, or None when every seed finished."""
        if not self.missing and not self.unfinished:
            return None
        total = len(self.finished) + len(self.missing) + len(self.unfinished)
        parts = []
        if self.missing:
            parts.append(
                f"{_names(self.missing)} {'is' if len(self.missing) == 1 else 'are'} missing"
            )
        if self.unfinished:
            verb = "has" if len(self.unfinished) == 1 else "have"
            parts.append(f"{_names(self.unfinished)} {verb} not finished")
        return (
            f"{parent}: {len(self.missing) + len(self.unfinished)} of {total} seeds not evaluated: "
            f"{'; '.join(parts)} (finish them with `cartpole-q train --resume {parent}`)"
        )


def _names(items: list[tuple[int, Path]], limit: int = 8) -> str:
    names = [path.name for _, path in items]
    shown = ", ".join(names[:limit])
    return shown if len(names) <= limit else f"{shown} and {len(names) - limit} more"


def seed_status(parent: Path) -> SeedStatus:
    """Sort the seeds of a multi-seed run into finished, missing and unfinished."""
    config = load_config(parent / rundir.CONFIG_FILE)
    seeds = config.train.seeds
    assert seeds is not None
    status = SeedStatus([], [], [])
    for seed in seeds:
        child = seed_dir(parent, seed, seeds)
        if not child.is_dir():
            status.missing.append((seed, child))
        elif _finished(child):
            status.finished.append((seed, child))
        else:
            status.unfinished.append((seed, child))
    return status


def _evaluate_one(
    worker: Worker | None,
    path: str,
    episodes: int | None,
    seed: int | None,
    physics: dict[str, Any] | None = None,
    max_steps: int | None = None,
) -> dict[str, Any]:
    from cartpole_q.evaluation import evaluate, exact_report, under_conditions

    run = rundir.load_run(path)
    config = under_conditions(run.config, physics, max_steps)
    report = evaluate(run.q_table, config, episodes=episodes, seed=seed)
    result = {"run_seed": run.config.seed, "path": run.path.name, **report.to_dict()}
    exact = exact_report(config, run.q_table)
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
    parent: Path,
    *,
    episodes: int | None = None,
    seed: int | None = None,
    workers: int | None = None,
    physics: dict[str, Any] | None = None,
    max_steps: int | None = None,
) -> dict[str, Any]:
    """Evaluate every finished seed of a multi-seed run in ``gymnasium.make``, in parallel.

    ``physics`` and ``max_steps`` play under other conditions (see ``under_conditions``).

    Returns:
        ``runs`` (one ``eval --json`` object per finished seed, with ``run_seed`` and
        ``path``), ``successes`` (means at or above the threshold), ``reward_threshold``,
        ``episodes``, the ``mean`` and ``min`` of the seeds' means, ``seeds`` (how many
        the run has), the seed directories left out (``missing``: absent, ``unfinished``:
        interrupted or not started) and ``note``, a line naming them (None if none).

    Raises:
        RunError: a finished seed's directory is damaged, or no seed has finished.
    """
    status = seed_status(parent)
    if not status.finished:
        raise RunError(f"{parent}: none of its seed runs has finished; {status.note(parent)}")
    paths = [str(path) for _, path in status.finished]
    # Loading every seed first refuses a damaged one before any work starts.
    for path in paths:
        rundir.load_run(path)
    workers = workers or default_workers(len(paths))
    jobs = [(path, episodes, seed, physics, max_steps) for path in paths]
    if workers <= 1:
        results = [_evaluate_one(None, *job) for job in jobs]
    else:
        results = run_in_workers(_evaluate_one, jobs, workers)
    from cartpole_q.envs.gym import inspect_env
    from cartpole_q.evaluation import under_conditions

    first = rundir.load_run(paths[0])
    reward_threshold = first.summary.get("reward_threshold")
    if physics or max_steps is not None:  # the horizon may scale CartPole's threshold
        conditions = under_conditions(first.config, physics, max_steps)
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
        "seeds": len(status.finished) + len(status.missing) + len(status.unfinished),
        "missing": [path.name for _, path in status.missing],
        "unfinished": [path.name for _, path in status.unfinished],
        "note": status.note(parent),
    }
