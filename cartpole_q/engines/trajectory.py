"""Figure 8.8's runs, compiled: one task, uniform or on-policy updates, its greedy values.

:func:`~cartpole_q.rl.planning_updates.trajectory_run` compiled with numba once per
machine (cached on disk); :func:`task_curves` draws a task and runs it, in chunks of about
:data:`CHUNK_WORK` units of work (a fraction of a second each), so that a caller's
``should_stop`` is asked between them. ``compiled=False`` runs the same Python (for tests
on tiny tasks).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, overload

import numpy as np

from cartpole_q.engines.compile import specialise
from cartpole_q.rl.planning_updates import (
    Curve,
    Task,
    task_draws,
    trajectory_progress,
    trajectory_run,
)

LOOP_NAME = "planning_trajectory_run"
CHUNK_WORK = 500_000
"""a chunk's work in :func:`~cartpole_q.rl.planning_updates.trajectory_run`'s units (``b``
per update, ``S * b`` per valuation, whose tens of sweeps make it the dearer): measured at
0.02-0.2 s on 2 shared cores for the book's tasks"""
_compiled: dict[str, Any] = {}


def compile_notice() -> str | None:
    """A sentence when the loop is not compiled yet (the first run), else ``None``."""
    from cartpole_q.numba_cache import is_cached

    if is_cached(LOOP_NAME):
        return None
    return "compiling the trajectory-sampling loop: once per machine and version, a few seconds..."


def _loop() -> Any:
    if LOOP_NAME not in _compiled:
        _compiled[LOOP_NAME] = specialise(trajectory_run, LOOP_NAME, {})
    return _compiled[LOOP_NAME]


@overload
def task_curves(
    seed: int, task: Task, curve: Curve, compiled: bool = True, *, should_stop: None = None
) -> tuple[np.ndarray, np.ndarray]: ...


@overload
def task_curves(
    seed: int, task: Task, curve: Curve, compiled: bool = True, *,
    should_stop: Callable[[], bool],
) -> tuple[np.ndarray, np.ndarray] | None: ...  # fmt: skip


def task_curves(
    seed: int,
    task: Task,
    curve: Curve,
    compiled: bool = True,
    *,
    should_stop: Callable[[], bool] | None = None,
) -> tuple[np.ndarray, np.ndarray] | None:
    """Task ``seed``'s two curves, ``(uniform, on_policy)``, each ``curve.updates // curve.every + 1`` values.

    Both run on the same task (:func:`~cartpole_q.rl.planning_updates.task_draws`); the
    on-policy run draws from the task's run generator. ``should_stop`` is asked before
    each chunk; when it says stop, ``None`` is returned at once.
    """
    next_states, rewards, rng = task_draws(seed, task.states, task.actions, task.branching)
    run = _loop() if compiled else trajectory_run
    curves = []
    for on_policy in (False, True):
        progress = trajectory_progress(task, curve)
        complete = False
        while not complete:
            if should_stop is not None and should_stop():
                return None
            complete = run(next_states, rewards, task, curve, on_policy, rng, progress, CHUNK_WORK)
        curves.append(progress.out)
    return curves[0], curves[1]
