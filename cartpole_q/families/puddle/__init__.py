"""The puddle world (Sutton 1996; Sutton & Barto Figure 12.14): its profile, world and twin.

:mod:`~cartpole_q.families.puddle.world` is the world (a point in the unit square, four
moves with noise, -1 a step and more in the two puddles, the goal in the upper right
corner); :mod:`~cartpole_q.families.puddle.twin` its compiled twin. Its observation is a
float32 Box of two dimensions: a config gives a grid (Figure 12.14 codes it with tiles).
"""

from __future__ import annotations

from cartpole_q.families.base import NAMESPACE, EnvProfile, TwinModule, World

PUDDLE_TIME_LIMIT = 10_000
"""steps before an episode is truncated: far beyond a learner's episodes (tens of steps
once it has learned; a uniformly random policy takes a few hundred to a few thousand)"""


def load_twin() -> TwinModule:
    """The puddle world's compiled twin, imported when first used (it compiles with numba)."""
    from cartpole_q.families.puddle import twin

    return twin


PROFILE = EnvProfile(
    name="PuddleWorld",
    description="drive a point to the upper right corner of the unit square around two "
    "puddles: four noisy moves of 0.05, -1 a step and up to -40 more inside a puddle "
    "(Sutton 1996; Sutton & Barto Figure 12.14)",
    ids=("cartpole_q/PuddleWorld-v0",),
    entry_points=("cartpole_q.families.puddle.world:PuddleWorldEnv",),
    observation_names=("x", "y"),
    action_names=("up", "down", "left", "right"),
    twin=load_twin,
)

PROFILES = (PROFILE,)
"""the family's profiles"""
WORLDS: tuple[World, ...] = (
    World(f"{NAMESPACE}/PuddleWorld-v0", "cartpole_q.families.puddle.world:PuddleWorldEnv",
          PUDDLE_TIME_LIMIT),
)  # fmt: skip
"""the worlds it registers"""
