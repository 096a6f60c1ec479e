"""Greedy evaluation of a Q-table in real Gymnasium environments.

``cartpole-q eval`` always plays here, in ``gymnasium.make(env.id, **env.kwargs)``: the
first episode's reset is seeded with the evaluation seed, later resets continue that
environment's random stream.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from cartpole_q.config import MAX_EPISODES, Config, ConfigError
from cartpole_q.discretize import state_index
from cartpole_q.engines.base import AgentParams

FrameCallback = Callable[[Any, int, int], None]
"""called with ``(env, episode, step)`` after every reset and step, e.g. to render"""


@dataclass(frozen=True)
class EvalReport:
    """Returns of a greedy evaluation and their statistics."""

    returns: tuple[float, ...]
    """the return of each episode, in order"""
    seed: int
    """the seed of the first reset"""

    @property
    def episodes(self) -> int:
        """Number of episodes played."""
        return len(self.returns)

    @property
    def mean(self) -> float:
        """Mean return."""
        return float(np.mean(self.returns))

    @property
    def std(self) -> float:
        """Population standard deviation of the returns."""
        return float(np.std(self.returns))

    def to_dict(self) -> dict[str, Any]:
        """Return ``mean, std, min, max, episodes, seed`` as ``eval --json`` prints them."""
        return {
            "mean": self.mean,
            "std": self.std,
            "min": float(np.min(self.returns)),
            "max": float(np.max(self.returns)),
            "episodes": self.episodes,
            "seed": self.seed,
        }

    @classmethod
    def from_returns(cls, returns: np.ndarray, seed: int) -> EvalReport:
        """Build a report from an array of returns."""
        return cls(returns=tuple(float(r) for r in returns), seed=seed)


def play_greedy(
    env: Any,
    q: np.ndarray,
    params: AgentParams,
    episodes: int,
    seed: int,
    on_frame: FrameCallback | None = None,
) -> np.ndarray:
    """Play the greedy policy of a 2-D ``(n_states, n_actions)`` Q-table.

    Args:
        env: a Gymnasium environment (from ``gymnasium.make``).
        q: the Q-table as ``(n_states, n_actions)``.
        params: the discretisation the table was trained with.
        episodes: how many episodes to play.
        seed: the seed of the first reset.
        on_frame: called after every reset and step, e.g. to record video frames.

    Returns:
        The return of each episode.
    """
    # Plain Python lists make the uncompiled binning rule about twice as fast per step.
    low, high, bins = params.low.tolist(), params.high.tolist(), params.bins.tolist()
    returns = np.zeros(episodes, dtype=np.float64)
    for episode in range(episodes):
        observation, _ = env.reset(seed=seed if episode == 0 else None)
        if on_frame is not None:
            on_frame(env, episode, 0)
        step = 0
        while True:
            action = int(np.argmax(q[state_index(observation, low, high, bins)]))
            observation, reward, terminated, truncated, _ = env.step(action)
            step += 1
            returns[episode] += reward
            if on_frame is not None:
                on_frame(env, episode, step)
            if terminated or truncated:
                break
    return returns


def evaluate(
    q_table: np.ndarray,
    config: Config,
    *,
    episodes: int | None = None,
    seed: int | None = None,
    render_mode: str | None = None,
    on_frame: FrameCallback | None = None,
) -> EvalReport:
    """Evaluate a Q-table's greedy policy in ``gymnasium.make``.

    Args:
        q_table: the table, shape ``(*bins, n_actions)`` as saved in ``q_table.npy``.
        config: the config it was trained with (environment and discretisation).
        episodes: episodes to play; default ``config.eval.episodes``.
        seed: seed of the first reset; default ``config.eval.seed``.
        render_mode: passed to ``gymnasium.make`` (``rgb_array`` for video, ``human``).
        on_frame: called after every reset and step.

    Raises:
        ConfigError: ``episodes`` is not between 1 and ``MAX_EPISODES``.
        cartpole_q.rundir.RunError: the table does not fit the config and environment.
    """
    from cartpole_q.environment import inspect_env, make_env
    from cartpole_q.rundir import check_q_table

    episodes = config.eval.episodes if episodes is None else episodes
    if not 1 <= episodes <= MAX_EPISODES:
        raise ConfigError(
            f"--episodes: must be between 1 and {MAX_EPISODES:,} greedy episodes, got {episodes:,}."
        )
    env_info = inspect_env(config)
    check_q_table(q_table, config.discretization.bins, env_info.n_actions, "the Q-table")
    params = AgentParams.from_config(config, env_info)
    seed = config.eval.seed if seed is None else seed
    env = make_env(config.env, render_mode=render_mode)
    try:
        returns = play_greedy(
            env, q_table.reshape(-1, env_info.n_actions), params, episodes, seed, on_frame
        )
    finally:
        env.close()
    return EvalReport.from_returns(returns, seed)
