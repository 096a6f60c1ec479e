"""Schedules of the learning and exploration rates: one value per episode.

For episode ``e`` (0 for the first), each value is computed afresh as a float64 scalar
(never by repeated multiplication):

- ``CONSTANT``: ``start``;
- ``EXPONENTIAL``: ``max(end, start * rate ** float(e))`` with ``rate`` the decay;
- ``LOG``: ``max(end, min(start, 1 - log10((e + 1) / rate)))`` with ``rate`` the ``k``.

Plain Python, compiled by the engines (see :mod:`cartpole_q.rl.tabular`).

>>> schedule_value(EXPONENTIAL, 1.0, 0.01, 0.5, 3)
0.125
>>> schedule_value(LOG, 1.0, 0.1, 9.0, 89)
0.1
"""

from __future__ import annotations

import math

from cartpole_q.rl.tabular import compilable

SCHEDULE_KINDS = ("constant", "exponential", "log")
"""schedule ``type`` values, in the order of the codes :func:`schedule_value` takes"""
CONSTANT, EXPONENTIAL, LOG = range(len(SCHEDULE_KINDS))


@compilable
def schedule_value(kind: int, start: float, end: float, rate: float, episode: int) -> float:
    """Return a schedule's value at a 0-based episode index.

    Args:
        kind: ``CONSTANT``, ``EXPONENTIAL`` or ``LOG``.
        start: the constant, the initial value, or the log schedule's cap.
        end: the floor.
        rate: the per-episode decay factor, or the log schedule's ``k``.
        episode: 0 for the first episode.
    """
    if kind == CONSTANT:
        return start
    if kind == EXPONENTIAL:
        return float(max(end, start * rate ** float(episode)))
    return float(max(end, min(start, 1.0 - math.log10((episode + 1.0) / rate))))
