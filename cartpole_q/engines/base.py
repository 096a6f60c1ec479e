"""What every engine shares: the agent's parameters, the training state, the interface."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Protocol

import numpy as np

from cartpole_q.config import Config, Schedule
from cartpole_q.environment import EnvInfo

ScheduleParams = tuple[int, float, float, float]


def schedule_params(schedule: Schedule) -> ScheduleParams:
    """Return a schedule as the ``(kind, start, end, rate)`` tuple the compiled code takes."""
    return (schedule.code, schedule.start, schedule.end, schedule.rate)


@dataclass(frozen=True)
class AgentParams:
    """The config's agent settings as the arrays and numbers the compiled functions take."""

    low: np.ndarray
    """grid lower edges, float64"""
    high: np.ndarray
    """grid upper edges, float64"""
    bins: np.ndarray
    """bins per dimension, int64"""
    gamma: float
    alpha: ScheduleParams
    epsilon: ScheduleParams
    threshold: float
    """the solve threshold; ``inf`` when the environment has none (never solved)"""

    @classmethod
    def from_config(cls, config: Config, env_info: EnvInfo) -> AgentParams:
        """Build the parameters of a validated config on its environment."""
        d = config.discretization
        threshold = env_info.reward_threshold
        return cls(
            low=np.array(d.low, dtype=np.float64),
            high=np.array(d.high, dtype=np.float64),
            bins=np.array(d.bins, dtype=np.int64),
            gamma=config.agent.gamma,
            alpha=schedule_params(config.agent.alpha),
            epsilon=schedule_params(config.agent.epsilon),
            threshold=math.inf if threshold is None else float(threshold),
        )


@dataclass
class TrainingState:
    """Everything that changes while training; an engine advances it episode by episode.

    ``q`` and ``visits`` are the 2-D ``(n_states, n_actions)`` views the compiled code
    addresses; the per-episode arrays are allocated for the configured episodes and filled
    up to ``episode``.
    """

    q: np.ndarray
    visits: np.ndarray
    agent_rng: np.random.Generator
    returns: np.ndarray
    lengths: np.ndarray
    epsilons: np.ndarray
    alphas: np.ndarray
    episode: int = 0
    """episodes finished"""
    env_steps: int = 0
    """environment steps taken in training (evaluations excluded)"""
    solved_episode: int | None = None
    """1-based episode at which the 100-episode average first reached the threshold"""
    solved_q: np.ndarray | None = None
    """a copy of ``q`` at the solve point, kept when training goes on past it"""
    evaluations: list[dict[str, Any]] = field(default_factory=list)
    """periodic greedy evaluations: episode, env_steps, mean, std, min, max"""

    @classmethod
    def fresh(
        cls, config: Config, env_info: EnvInfo, agent_rng: np.random.Generator
    ) -> TrainingState:
        """Allocate the state of a run that has not started."""
        n_states = math.prod(config.discretization.bins)
        episodes = config.train.episodes
        return cls(
            q=np.full((n_states, env_info.n_actions), config.agent.q_init, dtype=np.float64),
            visits=np.zeros((n_states, env_info.n_actions), dtype=np.int64),
            agent_rng=agent_rng,
            returns=np.zeros(episodes, dtype=np.float64),
            lengths=np.zeros(episodes, dtype=np.int64),
            epsilons=np.zeros(episodes, dtype=np.float64),
            alphas=np.zeros(episodes, dtype=np.float64),
        )


class Engine(Protocol):
    """Drives an environment around the shared agent functions."""

    name: str
    """``numba`` or ``gymnasium``, as recorded in ``summary.json``"""
    chunk_episodes: int
    """episodes per :meth:`run` call that keep progress and Ctrl-C responsive"""

    def run(self, state: TrainingState, stop: int, check_solved: bool) -> int | None:
        """Train episodes ``state.episode .. stop - 1``, advancing ``state``.

        When ``check_solved``, return right after the first episode whose moving average
        reaches the threshold, giving its 0-based index; else return ``None``.
        """
        ...

    def evaluate(self, q: np.ndarray, episodes: int, seed: int) -> np.ndarray:
        """Return the greedy policy's returns over ``episodes`` episodes from ``seed``."""
        ...

    def warm_up(self, state: TrainingState) -> None:
        """Compile (or load from the cache) the compiled code, so that timing excludes it.

        Touches neither the state's arrays nor its generator's stream.
        """
        ...

    def env_rng_state(self) -> dict[str, Any]:
        """Return the training environment's random generator state (for checkpoints)."""
        ...

    def close(self) -> None:
        """Release the environment."""
        ...
