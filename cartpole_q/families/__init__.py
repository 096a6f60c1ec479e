"""The environment families, and the registry of their profiles.

A family is one package holding everything the tool knows about some environments: their
profiles (:class:`~cartpole_q.families.base.EnvProfile`: names, physics, maps, exact model,
twin), the worlds it registers with Gymnasium (:class:`~cartpole_q.families.base.World`),
their Gymnasium classes, their compiled twins and, where they are its own, their exact
models. Each family's ``__init__`` is light (no numba, no Gymnasium): it defines
``PROFILES`` and ``WORLDS``, and its twins load through functions when first used.

========================================  ==================================================
family                                    environments
========================================  ==================================================
:mod:`~cartpole_q.families.cartpole`      CartPole-v1 (its physics settable and randomisable)
:mod:`~cartpole_q.families.mountaincar`   MountainCar-v0
:mod:`~cartpole_q.families.acrobot`       Acrobot-v1
:mod:`~cartpole_q.families.toy_text`      FrozenLake, Taxi, CliffWalking
:mod:`~cartpole_q.families.blackjack`     Blackjack-v1 and the book's Blackjack dealt one hand or a random state
:mod:`~cartpole_q.families.gridworlds`    the windy gridworlds and the Dyna mazes
:mod:`~cartpole_q.families.walks`         the 5-, 19- and 1000-state random walks
:mod:`~cartpole_q.families.book_mdps`     the one-state and maximization-bias MDPs
:mod:`~cartpole_q.families.planning`      the worlds of dynamic programming (chapters 3-4)
:mod:`~cartpole_q.families.bandit`        the k-armed testbed (chapter 2)
:mod:`~cartpole_q.families.puddle`        the puddle world (Figure 12.14)
========================================  ==================================================

:mod:`~cartpole_q.families.tables` holds what the worlds played from a transition table
share (their base class, their twins); :mod:`~cartpole_q.families.registration` registers
the worlds with Gymnasium.

:func:`profile_for` finds an id's profile by the id itself, or by the entry point the id is
registered with (a user who registers ``MyCartPole-v0`` with CartPole's class gets CartPole's
profile); an environment no profile describes gets :data:`~cartpole_q.families.base.UNKNOWN`
and works with what its spaces say. A plug-in adds an environment with one
:func:`register_profile` call.
"""

from __future__ import annotations

from collections.abc import Iterator

from cartpole_q.families import (
    acrobot,
    bandit,
    blackjack,
    book_mdps,
    cartpole,
    gridworlds,
    mountaincar,
    planning,
    puddle,
    toy_text,
    walks,
)
from cartpole_q.families.base import UNKNOWN, EnvProfile, Physics, PhysicsRange, World

__all__ = [
    "FAMILIES",
    "UNKNOWN",
    "EnvProfile",
    "Physics",
    "PhysicsRange",
    "World",
    "all_profiles",
    "all_worlds",
    "profile_for",
    "register_profile",
]

_PROFILES: list[EnvProfile] = []


def register_profile(profile: EnvProfile) -> EnvProfile:
    """Add a profile (its ids and entry points must be new).

    Raises:
        ValueError: an id or entry point is described by another profile already.
    """
    for known in _PROFILES:
        if known.name == profile.name:
            if known == profile:
                return known
            raise ValueError(f"a profile named {profile.name!r} is registered already")
        shared = (set(known.ids) & set(profile.ids)) | (
            set(known.entry_points) & set(profile.entry_points)
        )
        if shared:
            raise ValueError(f"{sorted(shared)[0]!r} is described by {known.name!r} already")
    _PROFILES.append(profile)
    return profile


def all_profiles() -> Iterator[EnvProfile]:
    """Every registered profile, the package's first."""
    return iter(tuple(_PROFILES))


def profile_for(env_id: str) -> EnvProfile:
    """The profile of ``env_id``: by id, else by its registered entry point, else UNKNOWN.

    An id written ``module:Name-v0`` (Gymnasium imports the module, which registers the
    id) is looked up as ``Name-v0``.

    >>> profile_for("CartPole-v1").name, profile_for("NoSuchEnv-v0").name
    ('CartPole', 'unknown')
    >>> profile_for("gymnasium.envs:CartPole-v1").name
    'CartPole'
    """
    name = env_id.rpartition(":")[2]
    for profile in _PROFILES:
        if name in profile.ids:
            return profile
    entry_point = _entry_point(env_id)
    if entry_point is not None:
        for profile in _PROFILES:
            if entry_point in profile.entry_points:
                return profile
    return UNKNOWN


def _entry_point(env_id: str) -> str | None:
    """The entry point ``env_id`` is registered with (``module:Class``), if it is.

    A look in the registry only: nothing is imported (``module:Name-v0`` is looked up as
    ``Name-v0``, found once the module that registers it has been imported).
    """
    try:
        from gymnasium.envs.registration import registry
    except ImportError:  # pragma: no cover - gymnasium is a dependency
        return None
    spec = registry.get(env_id.rpartition(":")[2])
    entry_point = None if spec is None else spec.entry_point
    return entry_point if isinstance(entry_point, str) else None


FAMILIES = (
    cartpole, mountaincar, acrobot, toy_text, blackjack, gridworlds, walks, book_mdps,
    planning, bandit, puddle,
)  # fmt: skip
"""the package's environment families, in the order their profiles are registered"""


def all_worlds() -> tuple[World, ...]:
    """Every world the package's families register with Gymnasium."""
    return tuple(world for family in FAMILIES for world in family.WORLDS)


for _family in FAMILIES:
    for _profile in _family.PROFILES:
        register_profile(_profile)
