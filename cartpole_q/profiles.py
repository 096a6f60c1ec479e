"""Kept for plug-ins written before the families: what they imported from here.

The profiles now live with their environments' families (:mod:`cartpole_q.families`);
``from cartpole_q.profiles import EnvProfile, register_profile`` still works.
"""

from cartpole_q.families import (
    UNKNOWN,
    EnvProfile,
    Physics,
    PhysicsRange,
    all_profiles,
    profile_for,
    register_profile,
)

__all__ = [
    "UNKNOWN",
    "EnvProfile",
    "Physics",
    "PhysicsRange",
    "all_profiles",
    "profile_for",
    "register_profile",
]
