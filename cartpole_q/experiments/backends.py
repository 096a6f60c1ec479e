"""Where many tasks run: this process, local worker processes, or a Ray cluster.

Each task is ``function(worker, *job)``; ``worker.should_stop()`` says whether the task
should end early (returning what it finished). Results reach ``on_result`` as tasks
finish, in whatever order; callers must not depend on that order. Ray is imported only
when ``backend="ray"`` is asked for, so the base install does not need it.
"""

from __future__ import annotations

import signal
import threading
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from typing import Any

from cartpole_q.errors import ConfigError
from cartpole_q.experiments.multiseed import run_in_workers

BACKENDS = ("local", "ray")


class _InProcess:
    """The worker handle of a task that runs in this process."""

    def __init__(self, should_stop: Callable[[], bool] | None) -> None:
        self._should_stop = should_stop

    def should_stop(self) -> bool:
        """Whether this process was asked to stop."""
        return self._should_stop is not None and self._should_stop()


class _NeverStop:
    """The worker handle of a Ray task: a stop cancels the task from the driver instead."""

    def should_stop(self) -> bool:
        """Never: the driver cancels Ray tasks itself."""
        return False


def execute(
    function: Callable[..., Any],
    jobs: Sequence[tuple[Any, ...]],
    on_result: Callable[[int, Any], None],
    *,
    backend: str = "local",
    workers: int = 1,
    address: str | None = None,
    should_stop: Callable[[], bool] | None = None,
) -> bool:
    """Run every job, handing each result to ``on_result(index, result)`` as it arrives.

    Args:
        function: a module-level function ``function(worker, *job)``.
        jobs: the argument tuples, started in this order.
        on_result: called in this process for each finished job.
        backend: ``local`` (this process when ``workers`` is 1, else worker processes)
            or ``ray``.
        workers: local worker processes; with Ray, the CPUs of a local cluster started
            here (ignored with ``address``).
        address: a running Ray cluster's address (``auto`` or ``HOST:PORT``); without
            it, a local Ray cluster is started for this call and stopped after it.
        should_stop: polled while waiting; once true no job starts any more.

    Returns:
        Whether every job ran (false after a stop).
    """
    if backend == "ray":
        return _execute_ray(function, jobs, on_result, workers, address, should_stop)
    if workers <= 1:
        handle = _InProcess(should_stop)
        for index, job in enumerate(jobs):
            if handle.should_stop():
                return False
            on_result(index, function(handle, *job))
        return not handle.should_stop()
    results = run_in_workers(function, jobs, workers, should_stop=should_stop, on_result=on_result)
    from cartpole_q.experiments.multiseed import NOT_STARTED

    return not any(result is NOT_STARTED for result in results) and not (
        should_stop is not None and should_stop()
    )


def _call(function: Callable[..., Any], job: tuple[Any, ...]) -> Any:
    """What a Ray task runs."""
    return function(_NeverStop(), *job)


def _ray() -> Any:
    try:
        import ray
    except ImportError:
        raise ConfigError(
            "--backend ray: Ray is not installed; install it with "
            "`pip install 'cartpole-q[ray]'` (or `pip install ray`)."
        ) from None
    return ray


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
    # ray.init installs its own SIGTERM handler (sys.exit); the command's own handling of
    # SIGINT and SIGTERM (exit 130, finished work saved) must stay in place.
    main = threading.current_thread() is threading.main_thread()
    handlers = {signum: signal.getsignal(signum) for signum in (signal.SIGINT, signal.SIGTERM)}
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
            "cluster's token (see the README)."
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
    on_result: Callable[[int, Any], None],
    workers: int,
    address: str | None,
    should_stop: Callable[[], bool] | None,
) -> bool:
    ray = _ray()
    with ray_connection(workers, address):
        remote = ray.remote(num_cpus=1, max_retries=0)(_call)
        pending = {remote.remote(function, job): index for index, job in enumerate(jobs)}
        try:
            while pending:
                if should_stop is not None and should_stop():
                    return False
                ready, _ = ray.wait(
                    list(pending), num_returns=len(pending), timeout=0.1, fetch_local=True
                )
                for ref in ready:
                    on_result(pending.pop(ref), ray.get(ref))
            return True
        finally:
            for ref in pending:  # stopped, or failed: nothing more is wanted
                ray.cancel(ref, force=True)
