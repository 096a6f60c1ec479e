"""Bounds on what a study file may ask for, checked when it is read.

A size in a study file (steps, states, branching factors, maze scales, updates) becomes
arrays and loops: unbounded, a typo (``steps: 1000000000000``) would fill the machine's
memory, or overflow a compiled loop's 64-bit counters, long after the file was accepted.
Each reader checks its sizes here first and refuses, with the memory they would take, what
no study needs.
"""

from __future__ import annotations

from cartpole_q.errors import ConfigError

STUDY_MEMORY = 4 * 2**30
"""the most memory a study's arrays may take (4 GiB: the book's largest figures take a few MiB)"""
MAX_COUNT = 10**15
"""the largest count (of updates, steps) a study may give: far below the 2**63 of the
compiled loops' integers, far above what any study can finish"""


def memory_text(n_bytes: int) -> str:
    """A number of bytes as a person reads it.

    >>> memory_text(3 * 2**30), memory_text(1536), memory_text(12)
    ('3.0 GiB', '1.5 KiB', '12 bytes')
    >>> memory_text(5 * 2**60)
    '5,242,880.0 TiB'
    """
    for unit, scale in (("TiB", 2**40), ("GiB", 2**30), ("MiB", 2**20), ("KiB", 2**10)):
        if n_bytes >= scale:
            return f"{n_bytes / scale:,.1f} {unit}"
    return f"{n_bytes} bytes"


def check_memory(where: str, key: str, needed: int, what: str) -> None:
    """Refuse a study whose arrays would take more than :data:`STUDY_MEMORY`.

    Args:
        where: the file, for the message.
        key: the key (a dotted path) that asks for the size.
        needed: the bytes the arrays would take.
        what: what they are, e.g. ``"a maze of 470,000,000 states"``.

    Raises:
        ConfigError: naming the file, the key, the memory needed and the limit.

    >>> check_memory("s.yaml", "steps", 2**40, "the curves of 3 learners")
    Traceback (most recent call last):
    ...
    cartpole_q.errors.ConfigError: s.yaml: steps: the curves of 3 learners would take 1.0 TiB of memory, more than the 4.0 GiB a study may take; ask for less.
    """
    if needed > STUDY_MEMORY:
        raise ConfigError(
            f"{where}: {key}: {what} would take {memory_text(needed)} of memory, more than the "
            f"{memory_text(STUDY_MEMORY)} a study may take; ask for less."
        )


def check_count(where: str, key: str, value: int, most: int = MAX_COUNT, why: str = "") -> None:
    """Refuse a count above ``most``.

    Raises:
        ConfigError: naming the file, the key, the limit and why it is there.

    >>> check_count("s.yaml", "max_updates", 10**21)
    Traceback (most recent call last):
    ...
    cartpole_q.errors.ConfigError: s.yaml: max_updates: must be at most 1,000,000,000,000,000, got 1,000,000,000,000,000,000,000.
    """
    if value > most:
        because = f" ({why})" if why else ""
        raise ConfigError(f"{where}: {key}: must be at most {most:,}{because}, got {value:,}.")
