"""Schedules of the learning and exploration rates: one value per episode.

For episode ``e`` (0 for the first), each value is computed afresh as a float64 scalar
(never by repeated multiplication):

- ``CONSTANT``: ``start``;
- ``EXPONENTIAL``: ``max(end, start * rate ** float(e))`` with ``rate`` the decay;
- ``LOG``: ``max(end, min(start, 1 - log10((e + 1) / rate)))`` with ``rate`` the ``k``;
- ``SAMPLE_AVERAGE`` (a step size only, ``agent.alpha: sample_average``): NaN. There is no
  value per episode: every update of a table entry moves it by ``1 / N``, ``N`` the entry's
  update count (:func:`~cartpole_q.rl.tabular.averaged_update`), and the episode's record
  says so with NaN.

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
STEP_SIZE_KINDS = (*SCHEDULE_KINDS, "sample_average")
"""``agent.alpha``'s kinds: a schedule, or the sample average (no value per episode)"""
CONSTANT, EXPONENTIAL, LOG, SAMPLE_AVERAGE = range(len(STEP_SIZE_KINDS))


@compilable
def schedule_value(kind: int, start: float, end: float, rate: float, episode: int) -> float:
    """Return a schedule's value at a 0-based episode index.

    Args:
        kind: ``CONSTANT``, ``EXPONENTIAL``, ``LOG`` or ``SAMPLE_AVERAGE`` (NaN).
        start: the constant, the initial value, or the log schedule's cap.
        end: the floor.
        rate: the per-episode decay factor, or the log schedule's ``k``.
        episode: 0 for the first episode.
    """
    if kind == CONSTANT:
        return start
    if kind == EXPONENTIAL:
        return float(max(end, start * rate ** float(episode)))
    if kind == SAMPLE_AVERAGE:
        return math.nan
    return float(max(end, min(start, 1.0 - math.log10((episode + 1.0) / rate))))


def smallest_positive_value(
    kind: int, start: float, end: float, rate: float, episodes: int
) -> tuple[float, int] | None:
    """The smallest positive value a schedule takes in episodes ``0 .. episodes - 1``.

    Every schedule is non-increasing in the episode (``decay <= 1``; the log term falls), so
    the smallest positive value is the last one before the schedule reaches 0, found by
    bisection: a few evaluations however many episodes.

    Returns:
        The value and its episode, or ``None`` when no episode's value is positive.

    >>> smallest_positive_value(EXPONENTIAL, 1.0, 0.0, 0.5, 2000)
    (5e-324, 1074)
    >>> smallest_positive_value(LOG, 1.0, 0.01, 25.0, 1000)
    (0.01, 999)
    >>> smallest_positive_value(CONSTANT, 0.0, 0.0, 1.0, 10) is None
    True
    """
    last = episodes - 1
    if schedule_value(kind, start, end, rate, last) > 0.0:
        return schedule_value(kind, start, end, rate, last), last
    if not schedule_value(kind, start, end, rate, 0) > 0.0:
        return None
    positive, zero = 0, last  # the value is positive at ``positive``, not at ``zero``
    while zero - positive > 1:
        middle = (positive + zero) // 2
        if schedule_value(kind, start, end, rate, middle) > 0.0:
            positive = middle
        else:
            zero = middle
    return schedule_value(kind, start, end, rate, positive), positive
