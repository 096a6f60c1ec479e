"""The one-writer lock: a live holder is named and refused; a dying one is waited for."""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path
from typing import Any

import pytest

from cartpole_q.errors import RunError
from cartpole_q.store import lock

pytestmark = pytest.mark.skipif(os.name != "posix", reason="flock is POSIX")

_HOLDER = """
import sys, time
from pathlib import Path
from cartpole_q.store.lock import directory_lock
with directory_lock(Path(sys.argv[1]), "sweep"):
    print("held", flush=True)
    time.sleep(float(sys.argv[2]))
"""


def _hold(directory: Path, seconds: float) -> subprocess.Popen[str]:
    process = subprocess.Popen(
        [sys.executable, "-c", _HOLDER, str(directory), str(seconds)],
        stdout=subprocess.PIPE, text=True,
    )  # fmt: skip
    assert process.stdout is not None and process.stdout.readline() == "held\n"
    return process


def test_a_live_holder_is_refused_by_pid(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(lock, "_PATIENCE_SECONDS", 0.1)
    holder = _hold(tmp_path, 60)
    try:
        expected = f"another cartpole-q process \\(pid {holder.pid}\\)"
        with pytest.raises(RunError, match=expected), lock.directory_lock(tmp_path, "sweep"):
            pytest.fail("a second writer got the lock")
    finally:
        holder.kill()
        holder.wait()


def test_a_holder_ending_within_the_patience_is_waited_for(tmp_path: Path) -> None:
    """What a ``kill -9`` then ``--resume`` meets: workers still ending for a moment."""
    holder = _hold(tmp_path, 0.3)
    started = time.monotonic()
    with lock.directory_lock(tmp_path, "sweep"):
        waited = time.monotonic() - started
    holder.wait()
    assert waited > 0.1, "the lock was free at once: the holder never held it"
    assert (tmp_path / lock.LOCK_FILE).read_text() == f"{os.getpid()}\n"


def test_the_lock_is_free_after_kill_9(tmp_path: Path) -> None:
    holder = _hold(tmp_path, 60)
    os.kill(holder.pid, signal.SIGKILL)
    holder.wait()
    with lock.directory_lock(tmp_path, "sweep"):
        pass


def _wait_for_the_lock_in_a_thread(
    directory: Path, monkeypatch: pytest.MonkeyPatch
) -> tuple[threading.Thread, list[lock.HeldLock | None]]:
    """``acquire_lock(directory)`` in a thread, returned once it waits with the file open."""
    waiting = threading.Event()
    real = lock._try_lock

    def try_lock(*args: Any) -> bool:
        waiting.set()
        return real(*args)

    monkeypatch.setattr(lock, "_try_lock", try_lock)
    got: list[lock.HeldLock | None] = []
    thread = threading.Thread(target=lambda: got.append(lock.acquire_lock(directory)))
    thread.start()
    assert waiting.wait(10)
    return thread, got


def test_a_waiter_whose_directory_a_failed_start_removed_is_told(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Not a lock on a file nobody else can see: ``None``, so the claim starts over."""
    directory = tmp_path / "new"
    directory.mkdir()
    first = lock.acquire_lock(directory)
    assert first is not None
    thread, got = _wait_for_the_lock_in_a_thread(directory, monkeypatch)
    shutil.rmtree(directory)  # a failed start removes the directory it created
    first.release()
    thread.join()
    assert got == [None]


def test_a_waiter_whose_lock_file_was_removed_locks_the_new_one(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    first = lock.acquire_lock(tmp_path)
    assert first is not None
    thread, got = _wait_for_the_lock_in_a_thread(tmp_path, monkeypatch)
    (tmp_path / lock.LOCK_FILE).unlink()  # a failed start removes the lock file it created
    first.release()
    thread.join()
    (held,) = got
    assert held is not None
    try:
        assert os.fstat(held.descriptor).st_ino == os.stat(tmp_path / lock.LOCK_FILE).st_ino
        assert held.created
    finally:
        held.release()
