"""MountainCar (Gymnasium's ``MountainCarEnv``): its names and its twin."""

from __future__ import annotations

from cartpole_q.profiles.base import EnvProfile

PROFILE = EnvProfile(
    name="MountainCar",
    description="drive an underpowered car up a hill: position and velocity, 3 pushes",
    ids=("MountainCar-v0",),
    entry_points=("gymnasium.envs.classic_control.mountain_car:MountainCarEnv",),
    observation_names=("position", "velocity"),
    action_names=("accelerate left", "don't accelerate", "accelerate right"),
    twin="cartpole_q.envs.twins.mountaincar",
)
