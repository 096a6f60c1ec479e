"""The compiled twins and the environments they reproduce.

A twin is a module of compiled functions (``reset``, ``step``, and ``randomized`` where the
environment has physics to randomise) with its sizes and the plain function that turns
``gymnasium.make`` arguments into its parameters (:class:`~cartpole_q.families.base.TwinModule`);
:class:`Twin` is what the engines bind into their compiled loops (see
:mod:`cartpole_q.engines.kernel`). An environment's profile loads its twin's module
(:attr:`cartpole_q.families.base.EnvProfile.twin`): a new twin is one module in its family
and the function that imports it.
"""

from __future__ import annotations

import hashlib
import importlib
import inspect
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from types import ModuleType
from typing import Any, cast

import numpy as np
from numba import njit

from cartpole_q.families import EnvProfile, all_profiles, profile_for
from cartpole_q.families.base import TwinModule
from cartpole_q.numba_cache import configure as configure_numba_cache

configure_numba_cache()  # before any cache=True function is defined


@njit(cache=True, nogil=True, inline="always")
def unchanged(
    params: tuple[float, ...], rng: np.random.Generator, keys: np.ndarray, lows: np.ndarray,
    highs: np.ndarray,
) -> tuple[float, ...]:  # fmt: skip
    """A twin without physics to randomise: its parameters, nothing drawn."""
    return params


@dataclass(frozen=True)
class Twin:
    """A compiled twin: what the compiled loops call, and what sizes them."""

    name: str
    """the module's name in its family (``cartpole``, ``tables``, ``toy_text_taxi``)"""
    key: str
    """the name and a digest of the module's source (compiled loops are cached under it)"""
    env_ids: tuple[str, ...]
    """the Gymnasium ids it reproduces"""
    reset: Any
    """compiled ``reset(state, observation, rng, params)``"""
    step: Any
    """compiled ``step(state, action, observation, rng, params) -> (reward, terminated)``"""
    randomize: Any
    """compiled ``randomize(params, rng, keys, lows, highs) -> params`` (``env.randomize``)"""
    params: Callable[..., tuple[Any, ...] | str]
    """``params(kwargs[, physics])``, or ``params(kwargs, env_id)`` when
    :attr:`reads_environment`: the twin's parameters, or why it cannot reproduce them"""
    reads_environment: bool
    """its parameters are read from the environment ``gymnasium.make`` builds"""
    state_size: int
    state_dtype: Any
    """the NumPy type of the state's array (``np.float64``, ``np.int64``)"""
    observation_size: int
    observation_dtype: Any
    """the NumPy type of the observation's array (``np.float32``, ``np.int64``)"""
    observation_kind: str
    """how an observation becomes a Q-table row: ``box``, ``discrete`` or ``tuple``"""

    @classmethod
    def of(cls, module: TwinModule, profile: EnvProfile) -> Twin:
        """The twin a module defines (see :class:`~cartpole_q.families.base.TwinModule`) for a profile."""
        source = cast(ModuleType, module)
        name = twin_name(source.__name__)
        digest = hashlib.sha256(inspect.getsource(source).encode()).hexdigest()[:12]
        return cls(
            name=name,
            key=f"{name}_{digest}",
            env_ids=profile.ids,
            reset=module.reset,
            step=module.step,
            randomize=getattr(module, "randomized", unchanged),
            params=module.twin_params,
            reads_environment=bool(module.READS_ENVIRONMENT),
            state_size=int(module.STATE_SIZE),
            state_dtype=module.STATE_DTYPE,
            observation_size=int(module.OBSERVATION_SIZE),
            observation_dtype=module.OBSERVATION_DTYPE,
            observation_kind=str(module.OBSERVATION_KIND),
        )


def twin_name(module_name: str) -> str:
    """A twin's short name, from its module's: its path in its family, ``twin`` left out.

    >>> twin_name("cartpole_q.families.cartpole.twin"), twin_name("cartpole_q.families.tables.twin")
    ('cartpole', 'tables')
    >>> twin_name("cartpole_q.families.toy_text.taxi_twin"), twin_name("my_plugin.twins.maze")
    ('toy_text_taxi', 'my_plugin_twins_maze')
    """
    path = module_name.removeprefix("cartpole_q.families.").split(".")
    return "_".join(part.removesuffix("_twin") for part in path if part != "twin")


_LOADED: dict[str, Twin] = {}


def _twin_of(profile: EnvProfile) -> Twin | None:
    """The twin a profile loads (its module imported, and the record made, once)."""
    if profile.twin is None:
        return None
    if profile.name not in _LOADED:
        if isinstance(profile.twin, str):
            # A plug-in's module by name: it meets the interface at its own risk.
            module = cast(TwinModule, importlib.import_module(profile.twin))
        else:  # the package's families: a loader whose return type mypy checks
            module = profile.twin()
        _LOADED[profile.name] = Twin.of(module, profile)
    return _LOADED[profile.name]


def twin_for(env_id: str) -> Twin | None:
    """The twin of an environment, as its profile names it (``None``: it has none)."""
    return _twin_of(profile_for(env_id))


def twins() -> tuple[Twin, ...]:
    """Every twin the registered profiles name."""
    return tuple(twin for profile in all_profiles() if (twin := _twin_of(profile)) is not None)


@dataclass(frozen=True)
class TwinSettings:
    """Everything the compiled loop needs to run one environment's twin."""

    twin: Twin
    max_episode_steps: int | None
    """the time limit (truncation), as ``gymnasium.make`` applies it (``None``: none)"""
    params: tuple[Any, ...]
    """the twin's parameters (the ``gymnasium.make`` arguments it reproduces): a tuple of
    floats, which compiled code passes by value, without the reference counting of an
    array; or the arrays of a transition table"""

    @property
    def state_size(self) -> int:
        """Floats in the twin's state."""
        return self.twin.state_size

    @property
    def observation_size(self) -> int:
        """Floats in the twin's observation."""
        return self.twin.observation_size


def twin_ids() -> tuple[str, ...]:
    """Every environment id a twin reproduces."""
    return tuple(env_id for twin in twins() for env_id in twin.env_ids)


def twin_settings(
    env_id: str,
    kwargs: Mapping[str, Any],
    spec_max_steps: int | None,
    physics: Mapping[str, float | str] | None = None,
) -> TwinSettings | str:
    """Return the twin settings for ``gymnasium.make(env_id, **kwargs)``, or why there are none.

    Args:
        env_id: the Gymnasium id.
        kwargs: the ``gymnasium.make`` arguments.
        spec_max_steps: the registered time limit, used when ``kwargs`` gives none
            (``None``: the environment has none).
        physics: ``env.physics`` (CartPole only; the config refuses it elsewhere).

    Returns:
        ``TwinSettings`` when a twin reproduces the environment exactly, else a sentence
        naming the id or key it cannot reproduce.
    """
    twin = twin_for(env_id)
    if twin is None:
        return f"env.id {env_id!r} has no compiled twin (only {', '.join(twin_ids())} do)"
    max_steps = kwargs.get("max_episode_steps", spec_max_steps)
    if max_steps is not None and (
        isinstance(max_steps, bool) or not isinstance(max_steps, int) or max_steps < 1
    ):
        return f"env.kwargs key 'max_episode_steps' must be a positive integer, got {max_steps!r}"
    if twin.reads_environment:
        params = twin.params(kwargs, env_id)
    elif physics:
        params = twin.params(kwargs, physics)
    else:
        params = twin.params(kwargs)
    if isinstance(params, str):
        return params
    return TwinSettings(twin, max_steps, params)
