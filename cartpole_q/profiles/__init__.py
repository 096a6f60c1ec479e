"""Environment profiles: what the package knows about each environment, and their registry.

:func:`profile_for` finds an id's profile by the id itself, or by the entry point the id is
registered with (a user who registers ``MyCartPole-v0`` with CartPole's class gets CartPole's
profile); an environment no profile describes gets :data:`~cartpole_q.profiles.base.UNKNOWN`
and works with what its spaces say. A new environment is one profile module and one
:func:`register_profile` call.
"""

from __future__ import annotations

from collections.abc import Iterator

from cartpole_q.profiles import acrobot, book, cartpole, mountaincar, planning, toy_text
from cartpole_q.profiles.base import UNKNOWN, EnvProfile, Physics, PhysicsRange

__all__ = [
    "UNKNOWN",
    "EnvProfile",
    "Physics",
    "PhysicsRange",
    "all_profiles",
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

    >>> profile_for("CartPole-v1").name, profile_for("NoSuchEnv-v0").name
    ('CartPole', 'unknown')
    """
    for profile in _PROFILES:
        if env_id in profile.ids:
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


for _profile in (
    cartpole.PROFILE, mountaincar.PROFILE, acrobot.PROFILE, toy_text.FROZENLAKE,
    toy_text.TAXI, toy_text.CLIFFWALKING, toy_text.BLACKJACK, toy_text.BLACKJACK_DEALT,
    toy_text.BLACKJACK_ES,
    book.WINDY_GRIDWORLD,
    book.KINGS_WINDY_GRIDWORLD, book.DYNA_MAZE, book.MAXIMIZATION_BIAS, book.RANDOM_WALK,
    book.RANDOM_WALK_1000, book.ONE_STATE, planning.GRIDWORLDS, planning.GAMBLER,
    planning.CAR_RENTAL,
):  # fmt: skip
    register_profile(_profile)
