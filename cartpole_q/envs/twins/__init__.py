"""Compiled twins of Gymnasium environments, bit-identical to them.

Each module defines:

- ``STATE_SIZE`` and ``STATE_DTYPE``: the twin's state, an array the compiled loop
  allocates (float64 for the classic-control twins, int64 for the tabular ones);
- ``OBSERVATION_SIZE``, ``OBSERVATION_DTYPE`` and ``OBSERVATION_KIND``: the array ``reset``
  and ``step`` write the observation into, and how it becomes a Q-table row (``box``: the
  binning rule on float32 values; ``discrete``: one integer; ``tuple``: one integer per
  ``Discrete`` component; see :mod:`cartpole_q.engines.rows`);
- the compiled ``reset(state, observation, rng, params)`` and
  ``step(state, action, observation, rng, params) -> (reward, terminated)``, where ``rng``
  is the environment's generator (``env.np_random``), from which they draw exactly what
  Gymnasium draws, in the same order (the classic-control steps draw nothing);
- the plain function ``twin_params`` that turns ``gymnasium.make`` arguments into
  ``params`` (a tuple, of floats or of arrays), or says which one the twin cannot
  reproduce: ``twin_params(kwargs)`` (CartPole's also takes ``env.physics``), or, with
  ``READS_ENVIRONMENT = True``, ``twin_params(kwargs, env_id)``, which reads what it needs
  from the environment ``gymnasium.make(env_id, **kwargs)`` builds (a transition table).

The environments a twin reproduces are named by their profiles (:mod:`cartpole_q.profiles`),
which name the twin's module.
"""

from collections.abc import Callable, Iterable, Mapping
from typing import Any, Protocol


class TwinModule(Protocol):
    """The interface above, which each of the package's twin modules meets (mypy checks).

    :data:`cartpole_q.envs.registry.TWIN_MODULES` lists them.
    The names are a module's, read-only here as a module's constants are to its readers;
    ``reset`` and ``step`` are numba dispatchers (``Any`` to mypy).
    """

    @property
    def STATE_SIZE(self) -> int:
        """The state array's length."""
        ...

    @property
    def STATE_DTYPE(self) -> Any:
        """The state array's NumPy type."""
        ...

    @property
    def OBSERVATION_SIZE(self) -> int:
        """The observation array's length."""
        ...

    @property
    def OBSERVATION_DTYPE(self) -> Any:
        """The observation array's NumPy type."""
        ...

    @property
    def OBSERVATION_KIND(self) -> str:
        """How an observation becomes a row: box, discrete or tuple."""
        ...

    @property
    def READS_ENVIRONMENT(self) -> bool:
        """``twin_params(kwargs, env_id)`` reads the environment it builds."""
        ...

    @property
    def PARAM_NAMES(self) -> tuple[str, ...]:
        """What ``params`` holds, in order."""
        ...

    @property
    def reset(self) -> Any:
        """The compiled ``reset(state, observation, rng, params)``."""
        ...

    @property
    def step(self) -> Any:
        """The compiled ``step(state, action, observation, rng, params) -> (reward, terminated)``."""
        ...

    @property
    def twin_params(self) -> Callable[..., tuple[Any, ...] | str]:
        """``params`` from ``gymnasium.make`` arguments, or why not."""
        ...


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
