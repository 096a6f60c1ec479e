"""Acrobot (Gymnasium's ``AcrobotEnv``): its names and its twin."""

from __future__ import annotations

from cartpole_q.profiles.base import EnvProfile

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
    twin="cartpole_q.envs.twins.acrobot",
)
