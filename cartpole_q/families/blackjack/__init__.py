"""Blackjack: Gymnasium's ``Blackjack-v1``, and the book's Blackjack dealt a hand (chapter 5).

The book's worlds deal one hand every episode, or a random state (exploring starts).

Each has an exact model from the rules (:mod:`~cartpole_q.families.blackjack.model`), so
``cartpole-q optimum`` and ``eval`` compute the best return. ``Blackjack-v1`` has a compiled
twin (:mod:`~cartpole_q.families.blackjack.twin`), and so has the world of exploring starts
(:mod:`~cartpole_q.families.blackjack.es_twin`); the world dealt one hand plays on the
gymnasium engine. The book's two worlds (:mod:`~cartpole_q.families.blackjack.dealt`) are a
``Tuple`` observation, ``Blackjack-v1``'s after the deal: every episode ends within a few
cards, so they have no time limit.
"""

from __future__ import annotations

from types import MappingProxyType

from cartpole_q.families.base import NAMESPACE, EnvProfile, TwinModule, World

_DEALT = "cartpole_q.families.blackjack.dealt"


def load_twin() -> TwinModule:
    """Blackjack-v1's compiled twin, imported when first used (it compiles with numba)."""
    from cartpole_q.families.blackjack import twin

    return twin


def load_es_twin() -> TwinModule:
    """The compiled twin of Blackjack with exploring starts, imported when first used."""
    from cartpole_q.families.blackjack import es_twin

    return es_twin


def stick_on_20(state_shape: tuple[int, ...]) -> list[int]:
    """Sutton & Barto's Example 5.1 policy: stick (0) on a player sum of 20 or 21, else hit (1).

    >>> actions = stick_on_20((32, 11, 2))
    >>> actions[(19 * 11 + 5) * 2 + 1], actions[(20 * 11 + 5) * 2 + 0], len(actions)
    (1, 0, 704)
    """
    per_sum = state_shape[1] * state_shape[2]
    return [0 if row // per_sum >= 20 else 1 for row in range(state_shape[0] * per_sum)]


BLACKJACK = EnvProfile(
    name="Blackjack",
    description="hit or stick against the dealer (Sutton & Barto's Example 5.1)",
    ids=("Blackjack-v1",),
    entry_points=("gymnasium.envs.toy_text.blackjack:BlackjackEnv",),
    observation_names=("player sum", "dealer card", "usable ace"),
    action_names=("stick", "hit"),
    policy_map="blackjack",
    model="blackjack",
    twin=load_twin,
    policies=MappingProxyType({"stick_20": stick_on_20}),
)

BLACKJACK_DEALT = EnvProfile(
    name="BlackjackDealt",
    description="Blackjack dealt one hand every episode, 13 with a usable ace against a 2 "
    "(Sutton & Barto's Example 5.4)",
    ids=("cartpole_q/BlackjackDealt-v0",),
    entry_points=(f"{_DEALT}:BlackjackDealtEnv",),
    observation_names=("player sum", "dealer card", "usable ace"),
    action_names=("stick", "hit"),
    policy_map="blackjack",
    model="blackjack",
    policies=MappingProxyType({"stick_20": stick_on_20}),
)

BLACKJACK_ES = EnvProfile(
    name="BlackjackES",
    description="Blackjack dealt a uniformly random one of its 200 states every episode "
    "(exploring starts, Sutton & Barto's Example 5.3)",
    ids=("cartpole_q/BlackjackES-v0",),
    entry_points=(f"{_DEALT}:BlackjackExploringStartsEnv",),
    observation_names=("player sum", "dealer card", "usable ace"),
    action_names=("stick", "hit"),
    policy_map="blackjack",
    model="blackjack",
    twin=load_es_twin,
    policies=MappingProxyType({"stick_20": stick_on_20}),
)

PROFILES = (BLACKJACK, BLACKJACK_DEALT, BLACKJACK_ES)
"""the family's profiles"""
WORLDS: tuple[World, ...] = (
    World(f"{NAMESPACE}/BlackjackDealt-v0", f"{_DEALT}:BlackjackDealtEnv", None),
    World(f"{NAMESPACE}/BlackjackES-v0", f"{_DEALT}:BlackjackExploringStartsEnv", None),
)
"""the book's two worlds (Example 5.4, Figure 5.3; Example 5.3, Figure 5.2)"""
