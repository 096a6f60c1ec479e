"""Sutton & Barto's worlds as Gymnasium environments, registered under ``cartpole_q/``.

=========================================  ==================================================
id                                         world
=========================================  ==================================================
``cartpole_q/WindyGridworld-v0``           Example 6.5 (:mod:`~cartpole_q.worlds.gridworlds`)
``cartpole_q/KingsWindyGridworld-v0``      Exercise 6.9: king's moves (``stay=True``: a 9th)
``cartpole_q/StochasticWindyGridworld-v0`` Exercise 6.10: king's moves, a varying wind
``cartpole_q/DynaMaze-v0``                 Example 8.1, Figure 8.2
``cartpole_q/BlockingMaze-v0``             Example 8.2, Figure 8.4 (``change_at=1000``)
``cartpole_q/ShortcutMaze-v0``             Example 8.3, Figure 8.5 (``change_at=3000``)
``cartpole_q/MaximizationBias-v0``         Example 6.7, Figure 6.5 (:mod:`~cartpole_q.worlds.bias`)
``cartpole_q/OneState-v0``                 Example 5.5, Figure 5.4 (:mod:`~cartpole_q.worlds.one_state`)
``cartpole_q/RandomWalk5-v0``              Example 6.2: 5 states, 0 and +1 ends (:mod:`~cartpole_q.worlds.random_walk`)
``cartpole_q/RandomWalk-v0``               Example 7.1, Figure 7.2: 19 states, -1 and +1 ends
``cartpole_q/RandomWalk1000-v0``           Example 9.1, Figures 9.1, 9.2: 1000 states, jumps of up to 100 (``groups``: state aggregation)
=========================================  ==================================================

The worlds of dynamic programming (chapters 3-4, ``cartpole-q dp``), :data:`PLANNING_WORLDS`:

=========================================  ==================================================
id                                         world
=========================================  ==================================================
``cartpole_q/Gridworld-v0``                Example 3.5, Figures 3.2, 3.5 (:mod:`~cartpole_q.worlds.planning_grids`)
``cartpole_q/SmallGridworld-v0``           Example 4.1, Figure 4.1: the 4 x 4 gridworld
``cartpole_q/CarRental-v0``                Example 4.2, Figure 4.2 (:mod:`~cartpole_q.worlds.car_rental`)
``cartpole_q/Gambler-v0``                  Example 4.3, Figure 4.3 (:mod:`~cartpole_q.worlds.gambler`)
=========================================  ==================================================

Blackjack dealt one hand or a random state (chapter 5), :data:`BLACKJACK_WORLDS` (a ``Tuple`` observation,
Gymnasium's ``Blackjack-v1`` after the deal; no transition table, a model from the rules):

=========================================  ==================================================
id                                         world
=========================================  ==================================================
``cartpole_q/BlackjackDealt-v0``           Example 5.4, Figure 5.3: 13 with a usable ace against a 2 (:mod:`~cartpole_q.worlds.blackjack_dealt`)
``cartpole_q/BlackjackES-v0``              Example 5.3, Figure 5.2: a uniformly random one of 200 states (exploring starts)
=========================================  ==================================================

The bandit of chapter 2 (``cartpole-q bandit``), :data:`BANDIT_WORLDS`:

=========================================  ==================================================
id                                         world
=========================================  ==================================================
``cartpole_q/Bandit-v0``                   the 10-armed testbed, Figures 2.2-2.6 (:mod:`~cartpole_q.worlds.bandit`)
=========================================  ==================================================

**Registration.** Gymnasium 1.x has no plug-in entry points any more (they were removed
in 1.0), so the ids are registered by this package: importing ``cartpole_q`` (which the
command line does) registers them as soon as Gymnasium is imported, before or after, and
without importing Gymnasium itself (``cartpole-q --help`` stays light). In a fresh
interpreter, ``gymnasium.make("cartpole_q.worlds:cartpole_q/WindyGridworld-v0")`` works
too: Gymnasium imports the module before the ``:``.

**Time limits.** The book gives none; the tool needs episodes to end (a greedy policy can
walk in circles), so each id has a generous one, far above what any episode of the book's
experiments takes: 10,000 steps in the grid worlds, 1,000 in the random walk (a random
walk lasts 100 steps on average and more than 1,000 about once in 170,000 episodes), and
10,000 in the 1000-state walk (83 steps on average; more than 1,000 about once in 2.3
million episodes, more than 2,000 about once in 7 * 10^12). The maximization-bias world
needs none: every episode ends within two steps.
``env.kwargs.max_episode_steps`` changes them.
"""

from __future__ import annotations

import sys
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from types import MappingProxyType, ModuleType
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from importlib.machinery import ModuleSpec

NAMESPACE = "cartpole_q"
"""the Gymnasium namespace of the worlds' ids"""


@dataclass(frozen=True)
class World:
    """One registered world: its id and what ``gymnasium.register`` takes."""

    id: str
    entry_point: str
    """``module:Class``"""
    max_episode_steps: int | None
    """the time limit registered with it"""
    kwargs: Mapping[str, Any] = field(default_factory=lambda: MappingProxyType({}))
    """the ``gymnasium.make`` arguments registered with it"""


_GRIDS = "cartpole_q.worlds.gridworlds"
GRID_TIME_LIMIT = 10_000
"""steps before a grid world's episode is truncated"""
WALK_TIME_LIMIT = 1_000
"""steps before a random walk's episode is truncated"""
JUMPING_WALK_TIME_LIMIT = 10_000
"""steps before an episode of the 1000-state walk is truncated (Figure 9.1 plays 100,000
episodes: with 1,000 steps one of them might be cut)"""

WORLDS: Sequence[World] = (
    World(f"{NAMESPACE}/WindyGridworld-v0", f"{_GRIDS}:WindyGridworldEnv", GRID_TIME_LIMIT),
    World(
        f"{NAMESPACE}/KingsWindyGridworld-v0", f"{_GRIDS}:KingsWindyGridworldEnv", GRID_TIME_LIMIT
    ),
    World(
        f"{NAMESPACE}/StochasticWindyGridworld-v0",
        f"{_GRIDS}:StochasticWindyGridworldEnv",
        GRID_TIME_LIMIT,
    ),
    World(f"{NAMESPACE}/DynaMaze-v0", f"{_GRIDS}:DynaMazeEnv", GRID_TIME_LIMIT),
    World(f"{NAMESPACE}/BlockingMaze-v0", f"{_GRIDS}:BlockingMazeEnv", GRID_TIME_LIMIT),
    World(f"{NAMESPACE}/ShortcutMaze-v0", f"{_GRIDS}:ShortcutMazeEnv", GRID_TIME_LIMIT),
    World(f"{NAMESPACE}/MaximizationBias-v0", "cartpole_q.worlds.bias:MaximizationBiasEnv", None),
    World(f"{NAMESPACE}/OneState-v0", "cartpole_q.worlds.one_state:OneStateEnv", WALK_TIME_LIMIT),
    World(
        f"{NAMESPACE}/RandomWalk5-v0",
        "cartpole_q.worlds.random_walk:RandomWalkEnv",
        WALK_TIME_LIMIT,
        MappingProxyType({"states": 5, "left_reward": 0.0}),
    ),
    World(
        f"{NAMESPACE}/RandomWalk-v0", "cartpole_q.worlds.random_walk:RandomWalkEnv", WALK_TIME_LIMIT
    ),
    World(
        f"{NAMESPACE}/RandomWalk1000-v0",
        "cartpole_q.worlds.random_walk:JumpingWalkEnv",
        JUMPING_WALK_TIME_LIMIT,
    ),
)
"""every world this package registers, with :data:`PLANNING_WORLDS`"""

BLACKJACK_WORLDS: Sequence[World] = (
    World(
        f"{NAMESPACE}/BlackjackDealt-v0",
        "cartpole_q.worlds.blackjack_dealt:BlackjackDealtEnv",
        None,
    ),
    World(
        f"{NAMESPACE}/BlackjackES-v0",
        "cartpole_q.worlds.blackjack_dealt:BlackjackExploringStartsEnv",
        None,
    ),
)
"""Blackjack dealt one hand: every episode ends within a few cards, as Blackjack-v1's"""

PLANNING_TIME_LIMIT = 1_000
"""steps before an episode of the gridworlds or the car rental is truncated (Example 3.5's
gridworld and the car rental never end; the 4 x 4 gridworld's random episodes take some
twenty steps on average)"""

PLANNING_WORLDS: Sequence[World] = (
    World(
        f"{NAMESPACE}/Gridworld-v0",
        "cartpole_q.worlds.planning_grids:GridworldEnv",
        PLANNING_TIME_LIMIT,
    ),
    World(
        f"{NAMESPACE}/SmallGridworld-v0",
        "cartpole_q.worlds.planning_grids:SmallGridworldEnv",
        PLANNING_TIME_LIMIT,
    ),
    World(
        f"{NAMESPACE}/CarRental-v0",
        "cartpole_q.worlds.car_rental:CarRentalEnv",
        PLANNING_TIME_LIMIT,
    ),
    World(f"{NAMESPACE}/Gambler-v0", "cartpole_q.worlds.gambler:GamblerEnv", GRID_TIME_LIMIT),
)
"""the worlds of dynamic programming (chapters 3-4, ``cartpole-q dp``), their models exact;
the gambler's time limit is the grid worlds' 10,000 steps (with stakes of 1 an episode can
be long)"""


BANDIT_TIME_LIMIT = 1_000
"""steps before a bandit's episode is truncated: the book's run length (the testbed never
ends an episode itself; ``cartpole-q bandit`` makes it with its study's ``steps``)"""

BANDIT_WORLDS: Sequence[World] = (
    World(f"{NAMESPACE}/Bandit-v0", "cartpole_q.worlds.bandit:BanditEnv", BANDIT_TIME_LIMIT),
)
"""the k-armed testbed of chapter 2 (``cartpole-q bandit``)"""


def register_worlds() -> None:
    """Register every world with Gymnasium (an id registered already is left as it is)."""
    import gymnasium

    for world in (*WORLDS, *PLANNING_WORLDS, *BLACKJACK_WORLDS, *BANDIT_WORLDS):
        if world.id not in gymnasium.registry:
            gymnasium.register(
                world.id,
                entry_point=world.entry_point,
                max_episode_steps=world.max_episode_steps,
                kwargs=dict(world.kwargs),
            )


def register_when_gymnasium_is_imported() -> None:
    """Register the worlds now if Gymnasium is imported, else right after its import.

    Importing Gymnasium costs a tenth of a second that a command such as ``--help`` need not
    pay; a finder at the head of ``sys.meta_path`` waits for Gymnasium's import instead, and
    registers the worlds when it has run.
    """
    if "gymnasium" in sys.modules:
        register_worlds()
    elif not any(isinstance(finder, _AfterGymnasium) for finder in sys.meta_path):
        sys.meta_path.insert(0, _AfterGymnasium())


class _AfterGymnasium:
    """Finds nothing itself: it makes Gymnasium's own loader register the worlds after it.

    A meta path finder needs only ``find_spec``; ``importlib.util`` is imported when
    Gymnasium is, not when the package is (the command line's start stays light).
    """

    def __init__(self) -> None:
        self._searching = False

    def find_spec(
        self,
        fullname: str,
        path: Sequence[str] | None,
        target: ModuleType | None = None,
    ) -> ModuleSpec | None:
        """Gymnasium's own spec, its loader made to register the worlds after loading it."""
        if fullname != "gymnasium" or self._searching:
            return None
        import importlib.util

        self._searching = True  # the search below asks this finder too
        try:
            spec = importlib.util.find_spec(fullname)
        finally:
            self._searching = False
        if spec is None or spec.loader is None or not hasattr(spec.loader, "exec_module"):
            return spec
        load = spec.loader.exec_module

        def load_then_register(module: ModuleType) -> None:
            load(module)
            if self in sys.meta_path:
                sys.meta_path.remove(self)
            register_worlds()

        # Only this spec's loader is changed, for the one import it makes.
        setattr(spec.loader, "exec_module", load_then_register)  # noqa: B010
        return spec
