"""The k-armed testbed of chapter 2 (``cartpole-q bandit``, Figures 2.2-2.6).

:mod:`~cartpole_q.families.bandit.world` is the testbed as a Gymnasium environment, and
:mod:`~cartpole_q.families.bandit.twin` the compiled draws the bandit engine makes of it.

The testbed never ends an episode itself; ``cartpole-q bandit`` plays it for its study's
``steps``, and ``cartpole-q train`` on it plays one fresh testbed per episode of
:data:`BANDIT_TIME_LIMIT` steps.
"""

from __future__ import annotations

from cartpole_q.families.base import NAMESPACE, EnvProfile, World

BANDIT_TIME_LIMIT = 1_000
"""steps before a bandit's episode is truncated: the book's run length"""

PROFILES: tuple[EnvProfile, ...] = ()
"""the family's profiles (none: what its spaces say is all the tool needs)"""
WORLDS: tuple[World, ...] = (
    World(
        f"{NAMESPACE}/Bandit-v0", "cartpole_q.families.bandit.world:BanditEnv", BANDIT_TIME_LIMIT
    ),
)
"""the worlds it registers"""
