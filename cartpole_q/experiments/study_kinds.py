"""Every study kind of the package, registered: ``cartpole-q study`` imports this module.

A new kind is one module defining a :class:`~cartpole_q.experiments.study.StudyKind`
(usually a :class:`~cartpole_q.experiments.study.RunsKind`) and registering it with
:func:`~cartpole_q.experiments.study.register_kind`, plus one import line here.
"""

from __future__ import annotations

from cartpole_q.experiments import (
    average_reward,
    bandits,
    linear,
    panels,
    planning,
    policy_gradient,
    sweep,
    updates,
)
from cartpole_q.experiments.study import StudyKind, kinds

MODULES = (sweep, bandits, planning, updates, linear, policy_gradient, average_reward, panels)
"""the modules that register the kinds (imported for that)"""


def registered() -> dict[str, StudyKind]:
    """Every registered kind by name."""
    return kinds()
