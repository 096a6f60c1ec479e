"""Sutton & Barto's worlds as Gymnasium environments, registered under ``cartpole_q/``.

=========================================  ==================================================
id                                         world
=========================================  ==================================================
``cartpole_q/WindyGridworld-v0``           Example 6.5 (:mod:`~cartpole_q.families.gridworlds`)
``cartpole_q/KingsWindyGridworld-v0``      Exercise 6.9: king's moves (``stay=True``: a 9th)
``cartpole_q/StochasticWindyGridworld-v0`` Exercise 6.10: king's moves, a varying wind
``cartpole_q/DynaMaze-v0``                 Example 8.1, Figure 8.2
``cartpole_q/BlockingMaze-v0``             Example 8.2, Figure 8.4 (``change_at=1000``)
``cartpole_q/ShortcutMaze-v0``             Example 8.3, Figure 8.5 (``change_at=3000``)
``cartpole_q/MaximizationBias-v0``         Example 6.7, Figure 6.5 (:mod:`~cartpole_q.families.book_mdps`)
``cartpole_q/OneState-v0``                 Example 5.5, Figure 5.4 (:mod:`~cartpole_q.families.book_mdps`)
``cartpole_q/DrivingHome-v0``              Example 6.1, Figure 6.1: driving home, six situations in a row
``cartpole_q/Baird-v0``                    Example 11.1, Figures 11.2, 11.5, 11.6: Baird's counterexample (continuing)
``cartpole_q/ShortCorridor-v0``            Example 13.1, Figures 13.1, 13.2: the short corridor with switched actions
``cartpole_q/RandomWalk5-v0``              Example 6.2: 5 states, 0 and +1 ends (:mod:`~cartpole_q.families.walks`)
``cartpole_q/RandomWalk-v0``               Example 7.1, Figure 7.2: 19 states, -1 and +1 ends
``cartpole_q/RandomWalk1000-v0``           Example 9.1, Figures 9.1, 9.2: 1000 states, jumps of up to 100 (``groups``: state aggregation)
``cartpole_q/PuddleWorld-v0``              Figure 12.14: the puddle world, a point in the unit square (:mod:`~cartpole_q.families.puddle`)
=========================================  ==================================================

The worlds of dynamic programming (chapters 3-4, ``cartpole-q dp``):

=========================================  ==================================================
id                                         world
=========================================  ==================================================
``cartpole_q/Gridworld-v0``                Example 3.5, Figures 3.2, 3.5 (:mod:`~cartpole_q.families.planning`)
``cartpole_q/SmallGridworld-v0``           Example 4.1, Figure 4.1: the 4 x 4 gridworld
``cartpole_q/CarRental-v0``                Example 4.2, Figure 4.2 (:mod:`~cartpole_q.families.planning`)
``cartpole_q/Gambler-v0``                  Example 4.3, Figure 4.3 (:mod:`~cartpole_q.families.planning`)
=========================================  ==================================================

Blackjack dealt one hand or a random state (chapter 5) (a ``Tuple`` observation,
Gymnasium's ``Blackjack-v1`` after the deal; no transition table, a model from the rules):

=========================================  ==================================================
id                                         world
=========================================  ==================================================
``cartpole_q/BlackjackDealt-v0``           Example 5.4, Figure 5.3: 13 with a usable ace against a 2 (:mod:`~cartpole_q.families.blackjack`)
``cartpole_q/BlackjackES-v0``              Example 5.3, Figure 5.2: a uniformly random one of 200 states (exploring starts)
=========================================  ==================================================

The bandit of chapter 2 (``cartpole-q bandit``):

=========================================  ==================================================
id                                         world
=========================================  ==================================================
``cartpole_q/Bandit-v0``                   the 10-armed testbed, Figures 2.2-2.6 (:mod:`~cartpole_q.families.bandit`)
=========================================  ==================================================

**Registration.** Gymnasium 1.x has no plug-in entry points any more (they were removed
in 1.0), so the ids are registered by this package: importing ``cartpole_q`` (which the
command line does) registers them as soon as Gymnasium is imported, before or after, and
without importing Gymnasium itself (``cartpole-q --help`` stays light). In a fresh
interpreter, ``gymnasium.make("cartpole_q:cartpole_q/WindyGridworld-v0")`` works too:
Gymnasium imports the module before the ``:`` (``cartpole_q.worlds``, the worlds' module
before the families, still works: its ids are recorded in older run directories).

**Time limits.** The book gives none; the tool needs episodes to end (a greedy policy can
walk in circles), so each id has a generous one, far above what any episode of the book's
experiments takes, set by its family: 10,000 steps in the grid worlds, 1,000 in the random
walk (a random walk lasts 100 steps on average and more than 1,000 about once in 170,000
episodes), and 10,000 in the 1000-state walk (83 steps on average; more than 1,000 about
once in 2.3 million episodes, more than 2,000 about once in 7 * 10^12). The
maximization-bias world needs none: every episode ends within two steps.
``env.kwargs.max_episode_steps`` changes them.
"""

from __future__ import annotations

import sys
from collections.abc import Sequence
from types import ModuleType
from typing import TYPE_CHECKING

from cartpole_q.families import all_worlds

if TYPE_CHECKING:
    from importlib.machinery import ModuleSpec


def register_worlds() -> None:
    """Register every world with Gymnasium (an id registered already is left as it is)."""
    import gymnasium

    for world in all_worlds():
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
