"""What the worlds that move by a transition table share: their base class and their twins.

- :mod:`~cartpole_q.families.tables.world`: :class:`~cartpole_q.families.tables.world.TableWorld`,
  a Gymnasium environment played from its table ``P``, as the toy-text worlds are;
- :mod:`~cartpole_q.families.tables.twin`: the compiled twin of any world that keeps those
  promises (FrozenLake, CliffWalking, the book's grid worlds and walks);
- :mod:`~cartpole_q.families.tables.aggregated_twin`: the same, observed in groups of states.

A new world with a transition table is a ``TableWorld`` subclass that builds ``P``, a
:class:`~cartpole_q.families.base.World` that registers it and a profile whose ``twin`` is
:func:`load_twin` (the tutorial "Add a world" shows the few lines).
"""

from __future__ import annotations

from cartpole_q.families.base import TwinModule


def load_twin() -> TwinModule:
    """The twin of any world played from its transition table, imported when first used."""
    from cartpole_q.families.tables import twin

    return twin


def load_aggregated_twin() -> TwinModule:
    """The twin of a table world observed in groups of states, imported when first used."""
    from cartpole_q.families.tables import aggregated_twin

    return aggregated_twin
