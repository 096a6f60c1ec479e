"""Greedy play in a real Gymnasium environment, in plain Python (no numba).

``cartpole-q eval`` and the gymnasium engine's evaluations play here: the first episode's
reset is seeded with the evaluation seed, later resets continue that environment's stream.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from cartpole_q.engines.base import EVAL_CHUNK_EPISODES, Grid
from cartpole_q.rl.binning import discrete_index, state_index
from cartpole_q.rl.tiles import active_tiles, greedy_tile_action

FrameCallback = Callable[[Any, int, int], None]
"""called with ``(env, episode, step)`` after every reset and step, e.g. to render"""


def play_greedy(
    env: Any,
    q: np.ndarray,
    grid: Grid,
    episodes: int,
    seed: int,
    on_frame: FrameCallback | None = None,
    step_cap: int | None = None,
    tilings: int = 1,
    should_stop: Callable[[], bool] | None = None,
) -> np.ndarray:
    """Play the greedy policy of a 2-D ``(n_states, n_actions)`` Q-table.

    Args:
        env: a Gymnasium environment (from ``gymnasium.make``).
        q: the Q-table as ``(n_states, n_actions)``.
        grid: the discretisation the table was trained with.
        episodes: how many episodes to play.
        seed: the seed of the first reset.
        on_frame: called after every reset and step, e.g. to record video frames.
        step_cap: end an episode after this many steps (for environments without a time
            limit, see :data:`GREEDY_STEP_CAP`); ``None``: only the environment ends it.
        tilings: tile coding's tilings: ``q`` is then the weights ``(T * tiles, n_actions)``
            and the action the argmax of the tiles' sum (see :mod:`cartpole_q.rl.tiles`).
        should_stop: asked after every :data:`EVAL_CHUNK_EPISODES` episodes; when it says
            so, play ends there (as :func:`~cartpole_q.engines.base.played_until_stopped`).

    Returns:
        The return of each episode played.
    """
    # Plain Python lists make the uncompiled binning rule about twice as fast per step.
    low, high, bins = grid.low.tolist(), grid.high.tolist(), grid.bins.tolist()
    starts = grid.starts.tolist()
    tile_rows = np.zeros(tilings, dtype=np.int64)
    returns = np.zeros(episodes, dtype=np.float64)
    for episode in range(episodes):
        observation, _ = env.reset(seed=seed if episode == 0 else None)
        if on_frame is not None:
            on_frame(env, episode, 0)
        step = 0
        while True:
            if tilings > 1:
                active_tiles(observation, low, high, bins, tilings, tile_rows)
                action = greedy_tile_action(q, tile_rows, q.shape[1])
            else:
                if starts:
                    row = discrete_index(observation, starts, bins)
                else:
                    row = state_index(observation, low, high, bins)
                action = int(np.argmax(q[row]))
            observation, reward, terminated, truncated, _ = env.step(action)
            step += 1
            returns[episode] += reward
            if on_frame is not None:
                on_frame(env, episode, step)
            if terminated or truncated or (step_cap is not None and step >= step_cap):
                break
        played = episode + 1
        chunk_ended = played % EVAL_CHUNK_EPISODES == 0 and played < episodes
        if chunk_ended and should_stop is not None and should_stop():
            return returns[:played]
    return returns
