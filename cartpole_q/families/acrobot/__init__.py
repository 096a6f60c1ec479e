"""Acrobot (Gymnasium's ``AcrobotEnv``): its names and its twin."""

from __future__ import annotations

from cartpole_q.families.base import EnvProfile, TwinModule, World


def load_twin() -> TwinModule:
    """Acrobot's compiled twin, imported when first used (it compiles with numba)."""
    from cartpole_q.families.acrobot import twin

    return twin


PROFILE = EnvProfile(
    name="Acrobot",
    description="swing a two-link pendulum above a line: 6 dimensions, 3 torques",
    ids=("Acrobot-v1",),
    entry_points=("gymnasium.envs.classic_control.acrobot:AcrobotEnv",),
    observation_names=(
        "cos θ1",
        "sin θ1",
        "cos θ2",
        "sin θ2",
        "θ1 velocity (rad/s)",
        "θ2 velocity (rad/s)",
    ),
    action_names=("torque -1", "torque 0", "torque +1"),
    twin=load_twin,
)

PROFILES = (PROFILE,)
"""the family's profiles"""
WORLDS: tuple[World, ...] = ()
"""the worlds it registers (none: Gymnasium registers it)"""
