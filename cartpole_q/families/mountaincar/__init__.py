"""MountainCar (Gymnasium's ``MountainCarEnv``): its names and its twin."""

from __future__ import annotations

from cartpole_q.families.base import EnvProfile, TwinModule, World


def load_twin() -> TwinModule:
    """MountainCar's compiled twin, imported when first used (it compiles with numba)."""
    from cartpole_q.families.mountaincar import twin

    return twin


PROFILE = EnvProfile(
    name="MountainCar",
    description="drive an underpowered car up a hill: position and velocity, 3 pushes",
    ids=("MountainCar-v0",),
    entry_points=("gymnasium.envs.classic_control.mountain_car:MountainCarEnv",),
    observation_names=("position", "velocity"),
    action_names=("accelerate left", "don't accelerate", "accelerate right"),
    twin=load_twin,
)

PROFILES = (PROFILE,)
"""the family's profiles"""
WORLDS: tuple[World, ...] = ()
"""the worlds it registers (none: Gymnasium registers it)"""
