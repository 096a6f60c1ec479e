"""Greedy evaluation of a Q-table in real Gymnasium environments.

``cartpole-q eval`` always plays here, in ``gymnasium.make(env.id, **env.kwargs)``: the
first episode's reset is seeded with the evaluation seed, later resets continue that
environment's random stream.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from cartpole_q.config import MAX_EPISODES, Config, ConfigError, load_config
from cartpole_q.engines.base import AgentParams
from cartpole_q.engines.play import FrameCallback, play_greedy
from cartpole_q.envs.gym import inspect_env, make_env
from cartpole_q.errors import RunError


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


def under_conditions(
    config: Config,
    physics: Mapping[str, Any] | None = None,
    max_steps: int | None = None,
) -> Config:
    """The config with other physics (merged onto its ``env.physics``) or another horizon.

    Checked like a config: an unknown key, a bad value, or physics on an environment that
    is not CartPole is a ``ConfigError`` naming it (``eval --physics``, ``--max-steps``).
    """
    overrides: dict[str, Any] = {}
    if physics:
        overrides["env.physics"] = {**config.env.physics, **physics}
    if max_steps is not None:
        overrides["env.kwargs.max_episode_steps"] = max_steps
    return load_config(config.to_dict(), overrides) if overrides else config


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
        RunError: the table does not fit the config and environment.
    """
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
            env, q_table.reshape(-1, env_info.n_actions), params.grid, episodes, seed, on_frame
        )
    finally:
        env.close()
    return EvalReport.from_returns(returns, seed)


def check_q_table(
    q_table: np.ndarray, bins: tuple[int, ...], n_actions: int | None, source: str
) -> None:
    """Check a Q-table against its config's grid (and the environment's actions).

    Raises:
        RunError: wrong dtype or shape, or a non-finite value.
    """
    if q_table.dtype != np.float64:
        raise RunError(f"{source}: must hold float64 values, found {q_table.dtype}.")
    expected = f"(*bins, n_actions) = ({', '.join(map(str, bins))}, {n_actions or 'n_actions'})"
    if q_table.ndim != len(bins) + 1 or tuple(q_table.shape[:-1]) != tuple(bins):
        raise RunError(
            f"{source}: has shape {q_table.shape}, which does not match its config: expected {expected}."
        )
    if n_actions is not None and q_table.shape[-1] != n_actions:
        raise RunError(
            f"{source}: has {q_table.shape[-1]} actions per state but the environment has "
            f"{n_actions}: expected {expected}."
        )
    if not np.isfinite(q_table).all():
        raise RunError(f"{source}: holds NaN or infinite values.")
