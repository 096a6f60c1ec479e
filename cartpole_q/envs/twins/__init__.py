"""Compiled twins of Gymnasium environments, bit-identical to them.

Each module defines ``STATE_SIZE``, ``OBSERVATION_SIZE``, ``N_ACTIONS``,
``MAX_EPISODE_STEPS``, the compiled ``reset(state, observation, rng, params)`` and
``step(state, action, observation, params) -> (reward, terminated)``, and the plain function
``twin_params(kwargs)`` that turns ``gymnasium.make`` arguments into ``params`` (a tuple of
floats) or says which
one the twin cannot reproduce. The environments a twin reproduces are named by their
profiles (:mod:`cartpole_q.profiles`), which name the twin's module.
"""

from collections.abc import Iterable, Mapping
from typing import Any


def unsupported_key(kwargs: Mapping[str, Any], supported: Iterable[str]) -> str | None:
    """A sentence naming the first key of ``kwargs`` a twin does not reproduce, or ``None``."""
    supported = tuple(supported)
    for key in kwargs:
        if key not in supported:
            return (
                f"env.kwargs key {key!r} is not reproduced by the compiled twin "
                f"(it supports {', '.join(supported)})"
            )
    return None
