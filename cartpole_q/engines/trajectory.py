"""Figure 8.8's runs, compiled: one task, uniform or on-policy updates, its greedy values.

:func:`~cartpole_q.rl.planning_updates.trajectory_run` compiled with numba once per
machine (cached on disk); :func:`task_curve` draws a task and runs it. ``compiled=False``
runs the same Python (for tests on tiny tasks).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from cartpole_q.engines.compile import specialise
from cartpole_q.rl.planning_updates import task_draws, trajectory_run

LOOP_NAME = "planning_trajectory_run"
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


def task_curves(
    seed: int,
    states: int,
    actions: int,
    branching: int,
    updates: int,
    every: int,
    termination: float,
    epsilon: float,
    tolerance: float,
    compiled: bool = True,
) -> tuple[np.ndarray, np.ndarray]:
    """Task ``seed``'s two curves, ``(uniform, on_policy)``, each ``updates // every + 1`` values.

    Both run on the same task (:func:`~cartpole_q.rl.planning_updates.task_draws`); the
    on-policy run draws from the task's run generator.
    """
    next_states, rewards, rng = task_draws(seed, states, actions, branching)
    run = _loop() if compiled else trajectory_run
    curves = []
    for on_policy in (False, True):
        out = np.empty(updates // every + 1)
        run(next_states, rewards, termination, epsilon, on_policy, every, tolerance, rng, out)
        curves.append(out)
    return curves[0], curves[1]
