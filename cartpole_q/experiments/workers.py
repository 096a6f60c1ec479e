"""Where many jobs run: this process, local worker processes, or a Ray cluster.

A job is ``function(handle, *args)``, a module-level function given a :class:`JobHandle`:
``handle.should_stop()`` says whether the job should end early (keeping what it finished),
``handle.reporter()`` forwards its progress to the command's display. A job may be a
generator: each item it yields reaches the caller as soon as it exists (a sweep saves every
finished run within about a second, whatever the size of the job); a plain job's return
value is its one item. Items reach ``on_item(job_index, item)`` in this process, in
whatever order the jobs finish; callers must not depend on that order.

Local workers ignore SIGINT and SIGTERM from their first instruction on (the parent blocks
both while it starts them, the child inherits the mask, sets them to SIG_IGN and only then
unblocks them), so a signal to the whole process group reaches the parent alone, and the
parent decides. Each worker talks to the parent through its own pipe: no queue, no feeder
thread, no lock, nothing an exit handler could wait on. A worker whose parent dies is
killed by the kernel on Linux (PR_SET_PDEATHSIG); elsewhere it stops when its pipe closes.
Ray is imported only when ``backend="ray"`` is asked for, so the base install needs none.
"""

from __future__ import annotations

import dataclasses
import inspect
import math
import multiprocessing
import os
import pickle
import signal
import socket
import sys
import threading
import time
import traceback
from collections.abc import Callable, Hashable, Iterator, Sequence
from contextlib import contextmanager, suppress
from multiprocessing.connection import Connection
from multiprocessing.connection import wait as wait_connections
from multiprocessing.process import BaseProcess
from typing import Any, Protocol

from cartpole_q.errors import ConfigError, UserError
from cartpole_q.processes import STOP_SIGNALS, leave_signals_to_parent
from cartpole_q.progress import NullReporter, Reporter
from cartpole_q.training import Progress

BACKENDS = ("local", "ray")
"""the ``--backend`` values"""
TASKS_PER_WORKER = 4
"""split work into at least this many jobs per worker, so that all workers finish together"""


class JobHandle(Protocol):
    """What a job sees of the process that runs it."""

    def should_stop(self) -> bool:
        """Whether the job should end now, keeping what it finished."""
        ...

    def reporter(self) -> Reporter:
        """Where the job's progress goes."""
        ...


def default_workers(n_jobs: int) -> int:
    """One worker per core, never more than there are jobs (at least one)."""
    return max(1, min(os.cpu_count() or 1, n_jobs))


def chunk_size(n_items: int, workers: int, most: int | None = None) -> int:
    """Items per job: about :data:`TASKS_PER_WORKER` jobs per worker, at most ``most`` items.

    >>> chunk_size(100, 2), chunk_size(100, 2, most=5), chunk_size(3, 8)
    (13, 5, 1)
    """
    size = max(1, math.ceil(n_items / (TASKS_PER_WORKER * max(1, workers))))
    return size if most is None else max(1, min(most, size))


def items_of(value: Any) -> Iterator[Any]:
    """The items of a job's outcome: a generator's items, or the one value returned."""
    if inspect.isgenerator(value):
        yield from value
    else:
        yield value


def execute(
    function: Callable[..., Any],
    jobs: Sequence[tuple[Any, ...]],
    on_item: Callable[[int, Any], None],
    *,
    backend: str = "local",
    workers: int = 1,
    address: str | None = None,
    should_stop: Callable[[], bool] | None = None,
    reporter: Reporter | None = None,
    abandon: bool = False,
) -> bool:
    """Run every job, handing each item to ``on_item(job_index, item)`` as it arrives.

    Args:
        function: a module-level function ``function(handle, *job)``, plain or a generator.
        jobs: the argument tuples, started in this order.
        on_item: called in this process for each item (each finished job's result).
        backend: ``local`` (this process when ``workers`` is 1, else worker processes)
            or ``ray``.
        workers: local worker processes; with Ray, the CPUs of a local cluster started
            here (ignored with ``address``).
        address: a running Ray cluster's address (``auto`` or ``HOST:PORT``); without
            it, a local Ray cluster is started for this call and stopped after it.
        should_stop: polled about ten times a second; once true no job starts any more
            and running local jobs are asked to stop (Ray jobs are cancelled).
        reporter: receives the jobs' progress.
        abandon: for jobs whose unfinished work is worth nothing (compiling a loop): once
            ``should_stop`` is true, running local jobs are killed at once instead of asked
            to stop, and they run in worker processes even with one worker, so that this
            process answers a stop within a tenth of a second. Items already made are
            handed on first.

    Returns:
        Whether every job started and no stop was requested.

    Raises:
        KeyboardInterrupt: raised here (by a signal handler) while waiting: every worker is
            killed at once, then it propagates. A job's exception propagates the same way.
    """
    reporter = reporter or NullReporter()
    if backend == "ray":
        return _execute_ray(function, jobs, on_item, workers, address, should_stop)
    if workers <= 1 and not abandon:
        handle = InProcess(should_stop, reporter)
        for index, job in enumerate(jobs):
            if handle.should_stop():
                return False
            for item in items_of(function(handle, *job)):
                on_item(index, item)
        return not handle.should_stop()
    started = _run_local(function, jobs, max(1, workers), reporter, should_stop, on_item, abandon)
    return started and not (should_stop is not None and should_stop())


def map_jobs(
    function: Callable[..., Any], jobs: Sequence[tuple[Any, ...]], workers: int
) -> list[Any]:
    """Every plain job's result, in job order (no stop, no progress)."""
    results: dict[int, Any] = {}
    execute(function, jobs, results.__setitem__, workers=workers)
    return [results[index] for index in range(len(jobs))]


class InProcess:
    """The handle of a job that runs in this process."""

    def __init__(self, should_stop: Callable[[], bool] | None, reporter: Reporter) -> None:
        self._should_stop = should_stop
        self._reporter = reporter

    def should_stop(self) -> bool:
        """Whether this process was asked to stop."""
        return self._should_stop is not None and self._should_stop()

    def reporter(self) -> Reporter:
        """This process's reporter."""
        return self._reporter


# -- local worker processes ---------------------------------------------------------------

_STOP = "stop"
_JOIN_SECONDS = 5.0
_SIGNALS = STOP_SIGNALS


class WorkerError(RuntimeError):
    """A worker process failed in a way that cannot be passed on as its own exception."""


class _Abandoned(Exception):
    """A stop asked to abandon the running jobs (see ``execute(..., abandon=True)``)."""


def _run_local(
    function: Callable[..., Any],
    jobs: Sequence[tuple[Any, ...]],
    workers: int,
    reporter: Reporter,
    should_stop: Callable[[], bool] | None,
    on_item: Callable[[int, Any], None],
    abandon: bool = False,
) -> bool:
    """Run the jobs in worker processes; return whether every job started."""
    if not jobs:
        return True
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
        started = _dispatch(
            function, jobs, conns, processes, reporter, should_stop, on_item, abandon
        )
    except _Abandoned:
        _end_workers(processes, conns, kill=True)
        return False
    except BaseException:
        _end_workers(processes, conns, kill=True)
        raise
    _end_workers(processes, conns, kill=False)
    return started


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
    reporter: Reporter,
    should_stop: Callable[[], bool] | None,
    on_item: Callable[[int, Any], None],
    abandon: bool = False,
) -> bool:
    """Hand out the jobs to idle workers and pass their messages on until none is busy.

    Raises:
        _Abandoned: ``abandon`` and a stop was asked for (the items that arrived are handed
            on first).
    """
    idle = list(range(len(conns)))
    busy: dict[int, int] = {}  # worker -> job
    arrived: list[tuple[int, Any]] = []  # items on_item has not seen yet
    next_job = 0
    stopping = False
    while True:
        if not stopping and should_stop is not None and should_stop():
            stopping = True
            if abandon:
                for job, item in arrived:
                    on_item(job, item)
                raise _Abandoned
            for worker in busy:
                _send(conns[worker], _STOP)
        while idle and not stopping and next_job < len(jobs):
            worker = idle.pop(0)
            conns[worker].send(("job", function, jobs[next_job]))
            busy[worker] = next_job
            next_job += 1
        # Only now, with every idle worker busy again, hand items on (saving them takes time).
        for job, item in arrived:
            on_item(job, item)
        arrived.clear()
        if not busy:
            return next_job == len(jobs)
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
                if kind == "item":
                    arrived.append((busy[worker], payload[0]))
                elif kind == "done":
                    busy.pop(worker)
                    idle.append(worker)
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


def _worker_main(conn: Connection, parent_pid: int) -> None:
    """A worker's life: ignore signals, die with the parent, run jobs until told to end."""
    leave_signals_to_parent(parent_pid)
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
            for item in items_of(function(Worker(conn), *args)):
                conn.send(("item", item))
        except OSError:
            return  # the parent is gone
        except BaseException as error:  # every failure goes to the parent
            text = traceback.format_exc()
            try:
                pickled: bytes | None = pickle.dumps(error)
            except Exception:  # it cannot travel as itself
                pickled = None
            reply: tuple[Any, ...] = ("error", pickled, text)
        else:
            reply = ("done",)
        try:
            conn.send(reply)
        except OSError:
            return


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

    def start(self, key: Hashable, label: str, episodes: int) -> None:
        _send(self._conn, ("start", key, label, episodes))

    def update(self, key: Hashable, progress: Progress) -> None:
        now = time.monotonic()
        self._unsent = progress
        if now - self._last >= self._min_interval:
            self._last = now
            self._send_update(key)

    def _send_update(self, key: Hashable) -> None:
        if self._unsent is not None:
            _send(self._conn, ("update", key, *dataclasses.astuple(self._unsent)))
            self._unsent = None

    def finish(self, key: Hashable, line: str) -> None:
        # the last update may have been throttled: the bar must end on the real count
        self._send_update(key)
        _send(self._conn, ("finish", key, line))

    def close(self) -> None:
        """Nothing to close."""


# -- Ray ------------------------------------------------------------------------------------


class _RayJob:
    """The handle of a Ray job: a stop cancels the job from the driver instead."""

    def should_stop(self) -> bool:
        """Never: the driver cancels Ray jobs itself."""
        return False

    def reporter(self) -> Reporter:
        """Progress of Ray jobs is not shown (the driver counts finished items)."""
        return NullReporter()


def _ray_job(function: Callable[..., Any], job: tuple[Any, ...]) -> Iterator[Any]:
    """What a Ray task runs: a generator, so that Ray streams each item as it is made."""
    yield from items_of(function(_RayJob(), *job))


def _ray() -> Any:
    try:
        import ray
    except ImportError:
        raise ConfigError(
            "--backend ray: Ray is not installed; install it with "
            "`pip install 'cartpole-q[ray]'` (or `pip install ray`)."
        ) from None
    return ray


RAY_CONNECT_SECONDS = 10.0
"""how long to wait for a Ray cluster's head to answer before giving up"""


def _check_reachable(address: str) -> None:
    """Refuse at once an address where nothing listens (Ray itself retries for minutes).

    Raises:
        ConfigError: the address is not ``auto``, ``ray://...`` or ``HOST:PORT``, or nothing
            accepts a connection there within :data:`RAY_CONNECT_SECONDS`.
    """
    if address == "auto" or "://" in address:
        return
    host, _, port = address.rpartition(":")
    if not host or not port.isdigit():
        raise ConfigError(
            f"--address {address}: give `auto` (a cluster started on this machine) or "
            "HOST:PORT of the cluster's head, e.g. 10.0.0.5:6379."
        )
    try:
        socket.create_connection((host.strip("[]"), int(port)), RAY_CONNECT_SECONDS).close()
    except OSError as error:
        reason = error.strerror or str(error) or type(error).__name__
        raise ConfigError(
            f"--address {address}: no Ray cluster answers there ({reason}). Is `ray start "
            "--head` running on that machine, and is the port the one it printed?"
        ) from None


def connect_ray(workers: int, address: str | None) -> bool:
    """Connect to the Ray cluster at ``address``, or start a local one with ``workers`` CPUs.

    Returns:
        Whether this call connected (False: it was connected already).

    Raises:
        ConfigError: Ray is not installed, or no cluster answers at ``address``.
    """
    ray = _ray()
    if ray.is_initialized():
        return False
    if address is not None:
        _check_reachable(address)
    # ray.init installs its own SIGTERM handler (sys.exit); the command's own handling of
    # SIGINT and SIGTERM (exit 130, finished work saved) must stay in place.
    main = threading.current_thread() is threading.main_thread()
    handlers = {signum: signal.getsignal(signum) for signum in _SIGNALS}
    try:
        if address is None:
            ray.init(
                num_cpus=workers, include_dashboard=False, log_to_driver=False,
                configure_logging=False,
            )  # fmt: skip
        else:
            ray.init(address=address, log_to_driver=False, configure_logging=False)
    except ConnectionError as error:
        raise ConfigError(
            f"--address {address}: cannot connect to a Ray cluster ({error}). Is `ray start "
            "--head` running there? Ray 2.59 and later use token authentication: on the head "
            "machine `--address auto` works; elsewhere set RAY_AUTH_MODE=token and give the "
            "cluster's token (see docs/tutorials/ray-cluster.md)."
        ) from None
    finally:
        if main:
            for signum, handler in handlers.items():
                if handler is not None:
                    signal.signal(signum, handler)
    return True


@contextmanager
def ray_connection(workers: int, address: str | None) -> Iterator[None]:
    """Stay connected to Ray inside the block; disconnect (or stop the local cluster) after."""
    connected = connect_ray(workers, address)
    try:
        yield
    finally:
        if connected:
            _ray().shutdown()


def _execute_ray(
    function: Callable[..., Any],
    jobs: Sequence[tuple[Any, ...]],
    on_item: Callable[[int, Any], None],
    workers: int,
    address: str | None,
    should_stop: Callable[[], bool] | None,
) -> bool:
    ray = _ray()
    with ray_connection(workers, address):
        remote = ray.remote(num_cpus=1, max_retries=0)(_ray_job)
        pending = {remote.remote(function, job): index for index, job in enumerate(jobs)}
        try:
            while pending:
                if should_stop is not None and should_stop():
                    return False
                ready, _ = ray.wait(
                    list(pending), num_returns=len(pending), timeout=0.1, fetch_local=True
                )
                for stream in ready:
                    try:
                        ref = next(stream)
                    except StopIteration:
                        del pending[stream]
                        continue
                    on_item(pending[stream], ray.get(ref))
            return True
        finally:
            for stream in pending:  # stopped, or failed: nothing more is wanted
                ray.cancel(stream, force=True)
