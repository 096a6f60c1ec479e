"""Child processes that leave signals to their parent and do not outlive it.

A command answers SIGINT and SIGTERM itself (it stops at a safe point, saying what it kept).
A process it starts must neither answer them too (a second message, a second decision) nor
keep running once the command is gone: it ignores both signals and, on Linux, asks the
kernel to kill it when its parent dies. Worker pools (:mod:`cartpole_q.experiments.workers`)
and the child that compiles one loop beside a run's own compilation
(:mod:`cartpole_q.engines.numba_engine`) start this way.
"""

from __future__ import annotations

import os
import signal
import sys

STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM)
"""the signals a command answers by stopping"""


def leave_signals_to_parent(parent_pid: int) -> None:
    """In a child process: ignore :data:`STOP_SIGNALS`, and die with the parent.

    Call it first thing in the child. A signal that arrived while the parent held them
    blocked (the child inherits the mask) is discarded, then they are unblocked.
    """
    for signum in STOP_SIGNALS:
        signal.signal(signum, signal.SIG_IGN)
    if hasattr(signal, "pthread_sigmask"):
        signal.pthread_sigmask(signal.SIG_UNBLOCK, set(STOP_SIGNALS))
    die_with_parent(parent_pid)


def die_with_parent(parent_pid: int) -> None:
    """On Linux, ask the kernel to SIGKILL this process when its parent dies.

    Elsewhere nothing happens (a worker then ends when its pipe to the parent closes).
    """
    if not sys.platform.startswith("linux"):
        return
    try:
        import ctypes

        ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGKILL, 0, 0, 0)  # PR_SET_PDEATHSIG
    except (OSError, AttributeError):
        return
    if os.getppid() != parent_pid:
        os._exit(1)  # the parent died before the request took effect
