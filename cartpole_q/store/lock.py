"""One writer at a time per directory: an advisory lock that names its holder.

A run, sweep or tune directory is written by one command at a time. Two commands resuming
the same sweep would run the same runs twice and the last writer would win; so the
command that writes a directory first takes its lock, and a second one is refused with
the holder's process id. The lock is ``flock`` on the file ``.lock`` in the directory:
the kernel releases it when the holder exits, however it exits (``kill -9`` included),
so a stale lock never blocks a later ``--resume``. Forked workers share the lock, so it
lasts until the last of them has ended; a holder that is dying (its workers take a few
milliseconds to follow a ``kill -9``) is waited for, briefly, before a second writer is
refused.
"""

from __future__ import annotations

import contextlib
import os
import time
from collections.abc import Callable, Iterator
from pathlib import Path

from cartpole_q.errors import RunError

LOCK_FILE = ".lock"
"""the lock file inside a locked directory (it holds the holder's process id)"""

_PATIENCE_SECONDS = 2.0
"""how long a held lock is retried before a second writer is refused"""


@contextlib.contextmanager
def directory_lock(directory: Path, what: str = "directory") -> Iterator[None]:
    """Hold the write lock of ``directory`` inside the block.

    Processes forked inside the block share the lock (they are the holder's workers).

    Args:
        directory: an existing directory.
        what: how messages call it ("sweep", "tune directory", "run").

    Raises:
        RunError: another process holds the lock (naming its process id), or the lock
            file cannot be created.
    """
    if os.name != "posix":  # pragma: no cover - flock is POSIX; elsewhere nothing is locked
        yield
        return
    import fcntl

    path = directory / LOCK_FILE
    try:
        descriptor = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
    except OSError as error:
        raise RunError(
            f"{directory}: cannot lock this {what} ({error.strerror}); is it writable?"
        ) from None
    try:
        if not _try_lock(descriptor, fcntl.flock, fcntl.LOCK_EX | fcntl.LOCK_NB):
            holder = _read_holder(descriptor)
            raise RunError(
                f"{directory}: another cartpole-q process ({holder}) is writing this {what}; "
                "one writer at a time keeps its results whole. Wait for it to finish (or stop "
                "it), then run the command again."
            ) from None
        os.ftruncate(descriptor, 0)
        os.pwrite(descriptor, f"{os.getpid()}\n".encode(), 0)
        yield
    finally:
        os.close(descriptor)  # releases the lock (forked workers have ended by now)


def _try_lock(descriptor: int, flock: Callable[[int, int], None], operation: int) -> bool:
    """Take the lock, retrying for ``_PATIENCE_SECONDS`` while a holder may be ending."""
    deadline = time.monotonic() + _PATIENCE_SECONDS
    while True:
        try:
            flock(descriptor, operation)
            return True
        except BlockingIOError:
            if time.monotonic() >= deadline:
                return False
            time.sleep(0.02)


def _read_holder(descriptor: int) -> str:
    """The holder as the lock file names it: ``pid 1234`` (or "pid unknown")."""
    with contextlib.suppress(OSError, ValueError):
        text = os.pread(descriptor, 32, 0).decode().strip()
        if text:
            return f"pid {int(text)}"
    return "pid unknown"
