"""What every engine shares: parameters as compiled code takes them, state, interface.

The compiled code takes a few typed records (named tuples of numbers and arrays) rather
than long lists of positional arguments: :class:`Grid`, :class:`AgentRecord`,
:class:`Tables` and :class:`EpisodeMetrics`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, NamedTuple, Protocol

import numpy as np

from cartpole_q.config import ALGORITHMS, Config, Schedule
from cartpole_q.envs.gym import EnvInfo


class ScheduleRecord(NamedTuple):
    """A schedule as the compiled code takes it (see :mod:`cartpole_q.rl.schedules`)."""

    kind: int
    start: float
    end: float
    rate: float

    @classmethod
    def of(cls, schedule: Schedule) -> ScheduleRecord:
        """The record of a config's schedule."""
        return cls(schedule.code, schedule.start, schedule.end, schedule.rate)


class AgentRecord(NamedTuple):
    """The algorithm and its hyperparameters, as the compiled code takes them."""

    algorithm: int
    """the code of ``agent.algorithm`` (see :mod:`cartpole_q.rl.algorithms`)"""
    gamma: float
    alpha: ScheduleRecord
    epsilon: ScheduleRecord
    threshold: float
    """the solve threshold; ``inf`` when the environment has none (never solved)"""


class Grid(NamedTuple):
    """How an observation becomes a Q-table row, as compiled code takes it.

    Binned (Box) observations: float64 edges and int64 bins per dimension, ``starts``
    empty. Indexed (Discrete, Tuple of Discrete) observations: ``bins`` holds each
    component's size and ``starts`` its ``start`` (int64), ``low`` and ``high`` empty; the
    row is ``obs - start`` (components in C order). ``starts.size > 0`` is the index mode.
    """

    low: np.ndarray
    high: np.ndarray
    bins: np.ndarray
    starts: np.ndarray

    @property
    def indexed(self) -> bool:
        """Whether observations are the row index (Discrete) rather than binned (Box)."""
        return bool(self.starts.size)

    @classmethod
    def of(cls, config: Config, env_info: EnvInfo) -> Grid:
        """The grid of a validated config on its (inspected) environment."""
        if env_info.index_starts is not None:
            return cls(
                np.zeros(0, dtype=np.float64),
                np.zeros(0, dtype=np.float64),
                np.array(env_info.state_shape, dtype=np.int64),
                np.array(env_info.index_starts, dtype=np.int64),
            )
        d = config.discretization
        assert d is not None  # inspect_env refuses a Box observation without a grid
        return cls(
            np.array(d.low, dtype=np.float64),
            np.array(d.high, dtype=np.float64),
            np.array(d.bins, dtype=np.int64),
            np.zeros(0, dtype=np.int64),
        )


class Tables(NamedTuple):
    """The learned tables, as 2-D ``(n_states, n_actions)`` views.

    ``q_b`` is Double Q-learning's second table (``(0, n_actions)`` for the others).
    """

    q: np.ndarray
    q_b: np.ndarray
    visits: np.ndarray


class EpisodeMetrics(NamedTuple):
    """One value per training episode: the columns of ``metrics.csv`` after ``episode``."""

    returns: np.ndarray
    """float64"""
    lengths: np.ndarray
    """int64"""
    epsilons: np.ndarray
    """float64"""
    alphas: np.ndarray
    """float64"""

    @classmethod
    def empty(cls, episodes: int) -> EpisodeMetrics:
        """Zeroed arrays for ``episodes`` episodes."""
        return cls(
            np.zeros(episodes, dtype=np.float64),
            np.zeros(episodes, dtype=np.int64),
            np.zeros(episodes, dtype=np.float64),
            np.zeros(episodes, dtype=np.float64),
        )

    def head(self, episodes: int) -> EpisodeMetrics:
        """Copies of the first ``episodes`` values."""
        return EpisodeMetrics(*(column[:episodes].copy() for column in self))


@dataclass(frozen=True)
class AgentParams:
    """A config's grid and agent settings, ready for the compiled code."""

    grid: Grid
    agent: AgentRecord

    @property
    def double(self) -> bool:
        """Whether the algorithm keeps two tables (Double Q-learning)."""
        return self.agent.algorithm == ALGORITHMS.index("double_q_learning")

    @classmethod
    def from_config(cls, config: Config, env_info: EnvInfo) -> AgentParams:
        """Build the parameters of a validated config on its environment."""
        threshold = env_info.reward_threshold
        return cls(
            grid=Grid.of(config, env_info),
            agent=AgentRecord(
                algorithm=ALGORITHMS.index(config.agent.algorithm),
                gamma=config.agent.gamma,
                alpha=ScheduleRecord.of(config.agent.alpha),
                epsilon=ScheduleRecord.of(config.agent.epsilon),
                threshold=math.inf if threshold is None else float(threshold),
            ),
        )


@dataclass
class TrainingState:
    """Everything that changes while training; an engine advances it episode by episode.

    The tables are the 2-D ``(n_states, n_actions)`` views the compiled code addresses;
    the per-episode metrics are allocated for the configured episodes and filled up to
    ``episode``.
    """

    tables: Tables
    agent_rng: np.random.Generator
    metrics: EpisodeMetrics
    physics_rng: np.random.Generator
    """draws ``env.randomize``'s physics before every episode (nothing else)"""
    episode: int = 0
    """episodes finished"""
    env_steps: int = 0
    """environment steps taken in training (evaluations excluded)"""
    solved_episode: int | None = None
    """1-based episode at which the 100-episode average first reached the threshold"""
    solved_q: np.ndarray | None = None
    """the policy table at the solve point, kept when training goes on past it"""
    evaluations: list[dict[str, Any]] = field(default_factory=list)
    """periodic greedy evaluations: episode, env_steps, mean, std, min, max"""

    @classmethod
    def fresh(
        cls,
        config: Config,
        env_info: EnvInfo,
        agent_rng: np.random.Generator,
        physics_rng: np.random.Generator | None = None,
    ) -> TrainingState:
        """Allocate the state of a run that has not started."""
        n_states = math.prod(env_info.state_shape)
        shape = (n_states, env_info.n_actions)
        double = config.agent.algorithm == "double_q_learning"
        return cls(
            tables=Tables(
                q=np.full(shape, config.agent.q_init, dtype=np.float64),
                q_b=np.full(shape if double else (0, shape[1]), config.agent.q_init),
                visits=np.zeros(shape, dtype=np.int64),
            ),
            agent_rng=agent_rng,
            metrics=EpisodeMetrics.empty(config.train.episodes),
            physics_rng=physics_rng if physics_rng is not None else np.random.default_rng(0),
        )

    def policy_table(self) -> np.ndarray:
        """The table whose greedy actions are the policy: ``Q``, or ``0.5 * (A + B)``.

        Halving is exact in binary floating point, so ``0.5 * (A + B)`` has the greedy
        actions (and ties) of ``A + B``, on which Double Q-learning acts.
        """
        q, q_b = self.tables.q, self.tables.q_b
        return 0.5 * (q + q_b) if q_b.size else q


class Engine(Protocol):
    """Drives an environment around the shared compiled step functions."""

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
