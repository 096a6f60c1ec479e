"""What an environment profile says about an environment, as plain data.

A profile tells the rest of the package what it needs to know about one environment, so
that nothing recognises environments by a table's shape or a class's name: the ids (and
registered entry points) it describes, the names of its observation dimensions and actions,
the physics a config may set and randomise, how a policy map lays out its states, how its
reward threshold follows a changed time limit, and which compiled twin and exact model it
has (by module and by kind, so that this package imports neither numba nor gymnasium).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any

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
    (a grid world's cells), ``blackjack`` (Sutton & Barto's two panels) or ``components``
    (a Discrete state decomposed into :attr:`state_components`)"""
    state_components: tuple[int, ...] = ()
    """with ``components``: the sizes a Discrete state decomposes into, in C order"""
    component_names: tuple[str, ...] = ()
    """with ``components``: a name per component"""
    rows_down: bool = False
    """the first map dimension is a grid world's rows, drawn downwards (Taxi)"""
    grid: Callable[[Any], GridCells] | None = None
    """a grid world's map, read from ``env.unwrapped``: ``(rows, columns, cells, moves)``, with
    a letter per cell (``S`` start, ``F`` free, ``H`` hole, ``C`` cliff, ``G`` goal, ``#``
    wall, ``E`` an end that is not the goal, row by row) and a ``(row step, column step)``
    per action"""
    twin: str | None = None
    """the module of its compiled twin (``cartpole_q.envs.twins.cartpole``), if any"""
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
