"""The run configuration's schema: frozen dataclasses, one docstring per field.

A :class:`Config` is complete (every default filled) and validated when it exists: only
:func:`cartpole_q.config.load_config` makes one, and nothing mutates it afterwards.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any

import yaml

from cartpole_q.rl.schedules import SCHEDULE_KINDS

ENGINES = ("auto", "numba", "gymnasium")
"""``engine`` values"""
MAX_EPISODES = 10_000_000
"""the most episodes a run (or an evaluation) may ask for"""
MAX_SEEDS = 10_000
"""the most seeds one command may run"""
MAX_SEED = 2**32 - 1
"""the largest seed (``seed``, ``eval.seed``, ``--seed``, ``--seeds``)"""
EXACT_INTEGER = 2**53
"""an integer given as a float (``1e6``) must be below this, where floats are exact"""


@dataclass(frozen=True)
class Schedule:
    """A value that may change once per episode (learning rate, exploration rate).

    For episode index ``e`` (0 for the first episode):

    - ``constant``: ``start``;
    - ``exponential``: ``max(end, start * rate ** e)``; the blog's ``epsilon *= 0.995``
      down to 0.01 is ``start=1.0, rate=0.995, end=0.01``;
    - ``log``: ``max(end, min(start, 1 - log10((e + 1) / rate)))`` with ``rate`` the
      constant ``k``; with ``start=1`` this is the classic tabular CartPole schedule.
    """

    kind: str
    """one of ``constant``, ``exponential``, ``log``"""
    start: float
    """the value at the first episode (the cap of the log schedule)"""
    end: float
    """the floor the value never goes below (equals ``start`` for a constant)"""
    rate: float = 1.0
    """the decay factor per episode (exponential) or ``k`` (log); unused for a constant"""

    @property
    def code(self) -> int:
        """The kind as the integer the compiled agent functions take."""
        return SCHEDULE_KINDS.index(self.kind)

    def to_yaml(self) -> float | dict[str, Any]:
        """Return the YAML form: a number for a constant, else a mapping."""
        if self.kind == "constant":
            return self.start
        if self.kind == "exponential":
            return {"type": "exponential", "start": self.start, "decay": self.rate, "end": self.end}
        return {"type": "log", "k": self.rate, "end": self.end, "start": self.start}


@dataclass(frozen=True)
class EnvConfig:
    """Which Gymnasium environment to learn."""

    id: str
    """the id given to ``gymnasium.make``"""
    kwargs: Mapping[str, Any]
    """keyword arguments forwarded to ``gymnasium.make`` (read-only mapping)"""
    physics: Mapping[str, float | str] = field(default_factory=lambda: MappingProxyType({}))
    """attributes set on ``env.unwrapped`` after ``gymnasium.make``: the keys and ranges the
    environment's profile allows (CartPole's, in :mod:`cartpole_q.profiles.cartpole`)"""
    randomize: Mapping[str, tuple[float, float]] = field(
        default_factory=lambda: MappingProxyType({})
    )
    """``[low, high]`` per key the profile lets vary; one uniform draw per key (in the
    profile's order) before every training episode's reset"""


@dataclass(frozen=True)
class DiscretizationConfig:
    """The grid that turns a continuous (Box) observation into a Q-table row.

    Discrete and Tuple-of-Discrete observations need none: they are the row index already
    (``Config.discretization`` is then ``None``).
    """

    bins: tuple[int, ...]
    """bins per observation dimension; a dimension with 1 bin is ignored"""
    low: tuple[float, ...]
    """lower edge of the grid per dimension; values below fall in the first bin"""
    high: tuple[float, ...]
    """upper edge of the grid per dimension; values above fall in the last bin"""


@dataclass(frozen=True)
class AgentConfig:
    """The learning algorithm and its hyperparameters."""

    algorithm: str
    """a registered algorithm's name (:func:`cartpole_q.rl.algorithms.names`)"""
    gamma: float
    """discount factor in [0, 1]"""
    alpha: Schedule
    """learning rate, every value in (0, 1]"""
    epsilon: Schedule
    """exploration rate of the epsilon-greedy policy, every value in [0, 1]"""
    q_init: float
    """initial value of every Q-table entry"""
    max_q_table_bytes: int
    """refuse to allocate a Q-table larger than this many bytes"""
    params: Mapping[str, float | int | str] = field(default_factory=lambda: MappingProxyType({}))
    """the algorithm's own keys (``agent.n``, ``agent.lambda``; see its module in
    :mod:`cartpole_q.rl.algorithms`), every one it declares, defaults filled (read-only)"""


@dataclass(frozen=True)
class TrainConfig:
    """How long to train and what to record on the way."""

    episodes: int
    """number of training episodes (an upper bound when ``stop_when_solved``)"""
    seeds: tuple[int, ...] | None
    """train one run per seed, in parallel; ``None`` trains the single top-level seed"""
    stop_when_solved: bool
    """stop at the first episode whose 100-episode average return reaches the threshold"""
    reward_threshold: float | None
    """the solve threshold; ``None`` takes the environment's registered threshold"""
    eval_every: int
    """run a greedy evaluation every this many episodes; 0 disables it"""
    eval_episodes: int
    """episodes per periodic greedy evaluation"""
    checkpoint_every: int
    """write a resumable checkpoint every this many episodes; 0 disables it"""


@dataclass(frozen=True)
class EvalConfig:
    """The greedy evaluation recorded in ``summary.json`` and used by ``cartpole-q eval``."""

    episodes: int
    """number of greedy episodes"""
    seed: int
    """seed of the evaluation environment's first reset"""


@dataclass(frozen=True)
class Config:
    """A complete, validated run configuration. Never mutated after loading."""

    name: str
    """run-name prefix: letters, digits, '-', '_'"""
    seed: int
    """the run's seed; every random generator of the run is derived from it"""
    engine: str
    """``auto``, ``numba`` or ``gymnasium``"""
    env: EnvConfig
    discretization: DiscretizationConfig | None
    """the binning grid of a Box observation; ``None`` for Discrete and Tuple-of-Discrete
    observations, which index the Q-table directly (when a config gives no grid, CartPole
    takes the embedded default's and every other environment none)"""
    agent: AgentConfig
    train: TrainConfig
    eval: EvalConfig

    def to_dict(self) -> dict[str, Any]:
        """Return the config as plain YAML-ready data, every key present."""
        return {
            "name": self.name,
            "seed": self.seed,
            "engine": self.engine,
            "env": {
                "id": self.env.id,
                "kwargs": _plain(self.env.kwargs),
                "physics": _plain(self.env.physics),
                "randomize": _plain(self.env.randomize),
            },
            "discretization": None
            if self.discretization is None
            else {
                "bins": list(self.discretization.bins),
                "low": list(self.discretization.low),
                "high": list(self.discretization.high),
            },
            "agent": {
                "algorithm": self.agent.algorithm,
                **_plain(self.agent.params),
                "gamma": self.agent.gamma,
                "alpha": self.agent.alpha.to_yaml(),
                "epsilon": self.agent.epsilon.to_yaml(),
                "q_init": self.agent.q_init,
                "max_q_table_bytes": self.agent.max_q_table_bytes,
            },
            "train": {
                "episodes": self.train.episodes,
                "seeds": None if self.train.seeds is None else format_seeds(self.train.seeds),
                "stop_when_solved": self.train.stop_when_solved,
                "reward_threshold": self.train.reward_threshold,
                "eval_every": self.train.eval_every,
                "eval_episodes": self.train.eval_episodes,
                "checkpoint_every": self.train.checkpoint_every,
            },
            "eval": {"episodes": self.eval.episodes, "seed": self.eval.seed},
        }

    def to_yaml(self) -> str:
        """Return the resolved config as YAML; loading it gives back an equal config."""
        # libyaml's emitter when PyYAML has it: the same text, many times faster.
        dumper = getattr(yaml, "CSafeDumper", yaml.SafeDumper)
        return yaml.dump(self.to_dict(), Dumper=dumper, sort_keys=False, default_flow_style=None)

    def for_seed(self, seed: int) -> Config:
        """Return this config as the single run of ``seed`` (no ``train.seeds``)."""
        return dataclasses.replace(
            self, seed=seed, train=dataclasses.replace(self.train, seeds=None)
        )


def format_seeds(seeds: Iterable[int]) -> str:
    """Write seeds compactly: ``(0, 1, 2, 3, 7)`` becomes ``"0-3,7"``.

    >>> format_seeds([0, 1, 2, 3, 7])
    '0-3,7'
    """
    parts: list[str] = []
    ordered = sorted(set(seeds))
    start = previous = None
    for seed in [*ordered, None]:
        if previous is not None and (seed is None or seed != previous + 1):
            parts.append(str(start) if start == previous else f"{start}-{previous}")
            start = seed
        elif start is None:
            start = seed
        previous = seed
    return ",".join(parts)


def _plain(value: Any) -> Any:
    """Turn read-only mappings back into plain dicts for YAML and JSON."""
    if isinstance(value, Mapping):
        return {key: _plain(item) for key, item in value.items()}
    if isinstance(value, list | tuple):
        return [_plain(item) for item in value]
    return value
