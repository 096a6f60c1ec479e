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

A new directory is locked before anything looks into it (see
:func:`cartpole_q.store.rundir.new_directory`); a command that fails while starting
removes the directory it created (or the lock file it created), while it still holds the
lock. A writer that was waiting for that lock then holds a file that is no longer in the
directory: :func:`acquire_lock` checks for this and locks the directory's new lock file,
or says that the directory is gone (``None``), instead of handing out a lock that nobody
else can see.
"""

from __future__ import annotations

import contextlib
import os
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path

from cartpole_q.errors import RunError, WriteError
from cartpole_q.store.atomic import write_failure

LOCK_FILE = ".lock"
"""the lock file inside a locked directory (it holds the holder's process id)"""

_PATIENCE_SECONDS = 2.0
"""how long a held lock is retried before a second writer is refused"""

_ATTEMPTS = 20
"""how often a lock file removed by a failed start is locked anew before giving up"""

_WAIT_ADVICE = (
    "one writer at a time keeps its results whole. Wait for it to finish (or stop it), then "
    "run the command again."
)


@dataclass
class HeldLock:
    """The write lock of a directory, held by this process until :meth:`release`."""

    directory: Path
    descriptor: int
    """the open lock file (closing it releases the lock)"""
    created: bool
    """this process created the lock file (a failed start removes it again)"""

    def name_holder(self) -> None:
        """Write this process's id into the lock file, for a refused writer's message.

        Raises:
            WriteError: the lock file cannot be written (a full disk), naming it; the
                lock is still held, so the caller can undo its start before releasing it.
        """
        if self.descriptor < 0:  # pragma: no cover - not POSIX
            return
        path = self.directory / LOCK_FILE
        try:
            os.ftruncate(self.descriptor, 0)
            os.pwrite(self.descriptor, f"{os.getpid()}\n".encode(), 0)
        except OSError as error:
            raise WriteError(f"{path}: cannot be written: {write_failure(path, error)}.") from None

    def release(self) -> None:
        """Release the lock (forked workers that share it have ended by now)."""
        if self.descriptor >= 0:
            os.close(self.descriptor)
            self.descriptor = -1


def acquire_lock(
    directory: Path, what: str = "directory", advice: str = _WAIT_ADVICE
) -> HeldLock | None:
    """Take the write lock of ``directory``, waiting briefly for a holder that is ending.

    The holder is not named in the lock file yet: :meth:`HeldLock.name_holder` does it.

    Args:
        directory: an existing directory.
        what: how messages call it ("sweep", "tune directory", "run").
        advice: what the refusal tells a second writer to do.

    Returns:
        The held lock, or ``None`` when the directory was removed while this process
        waited: the holder was a command that failed while starting it.

    Raises:
        RunError: another process holds the lock (naming its process id and ``advice``).
        WriteError: the lock file cannot be created (no permission, no inode left),
            naming it.
    """
    if os.name != "posix":  # pragma: no cover - flock is POSIX; elsewhere nothing is locked
        return HeldLock(directory, -1, False)
    import fcntl

    path = directory / LOCK_FILE
    for _ in range(_ATTEMPTS):
        opened = _open_lock_file(path)
        if opened is None:
            return None
        descriptor, created = opened
        try:
            if not _try_lock(descriptor, fcntl.flock, fcntl.LOCK_EX | fcntl.LOCK_NB):
                holder = _read_holder(descriptor)
                raise RunError(
                    f"{directory}: another cartpole-q process ({holder}) is writing this "
                    f"{what}; {advice}"
                )
            if not _still_in_place(path, descriptor):
                # The holder removed the lock file (a failed start): lock the new one.
                os.close(descriptor)
                if not directory.is_dir():
                    return None
                continue
        except BaseException:
            os.close(descriptor)
            raise
        return HeldLock(directory, descriptor, created)
    raise RunError(
        f"{directory}: other cartpole-q commands keep starting and failing in this {what}; "
        "run the command again once they have stopped."
    )


@contextlib.contextmanager
def directory_lock(directory: Path, what: str = "directory") -> Iterator[None]:
    """Hold the write lock of an existing ``directory`` inside the block.

    Processes forked inside the block share the lock (they are the holder's workers).

    Args:
        directory: an existing directory.
        what: how messages call it ("sweep", "tune directory", "run").

    Raises:
        RunError: another process holds the lock (naming its process id), or the
            directory was removed meanwhile.
        WriteError: the lock file cannot be created or written.
    """
    held = acquire_lock(directory, what)
    if held is None:
        raise RunError(f"{directory}: no longer exists (it was removed while this command waited).")
    try:
        held.name_holder()
        yield
    finally:
        held.release()


def _open_lock_file(path: Path) -> tuple[int, bool] | None:
    """Open (or create) the lock file: its descriptor and whether it was created here.

    Returns ``None`` when the directory is gone.
    """
    try:
        return os.open(path, os.O_RDWR | os.O_CREAT | os.O_EXCL, 0o644), True
    except FileExistsError:
        pass
    except FileNotFoundError:
        return None
    except OSError as error:
        raise WriteError(f"{path}: cannot be written: {write_failure(path, error)}.") from None
    try:
        return os.open(path, os.O_RDWR), False
    except FileNotFoundError:
        # removed between the two calls, by a failed start
        return _open_lock_file(path) if path.parent.is_dir() else None
    except OSError as error:
        raise WriteError(f"{path}: cannot be written: {write_failure(path, error)}.") from None


def _still_in_place(path: Path, descriptor: int) -> bool:
    """Whether the locked file is still the one at ``path`` (not removed by a failed start)."""
    try:
        now = os.stat(path)
    except FileNotFoundError:
        return False
    held = os.fstat(descriptor)
    return (now.st_dev, now.st_ino) == (held.st_dev, held.st_ino)


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
