"""What an environment family says about its environments, as plain data.

A profile tells the rest of the package what it needs to know about one environment, so
that nothing recognises environments by a table's shape or a class's name: the ids (and
registered entry points) it describes, the names of its observation dimensions and actions,
the physics a config may set and randomise, how a policy map lays out its states, how its
reward threshold follows a changed time limit, and which compiled twin and exact model it
has (a function that loads the twin, and a kind of model, so that describing an environment
imports neither numba nor Gymnasium). Here too: :class:`World`, a world a family registers
with Gymnasium, and :class:`TwinModule`, the interface every twin module meets.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any, Protocol

GridCells = tuple[int, int, tuple[str, ...], tuple[tuple[int, int], ...]]
"""a grid world's map: rows, columns, a letter per cell, a move per action"""


@dataclass(frozen=True)
class PhysicsRange:
    """The values one physics key may take."""

    low: float
    high: float
    low_open: bool = False
    """``low`` itself is excluded"""

    @property
    def interval(self) -> str:
        """``[0, 1000]`` or ``(0, 1]``."""
        return f"{'(' if self.low_open else '['}{self.low:g}, {self.high:g}]"


@dataclass(frozen=True)
class Physics:
    """The attributes of an environment a config may set (``env.physics``) and randomise."""

    ranges: Mapping[str, PhysicsRange]
    """numeric keys, in canonical order, and their ranges"""
    choices: Mapping[str, tuple[str, ...]] = field(default_factory=lambda: MappingProxyType({}))
    """keys that take one of some strings (CartPole's integrator)"""
    randomizable: tuple[str, ...] = ()
    """the keys ``env.randomize`` may draw, in the order of the draws"""
    defaults: Mapping[str, float] = field(default_factory=lambda: MappingProxyType({}))
    """the environment's own values (figures mark them)"""
    apply: Callable[[Any, Mapping[str, Any]], None] | None = None
    """set values on ``env.unwrapped``, derived values recomputed"""
    notes: str = ""
    """why the ranges are what they are (the README's table)"""

    @property
    def keys(self) -> tuple[str, ...]:
        """Every settable key, in canonical order (numeric ones, then the choices)."""
        return (*self.ranges, *self.choices)


@dataclass(frozen=True)
class EnvProfile:
    """One supported environment (or family of them) as the package sees it."""

    name: str
    """a short name (``CartPole``)"""
    ids: tuple[str, ...]
    """the Gymnasium ids it describes"""
    entry_points: tuple[str, ...] = ()
    """the registered entry points it describes too (an id registered with one of them,
    under any name, is this environment)"""
    observation_names: tuple[str, ...] = ()
    """one name per observation dimension (or Discrete component), for figures"""
    action_names: tuple[str, ...] = ()
    """what each action does, for figures"""
    physics: Physics | None = None
    """what ``env.physics`` and ``env.randomize`` may set (``None``: nothing)"""
    default_grid: bool = False
    """a config that gives no ``discretization`` takes the embedded default's grid"""
    threshold_scales: bool = False
    """a changed time limit scales the registered reward threshold (CartPole: 475 of 500
    steps becomes 950 of 1000)"""
    policy_map: str = "binned"
    """how ``plot --policy`` lays out states: ``binned`` (two dimensions of the grid), ``grid``
    (a grid world's cells), ``blackjack`` (Sutton & Barto's two panels), ``components``
    (a Discrete state decomposed into :attr:`state_components`) or ``racetrack`` (a
    study's ``figure.metric: policy`` draws trajectories on the track)"""
    state_components: tuple[int, ...] = ()
    """with ``components``: the sizes a Discrete state decomposes into, in C order"""
    component_names: tuple[str, ...] = ()
    """with ``components``: a name per component"""
    component_values: tuple[tuple[str, ...], ...] = ()
    """with ``components``: what each value of each component means, for figures (empty:
    the values 0, 1, 2, ...)"""
    average_reward: bool = False
    """a continuing world whose objective is the reward per step (Sutton & Barto section
    10.3): ``cartpole-q optimum`` gives its optimal gain by relative value iteration"""
    rows_down: bool = False
    """the first map dimension is a grid world's rows, drawn downwards (Taxi)"""
    grid: Callable[[Any], GridCells] | None = None
    """a grid world's map, read from ``env.unwrapped``: ``(rows, columns, cells, moves)``, with
    a letter per cell (``S`` start, ``F`` free, ``H`` hole, ``C`` cliff, ``G`` goal, ``#``
    wall, ``E`` an end that is not the goal, row by row) and a ``(row step, column step)``
    per action"""
    twin: Callable[[], TwinModule] | str | None = None
    """its compiled twin, if any: a function that imports and returns the twin's module
    (``load_twin`` in each of the package's families: the import is one that mypy and the
    layer contracts see), or a plug-in's module name, imported when the twin is first used"""
    model: str | None = None
    """its exact model for value iteration: ``transition_table`` (``env.unwrapped.P``) or
    ``blackjack`` (from the rules), if any"""
    description: str = ""
    """one line for the documentation"""
    policies: Mapping[str, Callable[[tuple[int, ...]], list[int]]] = field(
        default_factory=lambda: MappingProxyType({})
    )
    """named deterministic policies a prediction run may evaluate (``agent.policy``): from
    the table's state shape, the action of every table row in C order"""

    def names_observations(self, count: int) -> list[str]:
        """Axis names for ``count`` dimensions (``observation N`` when they do not fit).

        >>> EnvProfile("x", ("x-v0",), observation_names=("a", "b")).names_observations(3)
        ['observation 0', 'observation 1', 'observation 2']
        """
        if len(self.observation_names) == count:
            return list(self.observation_names)
        return [f"observation {d}" for d in range(count)]

    def names_actions(self, count: int) -> list[str] | None:
        """What each of ``count`` actions does, or ``None`` when the profile does not say."""
        return list(self.action_names) if len(self.action_names) == count else None


UNKNOWN = EnvProfile("unknown", ())
"""the profile of an environment no profile describes: nothing known beyond its spaces"""


NAMESPACE = "cartpole_q"
"""the Gymnasium namespace of the package's own worlds' ids"""


@dataclass(frozen=True)
class World:
    """One world the package registers with Gymnasium: its id and what ``register`` takes."""

    id: str
    entry_point: str
    """``module:Class``"""
    max_episode_steps: int | None
    """the time limit registered with it"""
    kwargs: Mapping[str, Any] = field(default_factory=lambda: MappingProxyType({}))
    """the ``gymnasium.make`` arguments registered with it"""


class TwinModule(Protocol):
    """A compiled twin's module: compiled twins of Gymnasium environments, bit-identical to them.

    Each module defines:

    - ``STATE_SIZE`` and ``STATE_DTYPE``: the twin's state, an array the compiled loop
      allocates (float64 for the classic-control twins, int64 for the tabular ones);
    - ``OBSERVATION_SIZE``, ``OBSERVATION_DTYPE`` and ``OBSERVATION_KIND``: the array ``reset``
      and ``step`` write the observation into, and how it becomes a Q-table row (``box``: the
      binning rule on float32 values; ``discrete``: one integer; ``tuple``: one integer per
      ``Discrete`` component; see :mod:`cartpole_q.engines.rows`);
    - the compiled ``reset(state, observation, rng, params)`` and
      ``step(state, action, observation, rng, params) -> (reward, terminated)``, where ``rng``
      is the environment's generator (``env.np_random``), from which they draw exactly what
      Gymnasium draws, in the same order (the classic-control steps draw nothing);
    - the plain function ``twin_params`` that turns ``gymnasium.make`` arguments into
      ``params`` (a tuple, of floats or of arrays), or says which one the twin cannot
      reproduce: ``twin_params(kwargs)`` (CartPole's also takes ``env.physics``), or, with
      ``READS_ENVIRONMENT = True``, ``twin_params(kwargs, env_id)``, which reads what it needs
      from the environment ``gymnasium.make(env_id, **kwargs)`` builds (a transition table).

    The environments a twin reproduces are the ids of the profiles that name it.

    Each family's ``load_twin`` returns its module typed as this, so mypy checks that the
    module meets it. The names are a module's, read-only here as a module's constants are to
    its readers; ``reset`` and ``step`` are numba dispatchers (``Any`` to mypy).
    """

    @property
    def STATE_SIZE(self) -> int:
        """The state array's length."""
        ...

    @property
    def STATE_DTYPE(self) -> Any:
        """The state array's NumPy type."""
        ...

    @property
    def OBSERVATION_SIZE(self) -> int:
        """The observation array's length."""
        ...

    @property
    def OBSERVATION_DTYPE(self) -> Any:
        """The observation array's NumPy type."""
        ...

    @property
    def OBSERVATION_KIND(self) -> str:
        """How an observation becomes a row: box, discrete or tuple."""
        ...

    @property
    def READS_ENVIRONMENT(self) -> bool:
        """``twin_params(kwargs, env_id)`` reads the environment it builds."""
        ...

    @property
    def PARAM_NAMES(self) -> tuple[str, ...]:
        """What ``params`` holds, in order."""
        ...

    @property
    def reset(self) -> Any:
        """The compiled ``reset(state, observation, rng, params)``."""
        ...

    @property
    def step(self) -> Any:
        """The compiled ``step(state, action, observation, rng, params) -> (reward, terminated)``."""
        ...

    @property
    def twin_params(self) -> Callable[..., tuple[Any, ...] | str]:
        """``params`` from ``gymnasium.make`` arguments, or why not."""
        ...


def unsupported_key(kwargs: Mapping[str, Any], supported: Iterable[str]) -> str | None:
    """A sentence naming the first key of ``kwargs`` a twin does not reproduce, or ``None``."""
    supported = tuple(supported)
    for key in kwargs:
        if key not in supported:
            return (
                f"env.kwargs key {key!r} is not reproduced by the compiled twin "
                f"(it supports {', '.join(supported)})"
            )
    return None
