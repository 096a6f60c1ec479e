"""CartPole (Gymnasium's ``CartPoleEnv``): its physics, its names, its twin.

``env.physics`` sets attributes of ``env.unwrapped`` after ``gymnasium.make``; ``total_mass``
and ``polemass_length`` are then recomputed exactly as ``CartPoleEnv.__init__`` computes them
(setting the attributes alone leaves them stale, as ray #14090 found).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from types import MappingProxyType
from typing import Any

from cartpole_q.families.base import EnvProfile, Physics, PhysicsRange, TwinModule, World


def set_physics(env: Any, physics: Mapping[str, Any]) -> None:
    """Set CartPole's physics on ``env.unwrapped``, derived values recomputed."""
    cartpole = env.unwrapped
    for key, value in physics.items():
        setattr(cartpole, key, value)
    cartpole.total_mass = cartpole.masspole + cartpole.masscart
    cartpole.polemass_length = cartpole.masspole * cartpole.length


PHYSICS = Physics(
    ranges=MappingProxyType({
        "gravity": PhysicsRange(0.0, 1000.0),
        "masscart": PhysicsRange(0.0, 1000.0, low_open=True),
        "masspole": PhysicsRange(0.0, 1000.0, low_open=True),
        "length": PhysicsRange(0.0, 100.0, low_open=True),
        "force_mag": PhysicsRange(0.0, 10_000.0, low_open=True),
        "tau": PhysicsRange(0.0, 1.0, low_open=True),
        "theta_threshold_radians": PhysicsRange(0.0, math.pi, low_open=True),
        "x_threshold": PhysicsRange(0.0, 1000.0, low_open=True),
    }),
    choices=MappingProxyType({"kinematics_integrator": ("euler", "semi-implicit euler")}),
    randomizable=("gravity", "masscart", "masspole", "length", "force_mag", "tau"),
    defaults=MappingProxyType({
        "gravity": 9.8, "masscart": 1.0, "masspole": 0.1, "length": 0.5, "force_mag": 10.0,
        "tau": 0.02, "theta_threshold_radians": 12 * 2 * math.pi / 360, "x_threshold": 2.4,
    }),
    apply=set_physics,
    notes=(
        "gravity may be 0 (weightless: the pole only moves when pushed) but not negative, "
        "which would pull the pole upright and make balancing another task; the upper ends "
        "keep the state finite (a force of 1e308 overflows float64 at the first step)"
    ),
)  # fmt: skip


def load_twin() -> TwinModule:
    """CartPole's compiled twin, imported when first used (it compiles with numba)."""
    from cartpole_q.families.cartpole import twin

    return twin


PROFILE = EnvProfile(
    name="CartPole",
    description="balance a pole on a cart: 4 continuous dimensions, push left or right",
    ids=("CartPole-v1", "CartPole-v0"),
    entry_points=("gymnasium.envs.classic_control.cartpole:CartPoleEnv",),
    observation_names=(
        "cart position (m)",
        "cart velocity (m/s)",
        "pole angle (rad)",
        "pole angular velocity (rad/s)",
    ),
    action_names=("push left", "push right"),
    physics=PHYSICS,
    default_grid=True,
    threshold_scales=True,
    twin=load_twin,
)

PROFILES = (PROFILE,)
"""the family's profiles"""
WORLDS: tuple[World, ...] = ()
"""the worlds it registers (none: Gymnasium registers it)"""
