"""The run configuration's schema: frozen dataclasses whose fields carry their own metadata.

A :class:`Config` is complete (every default filled) and validated when it exists: only
:func:`cartpole_q.config.load_config` makes one, and nothing mutates it afterwards.

Every field of :class:`Config` and its sections carries a :class:`Key` (written with
:func:`spec`): the kind of value it takes, its range or choices, and its line in the README's
config reference. Validation, :meth:`Config.to_dict`, the unknown-key check, merging and the
README's table all walk these fields, so a new config key is a field here and a value in
``default.yaml``. The dataclasses' field order is the order of a config file.
"""

from __future__ import annotations

import dataclasses
import functools
import typing
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any, Literal

import yaml

from cartpole_q.rl.algorithm import Param
from cartpole_q.rl.schedules import STEP_SIZE_KINDS
from cartpole_q.rl.tabular import TIE_BREAKS
from cartpole_q.rl.tiles import tile_shape

SAMPLE_AVERAGE_KIND = STEP_SIZE_KINDS[-1]
"""``agent.alpha: sample_average``: the step size of an update is ``1 / N``, not a schedule's"""

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

Kind = Literal[
    "name", "str", "int", "float", "bool", "choice", "algorithm", "schedule", "seeds",
    "bins", "floats", "kwargs", "physics", "randomize", "params", "section", "info_key",
]  # fmt: skip
"""What a config key's value is (see :attr:`Key.kind`)."""


@dataclass(frozen=True)
class Key:
    """A config key's metadata: how it is read, written back and documented.

    The names ``kind``, ``low``, ``high``, ``low_open`` and ``choices`` mean what they mean
    on an algorithm's :class:`~cartpole_q.rl.algorithm.Param`, so that one reader checks
    both.
    """

    kind: Kind
    """the value: ``name`` (a run name), ``str``, ``int``, ``float``, ``bool``, ``choice``,
    ``algorithm`` (a registered one), ``schedule``, ``seeds``, ``bins`` (positive integers),
    ``floats`` (finite numbers), ``kwargs`` (``gymnasium.make``'s), ``physics`` and
    ``randomize`` (checked against the environment's profile), ``params`` (the algorithm's
    own keys, which stand in the section itself), ``section`` (a mapping of keys) or
    ``info_key`` (a key of the environment's ``info``: letters, digits and ``_``)"""
    doc: str
    """its line in the README's config reference (Markdown); ``{interval}`` and
    ``{choices}`` are replaced by the range and the choices below; empty: no line (a
    section whose keys have theirs)"""
    low: float | None = None
    """the smallest value (``None``: no bound)"""
    high: float | None = None
    """the largest value (``None``: no bound)"""
    low_open: bool = False
    """``low`` itself is excluded"""
    choices: tuple[str, ...] = ()
    """the values of a ``choice``"""
    nullable: bool = False
    """``null`` is a value of its own: the single top-level seed, the environment's
    threshold, no grid"""
    sample_average: bool = False
    """a ``schedule`` that may also be ``sample_average`` (a step size per update, not per
    episode: ``agent.alpha``)"""

    @property
    def interval(self) -> str:
        """The accepted values as messages and the README write them: ``(0, 1]``."""
        return Param(
            "", 0, "", kind=self.kind, low=self.low, high=self.high, low_open=self.low_open,
            choices=self.choices,
        ).interval  # fmt: skip


_KEY = "cartpole_q.key"
"""where a field's metadata holds its :class:`Key`"""


def spec(
    kind: Kind,
    doc: str,
    *,
    low: float | None = None,
    high: float | None = None,
    low_open: bool = False,
    choices: tuple[str, ...] = (),
    nullable: bool = False,
    sample_average: bool = False,
) -> dict[str, Key]:
    """A field's metadata: ``field(metadata=spec("float", "discount", low=0.0, high=1.0))``."""
    return {_KEY: Key(kind, doc, low, high, low_open, choices, nullable, sample_average)}


def key_of(item: dataclasses.Field[Any]) -> Key:
    """The :class:`Key` a dataclass field carries."""
    key: Key = item.metadata[_KEY]
    return key


@dataclass(frozen=True)
class Schedule:
    """A value that may change once per episode (learning rate, exploration rate).

    For episode index ``e`` (0 for the first episode):

    - ``constant``: ``start``;
    - ``exponential``: ``max(end, start * rate ** e)``; the blog's ``epsilon *= 0.995``
      down to 0.01 is ``start=1.0, rate=0.995, end=0.01``;
    - ``log``: ``max(end, min(start, 1 - log10((e + 1) / rate)))`` with ``rate`` the
      constant ``k``; with ``start=1`` this is the classic tabular CartPole schedule;
    - ``sample_average`` (``agent.alpha`` only): no value per episode; each update of a
      table entry moves it by ``1 / N``, ``N`` the entry's update count (``start``, ``end``
      0, unused).
    """

    kind: str
    """one of ``constant``, ``exponential``, ``log`` (or ``sample_average``)"""
    start: float
    """the value at the first episode (the cap of the log schedule)"""
    end: float
    """the floor the value never goes below (equals ``start`` for a constant)"""
    rate: float = 1.0
    """the decay factor per episode (exponential) or ``k`` (log); unused for a constant"""

    @property
    def code(self) -> int:
        """The kind as the integer the compiled agent functions take."""
        return STEP_SIZE_KINDS.index(self.kind)

    @property
    def averages(self) -> bool:
        """Whether this is ``sample_average``, a step size per update (``agent.alpha``)."""
        return self.kind == SAMPLE_AVERAGE_KIND

    def to_yaml(self) -> float | str | dict[str, Any]:
        """Return the YAML form: a number, ``sample_average``, or a schedule's mapping."""
        if self.kind == "constant":
            return self.start
        if self.averages:
            return SAMPLE_AVERAGE_KIND
        form = SCHEDULE_FORMS[self.kind]
        return {"type": self.kind, **{key.name: getattr(self, key.field) for key in form}}


@dataclass(frozen=True)
class ScheduleKey:
    """A key of a schedule mapping: its YAML name and the :class:`Schedule` field it sets."""

    name: str
    """the key in YAML (``decay``, ``k``)"""
    field: str
    """the :class:`Schedule` field it sets"""
    bounds: Key | None = None
    """its range; ``None``: the range of the schedule's own key (``agent.alpha``'s)"""
    default: float | None = None
    """the value when it is left out; ``None``: it is required"""


SCHEDULE_FORMS: Mapping[str, tuple[ScheduleKey, ...]] = MappingProxyType({
    "constant": (ScheduleKey("value", "start"),),
    "exponential": (
        ScheduleKey("start", "start"),
        ScheduleKey("decay", "rate", Key("float", "", low=0.0, high=1.0, low_open=True)),
        ScheduleKey("end", "end"),
    ),
    "log": (
        ScheduleKey("k", "rate", Key("float", "", low=0.0, low_open=True)),
        ScheduleKey("end", "end"),
        ScheduleKey("start", "start", default=1.0),
    ),
})  # fmt: skip
"""the keys of each schedule mapping after its ``type``, in the order files write them
(a number is a constant, too)"""


@dataclass(frozen=True)
class EnvConfig:
    """Which Gymnasium environment to learn."""

    id: str = field(
        metadata=spec(
            "str",
            "any Gymnasium environment with `Discrete` actions and a 1-D `Box` observation "
            "(binned), a `Discrete` or a `Tuple` of `Discrete` observations (the Q-table's "
            "index); a registered id with its version (`CartPole-v1`, not `CartPole`), checked "
            "before anything is made. `package:Name-v0` (Gymnasium's syntax) imports `package`, "
            "which registers `Name-v0`: importing runs that package's code, so it is done for "
            "a config you give (`train`, `sweep`, `tune`), never for one read back from a run "
            "or sweep directory (`eval`, `plot`, `compare`, `robustness` refuse it)",
        )
    )
    kwargs: Mapping[str, Any] = field(
        metadata=spec(
            "kwargs",
            "passed to `gymnasium.make`, e.g. `sutton_barto_reward: true`, "
            "`max_episode_steps: 200` (a positive whole number); whatever the environment "
            "refuses is an error naming the key. `render_mode` is refused: training never "
            "renders (`eval --render`, `eval --video FILE.gif`, `train --watch N` draw)",
        )
    )
    physics: Mapping[str, float | str] = field(
        default_factory=lambda: MappingProxyType({}),
        metadata=spec(
            "physics",
            "attributes set on `env.unwrapped` after `gymnasium.make`, the values derived "
            "from them recomputed as the environment's `__init__` does (CartPole's "
            "`total_mass` and `polemass_length`); the compiled twin takes the same values "
            "and stays bit-identical. The keys and ranges each environment's profile allows:",
        ),
    )
    randomize: Mapping[str, tuple[float, float]] = field(
        default_factory=lambda: MappingProxyType({}),
        metadata=spec(
            "randomize",
            "`{key: [low, high]}`: before every training episode one `uniform(low, high)` "
            "per key, in the profile's order, from the run's third random generator; "
            "evaluations use `env.physics`. The keys each environment's profile lets vary:",
        ),
    )


@dataclass(frozen=True)
class DiscretizationConfig:
    """The grid that turns a continuous (Box) observation into a Q-table row.

    Discrete and Tuple-of-Discrete observations need none: they are the row index already
    (``Config.discretization`` is then ``None``).
    """

    bins: tuple[int, ...] = field(
        metadata=spec("bins", "bins per observation dimension (1 ignores the dimension)")
    )
    low: tuple[float, ...] = field(
        metadata=spec("floats", "the grid's lower edges; values below fall in the first bin")
    )
    high: tuple[float, ...] = field(
        metadata=spec("floats", "the grid's upper edges; values above fall in the last bin")
    )
    tilings: int = field(
        metadata=spec(
            "int",
            "tile coding: this many grids, each shifted by a fraction of a bin, whose values "
            'are summed (1: one plain grid, the binning rule; docs/algorithms.md, "Tile '
            'coding")',
            low=1,
            high=64,
        )
    )

    @property
    def table_shape(self) -> tuple[int, ...]:
        """The Q-table's shape without the action axis: the bins, or on tiles ``(T, *sizes)``.

        >>> DiscretizationConfig((1, 6), (0.0, 0.0), (1.0, 1.0), tilings=4).table_shape
        (4, 1, 7)
        """
        return tile_shape(self.bins, self.tilings) if self.tilings > 1 else self.bins


@dataclass(frozen=True)
class AgentConfig:
    """The learning algorithm and its hyperparameters."""

    algorithm: str = field(
        metadata=spec(
            "algorithm",
            "{choices} (each stated precisely in docs/algorithms.md: target, order "
            "of work, random draws)",
        )
    )
    # Declared second since files write an algorithm's own keys right after its name;
    # keyword-only so that it may keep a default before the fields without one.
    params: Mapping[str, float | int | str] = field(
        default_factory=lambda: MappingProxyType({}),
        kw_only=True,
        metadata=spec(
            "params",
            "the algorithm's own keys (`agent.n`, `agent.lambda`), every one it declares, "
            "defaults filled (a read-only mapping; see its module in `cartpole_q.rl.algorithms`)",
        ),
    )
    gamma: float = field(metadata=spec("float", "discount, in {interval}", low=0.0, high=1.0))
    alpha: Schedule = field(
        metadata=spec(
            "schedule",
            "learning rate in {interval}: a number, a schedule, or `sample_average` (every "
            "update of a table entry moves it by `1 / N`, `N` the entry's update count: the "
            'average of its targets; docs/algorithms.md, "Sample averages")',
            low=0.0,
            high=1.0,
            low_open=True,
            sample_average=True,
        )
    )
    epsilon: Schedule = field(
        metadata=spec(
            "schedule",
            "exploration rate of the epsilon-greedy policy in {interval}: a number, or a schedule",
            low=0.0,
            high=1.0,
        )
    )
    q_init: float = field(
        metadata=spec("float", "initial value of every Q-table entry (optimistic values explore)")
    )
    max_q_table_bytes: int = field(
        metadata=spec(
            "int", "refuse a Q-table larger than this many bytes, before allocating it", low=1
        )
    )
    tie_break: str = field(
        metadata=spec(
            "choice",
            "{choices}: which of equally valued best actions epsilon-greedy exploits: the "
            "lowest (design.md), or one drawn at random, as Sutton & Barto's figures do "
            "(docs/algorithms.md)",
            choices=TIE_BREAKS,
        )
    )
    initial_values: tuple[float, ...] | None = field(
        default=None,
        metadata=spec(
            "floats",
            "a prediction run's initial V, one number per state (per row of the table, in "
            "the order of the observations; a terminal state's value is never read): Sutton "
            "& Barto Example 6.1's predictions; `null`: every state starts at `agent.q_init`. "
            "Not on tiles",
            nullable=True,
        ),
    )


@dataclass(frozen=True)
class TrainConfig:
    """How long to train and what to record on the way."""

    episodes: int = field(
        metadata=spec(
            "int",
            "training episodes (an upper bound when `stop_when_solved`)",
            low=1,
            high=MAX_EPISODES,
        )
    )
    seeds: tuple[int, ...] | None = field(
        metadata=spec(
            "seeds",
            'e.g. `"0-99"` or `[0, 1, 2]`: one run per seed, in parallel (each seed once); '
            "`null` trains the single `seed`",
            nullable=True,
        )
    )
    stop_when_solved: bool = field(
        metadata=spec(
            "bool",
            "stop at the first episode whose 100-episode average return reaches the "
            "threshold; either way the table kept is the one from the solve point",
        )
    )
    reward_threshold: float | None = field(
        metadata=spec(
            "float",
            "the solve threshold; `null` takes the environment's (475 for CartPole-v1), for "
            "CartPole scaled with a changed time limit: `env.kwargs.max_episode_steps: 1000` "
            "makes it 475 × 1000 / 500 = 950",  # noqa: RUF001 (the README's sign)
            nullable=True,
        )
    )
    eval_every: int = field(
        metadata=spec(
            "int", "a greedy evaluation every this many training episodes (0: never)", low=0
        )
    )
    eval_episodes: int = field(
        metadata=spec(
            "int", "episodes per greedy evaluation during training", low=1, high=MAX_EPISODES
        )
    )
    checkpoint_every: int = field(
        metadata=spec("int", "a resumable checkpoint every this many episodes (0: never)", low=0)
    )
    tensorboard: bool = field(
        metadata=spec(
            "bool",
            "also write TensorBoard event files into the run directory's `tensorboard/` "
            "(`train --tensorboard`; needs the `[tensorboard]` extra); results are unchanged",
        )
    )
    info_metric: str | None = field(
        default=None,
        metadata=spec(
            "info_key",
            "a key of the environment's step `info` (letters, digits, `_`): its per-step "
            "values (bool or number) are summed per episode and kept as the column "
            "`info_KEY` of `metrics.csv` (and of checkpoints and sweeps' `curves.npz`), "
            "drawn with `plot --metric info:KEY`; only the gymnasium engine sees `info`: "
            "`engine: auto` takes it, `engine: numba` is refused; `null`: none",
            nullable=True,
        ),
    )
    max_env_steps: int | None = field(
        default=None,
        metadata=spec(
            "int",
            "stop training after this many env steps in all (`null`: no limit; "
            "`train.episodes` still bounds the run): the episode that reaches it is cut "
            "there, as a time limit cuts it, and is the run's last (Sutton & Barto Figure "
            "8.3: halfway through the second episode)",
            low=1,
            nullable=True,
        ),
    )


@dataclass(frozen=True)
class EvalConfig:
    """The greedy evaluation recorded in ``summary.json`` and used by ``cartpole-q eval``."""

    episodes: int = field(
        metadata=spec(
            "int",
            "episodes of the final greedy evaluation (and `cartpole-q eval`'s default)",
            low=1,
            high=MAX_EPISODES,
        )
    )
    seed: int = field(
        metadata=spec(
            "int",
            "seed of the final evaluation's first reset (and `cartpole-q eval`'s default)",
            low=0,
            high=MAX_SEED,
        )
    )


@dataclass(frozen=True)
class Config:
    """A complete, validated run configuration. Never mutated after loading."""

    name: str = field(
        metadata=spec(
            "name",
            "run-name prefix: letters, digits, `-`, `_`; left out with another `env.id`, "
            "made from it (`frozenlake` for `FrozenLake-v1`)",
        )
    )
    seed: int = field(
        metadata=spec(
            "int",
            "the run's seed, 0 to 2^32 - 1; every random generator of the run derives from it",
            low=0,
            high=MAX_SEED,
        )
    )
    engine: str = field(
        metadata=spec(
            "choice",
            "{choices}; `auto` is `numba` where the environment has a compiled twin",
            choices=ENGINES,
        )
    )
    env: EnvConfig = field(metadata=spec("section", ""))
    discretization: DiscretizationConfig | None = field(
        metadata=spec(
            "section",
            "the binning grid, for `Box` observations only. Left out, CartPole takes the "
            "default's grid and every other environment none; `Discrete(n, start)` and "
            "`Tuple` observations need none (`config.yaml` says `discretization: null`; "
            "giving one is an error naming the reason), a `Box` without one is an error",
            nullable=True,
        )
    )
    agent: AgentConfig = field(metadata=spec("section", ""))
    train: TrainConfig = field(metadata=spec("section", ""))
    eval: EvalConfig = field(metadata=spec("section", ""))

    def to_dict(self) -> dict[str, Any]:
        """Return the config as plain YAML-ready data, every key present."""
        return _yaml_fields(self)

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


@functools.cache
def sections() -> Mapping[str, type]:
    """The sections of a config file, in file order, and the dataclass each is read into.

    >>> list(sections())
    ['env', 'discretization', 'agent', 'train', 'eval']
    """
    hints = typing.get_type_hints(Config)
    found: dict[str, type] = {}
    for item in dataclasses.fields(Config):
        if key_of(item).kind == "section":
            # `DiscretizationConfig | None`: the dataclass among the union's members.
            members = typing.get_args(hints[item.name]) or (hints[item.name],)
            found[item.name] = next(
                m for m in members if isinstance(m, type) and dataclasses.is_dataclass(m)
            )
    return MappingProxyType(found)


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


def _yaml_fields(record: Any) -> dict[str, Any]:
    """A section (or the whole config) as YAML data, its keys in field order."""
    data: dict[str, Any] = {}
    for item in dataclasses.fields(record):
        value = getattr(record, item.name)
        kind = key_of(item).kind
        if kind == "params":
            data.update(_plain(value))  # the algorithm's own keys stand in the section
        elif value is None:
            data[item.name] = None
        elif kind == "section":
            data[item.name] = _yaml_fields(value)
        elif kind == "schedule":
            data[item.name] = value.to_yaml()
        elif kind == "seeds":
            data[item.name] = format_seeds(value)
        else:
            data[item.name] = _plain(value)
    return data


def _plain(value: Any) -> Any:
    """Turn read-only mappings and tuples back into plain dicts and lists for YAML and JSON."""
    if isinstance(value, Mapping):
        return {key: _plain(item) for key, item in value.items()}
    if isinstance(value, list | tuple):
        return [_plain(item) for item in value]
    return value
