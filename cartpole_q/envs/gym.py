"""Gymnasium environments: making them, and checking a config against one.

Everything that can be wrong about a config only once the environment is known (an
unknown id, an argument of a type its constructor does not take, unsupported spaces, a grid
of the wrong dimension, a Q-table too large to allocate) is found here, before any run
directory exists.
"""

from __future__ import annotations

import math
import numbers
import os
import sys
import warnings
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from cartpole_q.config import (
    Config,
    ConfigError,
    EnvConfig,
    Provenance,
    blame,
    shorten,
    shown,
    shown_value,
)
from cartpole_q.config.bounds import memory_text
from cartpole_q.config.messages import type_name
from cartpole_q.envs.arguments import NUMBER, Rule, constructor_parameters, declared, rule_of
from cartpole_q.errors import RunError
from cartpole_q.families import profile_for


@dataclass(frozen=True)
class EnvInfo:
    """What training needs to know about an environment."""

    id: str
    """the Gymnasium id"""
    observation_dim: int
    """length of the 1-D Box observation (components of a Tuple, 1 for a Discrete)"""
    n_actions: int
    """size of the Discrete action space"""
    reward_threshold: float | None
    """return that counts as solved (config's ``train.reward_threshold`` or the env's)"""
    max_episode_steps: int | None
    """the time limit after which an episode is truncated"""
    state_shape: tuple[int, ...] = ()
    """the Q-table's shape without the action axis: the bins of a Box observation, ``(n,)``
    for ``Discrete(n)``, ``(a, b, ...)`` for a Tuple of Discrete spaces"""
    index_starts: tuple[int, ...] | None = None
    """each Discrete component's ``start`` when the observation is the row index itself
    (row ``obs - start``; a Tuple's components in C order); ``None`` when it is binned"""

    @property
    def indexed(self) -> bool:
        """Whether observations index the Q-table directly (Discrete or Tuple of Discrete)."""
        return self.index_starts is not None


def make_env(
    env: EnvConfig, render_mode: str | None = None, source: str | Provenance = "config"
) -> Any:
    """Return ``gymnasium.make(env.id, **env.kwargs)``, optionally with a render mode.

    Raises:
        ConfigError: the environment cannot be made: an unknown id, a module that cannot be
            imported, a missing package, or an argument it refuses (naming ``env.id`` or the
            ``env.kwargs`` key, never with a traceback).
    """
    import gymnasium

    check_env_id(env.id, source)
    kwargs = dict(env.kwargs)
    if render_mode is not None:
        kwargs["render_mode"] = render_mode
    try:
        with warnings.catch_warnings():
            # Gymnasium warns about out-of-date versions such as CartPole-v0; the user chose it.
            warnings.simplefilter("ignore", category=DeprecationWarning)
            made = gymnasium.make(env.id, **kwargs)
    except ImportError as error:
        module = env.id.partition(":")[0] if ":" in env.id else (error.name or "a module")
        detail = str(error).split(". ")[0]
        raise ConfigError(
            f"{blame(source, 'env.id')}: env.id: cannot make {env.id!r}: the module {module!r} "
            f"cannot be imported ({detail}); install it, or check the part of env.id before ':'."
        ) from None
    except gymnasium.error.DependencyNotInstalled as error:
        raise ConfigError(
            f"{blame(source, 'env.id')}: env.id: {env.id!r} needs a package that is not "
            f"installed ({shorten(str(error), 200)})."
        ) from None
    except gymnasium.error.Error as error:
        imported, name = env_module(env.id), env.id.rpartition(":")[2]
        detail = shorten(str(error), 200)
        if imported is not None and name not in gymnasium.registry:
            detail = f"importing {imported!r} registered no environment {name!r}"
        raise ConfigError(
            f"{blame(source, 'env.id')}: env.id: cannot make {env.id!r}: {detail.rstrip('.')}."
        ) from None
    except Exception as error:  # whatever the environment raises for arguments it refuses
        raise kwargs_error(env, error, source) from None
    if env.physics:
        set_physics(made, env.physics)
    return made


def check_env_id(env_id: str, source: str | Provenance = "config") -> None:
    """Refuse an ``env.id`` Gymnasium cannot make, before anything it names is imported.

    A plain id must be registered (an id without its version is refused with the
    version to give: Gymnasium would pick its latest silently, and the run would not say
    which). ``module:Name-vN`` is Gymnasium's way to make an environment another package
    registers: making it imports ``module``, which runs that module's code, by design, as
    ``python -m module`` would; so the module is checked to exist first (without running
    it), and a config read back from a run or sweep directory may not name one
    (:func:`check_recorded_env_id`).

    >>> check_env_id("CartPole-v1")
    >>> check_env_id("CartPole")
    Traceback (most recent call last):
    ...
    cartpole_q.errors.ConfigError: config: env.id: 'CartPole' gives no version; write 'CartPole-v1' (the latest version Gymnasium has), so that the run records which environment it trained on.

    Raises:
        ConfigError: naming ``env.id``: a malformed id, an unknown one (with the closest
            registered id), an id without its version, or a module that does not exist.
    """
    import difflib
    import importlib.util

    from gymnasium import error as gym_error
    from gymnasium.envs.registration import (
        find_highest_version,
        get_env_id,
        parse_env_id,
        registry,
    )

    where = f"{blame(source, 'env.id')}: env.id: {shown(env_id)}"
    module, colon, name = env_id.partition(":")
    if not colon:
        module, name = "", env_id
    if ":" in name or (colon and not module):
        raise ConfigError(
            f"{where} is not an environment id such as 'CartPole-v1' or 'module:Name-v0'."
        )
    try:
        namespace, base, version = parse_env_id(name)
    except gym_error.Error:
        raise ConfigError(
            f"{where} is not an environment id such as 'CartPole-v1' ([namespace/]name-vN)."
        ) from None
    if module:
        parts = module.split(".")
        if not all(part.isidentifier() for part in parts):
            raise ConfigError(f"{where}: {shown(module)} before ':' is not a module name.")
        if module not in sys.modules and importlib.util.find_spec(parts[0]) is None:
            raise ConfigError(
                f"{where}: the module {shown(parts[0])} cannot be imported (no module of that "
                "name is installed); install it, or check the part of env.id before ':'."
            )
        return  # the module registers it when gymnasium.make imports it
    if name in registry:
        return
    latest = find_highest_version(namespace, base) if version is None else None
    if latest is not None:
        versioned = get_env_id(namespace, base, latest)
        raise ConfigError(
            f"{where} gives no version; write {versioned!r} (the latest version Gymnasium "
            "has), so that the run records which environment it trained on."
        )
    close = difflib.get_close_matches(name, list(registry), n=1, cutoff=0.6)
    hint = f"; did you mean {close[0]!r}?" if close else "."
    raise ConfigError(
        f"{where} is not a registered Gymnasium environment{hint} An environment another "
        "package registers is made as 'package:Name-v0' (which imports that package)."
    )


def env_module(env_id: str) -> str | None:
    """The module ``env.id`` asks Gymnasium to import (``module:Name-v0``), if any.

    >>> env_module("mygame.envs:Maze-v0"), env_module("CartPole-v1")
    ('mygame.envs', None)
    """
    module, colon, _ = env_id.partition(":")
    return module if colon and module else None


def check_recorded_env_id(env_id: str, where: str) -> None:
    """Refuse a config read back from a directory whose ``env.id`` would import a module.

    Importing runs the module's code. cartpole-q imports what ``env.id`` names only
    from a config the user gives (``train``, ``sweep``, ``tune``, ``load_config``), never
    from one it reads back to evaluate, plot or compare (a run directory may come from
    anyone), unless that module is imported already: from Python, import it first.

    Raises:
        RunError: naming ``where`` (the config file) and the module.
    """
    module = env_module(env_id)
    if module is None or module in sys.modules:
        return
    raise RunError(
        f"{where}: env.id: {shown(env_id)} would import the module {shown(module)}, which "
        "runs its code; cartpole-q imports a module named by env.id only from a config you "
        "give it (train, sweep, tune), never from a run or sweep directory it reads. To use "
        f"this run, import {module} yourself and call the Python API (cartpole_q.load_run)."
    )


def kwargs_error(env: EnvConfig, error: Exception, source: str | Provenance) -> ConfigError:
    """The config error for an environment that refused its arguments, naming the key.

    The key is the one the error names (an unexpected keyword, a value it could not look
    up), else the only one given; else all of them.

    >>> from cartpole_q.config import load_config
    >>> env = load_config(overrides={"env.kwargs.map_name": "9x9"}).env
    >>> str(kwargs_error(env, KeyError("9x9"), "a.yaml")).split(":")[:2]
    ['a.yaml', ' env.kwargs.map_name']
    """
    kwargs = dict(env.kwargs)
    text = str(error)
    named = [key for key in kwargs if f"'{key}'" in text or f"`{key}`" in text]
    if not named and isinstance(error, KeyError) and error.args:
        named = [key for key, value in kwargs.items() if value == error.args[0]]
    if not named and len(kwargs) == 1:
        named = list(kwargs)
    field = f"env.kwargs.{shorten(named[0])}" if len(named) == 1 else "env.kwargs"
    given = (
        f"{shorten(named[0])}={shown(kwargs[named[0]])}"
        if len(named) == 1
        else shorten(", ".join(f"{key}={shown(value)}" for key, value in kwargs.items()))
    )
    # The environment's message may quote the whole value it refused: cut it too.
    detail = shorten(f"{type(error).__name__}: {text}" if text else type(error).__name__, 200)
    return ConfigError(
        f"{blame(source, field)}: {field}: {shown(env.id)} cannot be made with {given or 'no arguments'} "
        f"({detail}); check the value against the environment's documentation."
    )


DECLARED_ELSEWHERE: Mapping[tuple[str, str], Rule] = {
    # Gymnasium writes `goal_velocity=0` with no annotation, but documents a float velocity
    # (and MountainCar's compiled twin takes any finite number): 0 is no whole-number rule.
    ("gymnasium.envs.classic_control.mountain_car:MountainCarEnv", "goal_velocity"): NUMBER,
}
"""the rules of arguments whose signature says less than their documentation, by the
constructor (``module:qualname``) and the argument"""


def check_env_kwargs(env: EnvConfig, spec: Any, source: str | Provenance = "config") -> None:
    """Refuse an ``env.kwargs`` value of a type the world's constructor does not take.

    The constructor is the entry point of the registered ``spec``; what each argument takes
    is read from its signature (:mod:`cartpole_q.envs.arguments`). The arguments
    ``gymnasium.make`` takes itself (``max_episode_steps``, ``disable_env_checker``,
    ``render_mode``) are not the constructor's (the config's reading checks the time limit
    and refuses a render mode); a key the constructor does not name, or a constructor whose
    signature cannot be read, is left to ``gymnasium.make``, which names what it refuses.

    >>> import gymnasium
    >>> from cartpole_q.config import load_config
    >>> env = load_config(overrides={"env.id": "FrozenLake-v1", "env.kwargs.is_slippery": 1}).env
    >>> check_env_kwargs(env, gymnasium.spec("FrozenLake-v1"), "a.yaml")
    Traceback (most recent call last):
    ...
    cartpole_q.errors.ConfigError: a.yaml: env.kwargs.is_slippery: 'FrozenLake-v1' expects is_slippery to be a boolean (true or false), got 1 (a number); FrozenLakeEnv declares is_slippery: bool = True.

    Raises:
        ConfigError: naming ``env.kwargs.<key>``, what the world expects and what was given.
    """
    import inspect

    import gymnasium
    from gymnasium.envs.registration import load_env_creator

    make_parameters = inspect.signature(gymnasium.make).parameters.values()
    own = {p.name for p in make_parameters if p.kind is not p.VAR_KEYWORD} | {"render_mode"}
    entry_point = spec.entry_point
    try:
        creator = load_env_creator(entry_point) if isinstance(entry_point, str) else entry_point
        owner, parameters, namespace = constructor_parameters(creator)
    except Exception:  # an entry point that cannot be read: gymnasium.make says what is wrong
        return
    where = f"{getattr(creator, '__module__', '')}:{getattr(creator, '__qualname__', '')}"
    for name, value in env.kwargs.items():
        parameter = parameters.get(name)
        if name in own or parameter is None:
            continue
        rule = DECLARED_ELSEWHERE.get((where, name)) or rule_of(parameter, namespace)
        if rule is None or rule.accepts(value):
            continue
        field = f"env.kwargs.{shorten(name)}"
        given = "null" if value is None else f"{shown_value(value)} (a {type_name(value)})"
        raise ConfigError(
            f"{blame(source, field)}: {field}: {shown(env.id)} expects {shorten(name)} to be "
            f"{rule.text}, got {given}; {owner} declares {shorten(declared(parameter))}."
        )


def set_physics(env: Any, physics: Mapping[str, float | str]) -> None:
    """Set physics on ``env.unwrapped`` as the environment's profile does it.

    CartPole's recomputes ``total_mass`` and ``polemass_length`` exactly as
    ``CartPoleEnv.__init__`` does; setting the attributes alone would leave them stale
    (ray #14090).
    """
    spec = getattr(env, "spec", None)
    env_id = spec.id if spec is not None else ""
    physics_spec = profile_for(env_id).physics
    if physics_spec is None or physics_spec.apply is None:
        raise ConfigError(f"env.physics: {env_id!r} has no physics to set.")
    physics_spec.apply(env, physics)


def info_value(info: Mapping[str, Any], key: str, env_id: str) -> float:
    """A step's ``info[key]`` as a number: a bool counts 1 or 0.

    >>> info_value({"left_from_a": True}, "left_from_a", "w"), info_value({"x": 2}, "x", "w")
    (1.0, 2.0)

    Raises:
        RunError: the step's info lacks ``key``, or its value is not a bool or a real number.
    """
    if key not in info:
        reported = ", ".join(sorted(map(str, info))) or "nothing"
        raise RunError(
            f"train.info_metric: {key}: a step of {env_id} has no such key in its info (it "
            f"reported: {reported}); name a key the environment reports at every step."
        )
    value = info[key]
    if isinstance(value, bool | np.bool_ | numbers.Real):
        return float(value)
    raise RunError(
        f"train.info_metric: {key}: {env_id} reports a {type(value).__name__} there "
        f"({shown(value)}); only a bool or a number can be summed per episode."
    )


def inspected_fields(config: Config) -> str:
    """What :func:`inspect_env` reads of a config, as text: configs alike here share its facts.

    Keep it in step with :func:`inspect_env` (a study reuses the facts of one point for
    the points that agree here; tests compare the two for many configs).
    """
    return repr(
        (
            config.env,
            config.discretization,
            config.agent.max_q_table_bytes,
            config.agent.initial_values,
            config.train.info_metric,
            config.train.reward_threshold,
        )
    )


def inspect_env(config: Config, source: str | Provenance = "config") -> EnvInfo:
    """Make the config's environment once and check that the config can train on it.

    Args:
        config: the validated config.
        source: the config's file (or another label) for error messages.

    Raises:
        ConfigError: naming ``env.id``, ``env.kwargs``, ``discretization`` or
            ``agent.max_q_table_bytes``, when the environment cannot be made or an
            ``env.kwargs`` value does not fit its constructor's signature, its actions
            are not a Discrete from 0, its observations not a 1-D Box, a Discrete or a Tuple
            of Discrete spaces, a Box has no grid or one of another dimension, a Discrete
            observation is given a grid, or the Q-table would exceed the size limit.
    """
    import gymnasium
    from gymnasium import spaces

    env_id = config.env.id
    # Before the world is made: its constructor may take a value of the wrong type silently.
    registered = gymnasium.registry.get(env_id.rpartition(":")[2])
    if registered is not None:
        check_env_kwargs(config.env, registered, source)
    env = make_env(config.env, source=source)
    try:
        observation_space, action_space, spec = env.observation_space, env.action_space, env.spec
        if registered is None and spec is not None:  # registered by the module make imported
            check_env_kwargs(config.env, spec, source)
        try:  # some arguments are only used, and refused, at the first reset
            env.reset(seed=0)
        except Exception as error:
            raise kwargs_error(config.env, error, source) from None
        if config.train.info_metric is not None:
            _check_info_metric(env, config.train.info_metric, env_id, source)
    finally:
        env.close()
    if not isinstance(action_space, spaces.Discrete) or int(action_space.start) != 0:
        raise ConfigError(
            f"{blame(source, 'env.id')}: env.id: {env_id!r} has action space {action_space}; tabular "
            "Q-learning here needs Discrete actions numbered from 0."
        )
    index_starts = _index_starts(observation_space)
    if index_starts is not None:
        components = (
            observation_space.spaces
            if isinstance(observation_space, spaces.Tuple)
            else (observation_space,)
        )
        state_shape = tuple(int(getattr(space, "n", 0)) for space in components)
        observation_dim = len(state_shape)
        if config.discretization is not None:
            raise ConfigError(
                f"{blame(source, 'discretization')}: discretization: {env_id!r} has observation space "
                f"{observation_space}, whose observations index the Q-table directly (shape "
                f"{(*state_shape, int(action_space.n))}); a grid bins only Box observations, "
                "so leave discretization out (or set it to null)."
            )
        largest = max(
            max(abs(start), abs(start + n - 1))
            for start, n in zip(index_starts, state_shape, strict=True)
        )
        if largest >= EXACT_INTEGERS:
            raise ConfigError(
                f"{blame(source, 'env.id')}: env.id: {env_id!r} has observation space "
                f"{observation_space}, whose values reach {largest}; the engines take "
                "observations as float64 values, exact only below 2**53, so number them "
                "closer to 0 (a Discrete's start)."
            )
        field = "env.id"
    elif isinstance(observation_space, spaces.Box) and len(observation_space.shape) == 1:
        observation_dim = int(observation_space.shape[0])
        if config.discretization is None:
            raise ConfigError(
                f"{blame(source, 'discretization')}: discretization: {env_id!r} has observation space "
                f"{observation_space}, which needs a grid: give discretization.bins, low "
                f"and high, one entry per dimension ({observation_dim})."
            )
        state_shape = config.discretization.bins
        if len(state_shape) != observation_dim:
            raise ConfigError(
                f"{blame(source, 'discretization.bins')}: discretization.bins: has {len(state_shape)} entries but "
                f"{env_id!r} observations have {observation_dim} dimensions; give bins, low "
                "and high one entry per dimension."
            )
        field = "discretization.bins"
        # On tiles: the weights of T tilings, each bins + 1 tiles wide (cartpole_q.rl.tiles).
        state_shape = config.discretization.table_shape
    else:
        raise ConfigError(
            f"{blame(source, 'env.id')}: env.id: {env_id!r} has observation space {observation_space}; "
            "tabular learning here needs a 1-D Box (binned by discretization), a Discrete, "
            "or a Tuple of Discrete spaces."
        )
    n_actions = int(action_space.n)
    table_bytes = q_table_bytes(state_shape, n_actions)
    limit = config.agent.max_q_table_bytes
    if table_bytes > limit:
        fewer = "use fewer bins" if index_starts is None else "use a smaller environment"
        raise ConfigError(
            f"{blame(source, field)}: {field}: the Q-table would hold {math.prod(state_shape):,} "
            f"states x {n_actions} actions = {memory_text(table_bytes)}, above the limit of "
            f"{memory_text(limit)} (agent.max_q_table_bytes); {fewer} or raise the limit."
        )
    starts = config.agent.initial_values
    if starts is not None and len(starts) != math.prod(state_shape):
        raise ConfigError(
            f"{blame(source, 'agent.initial_values')}: agent.initial_values: has "
            f"{len(starts)} values but the table of {env_id!r} has "
            f"{math.prod(state_shape):,} states; give one value per state, in the order of "
            "the observations (a terminal state's too, though it is never read)."
        )
    max_steps = config.env.kwargs.get("max_episode_steps", spec.max_episode_steps if spec else None)
    threshold = _threshold_of(config, spec)
    return EnvInfo(
        id=env_id,
        observation_dim=observation_dim,
        n_actions=n_actions,
        reward_threshold=threshold,
        max_episode_steps=max_steps,
        state_shape=tuple(state_shape),
        index_starts=index_starts,
    )


def _check_info_metric(env: Any, key: str, env_id: str, source: str | Provenance) -> None:
    """Refuse a ``train.info_metric`` the environment's first step does not report.

    One step (action 0) after the reset; training checks every step the same way.
    """
    _, _, _, _, info = env.step(0)
    try:
        info_value(info, key, env_id)
    except RunError as error:
        raise ConfigError(f"{blame(source, 'train.info_metric')}: {error}") from None


EXACT_INTEGERS = 2**53
"""Discrete observations must stay below this in magnitude: the gymnasium engine passes every
observation to compiled code as float64 values, exact only below 2**53"""


def _index_starts(space: Any) -> tuple[int, ...] | None:
    """The ``start`` of each Discrete component, or ``None`` if not Discrete / Tuple of them."""
    from gymnasium import spaces

    if isinstance(space, spaces.Discrete):
        return (int(space.start),)
    if (
        isinstance(space, spaces.Tuple)
        and space.spaces
        and all(isinstance(component, spaces.Discrete) for component in space.spaces)
    ):
        return tuple(int(getattr(component, "start", 0)) for component in space.spaces)
    return None


def registered_spec(env: EnvConfig, source: str | Provenance = "config") -> Any:
    """The Gymnasium spec ``env.id`` is registered under; the world is not made.

    A plug-in world's id (``module:Name-v0``) imports its module first, as ``gymnasium.make``
    would, which registers it.

    Raises:
        ConfigError: naming ``env.id``: as :func:`check_env_id`, its module cannot be
            imported, or it registers no such id.
    """
    import importlib

    import gymnasium

    module, _, name = env.id.rpartition(":")
    spec = gymnasium.registry.get(name)
    if spec is None:
        check_env_id(env.id, source)
        if module:
            try:
                importlib.import_module(module)
            except Exception as error:  # (a module's own code runs: anything may fail)
                detail = shorten(str(error).split(". ")[0], 200)
                raise ConfigError(
                    f"{blame(source, 'env.id')}: env.id: cannot make {env.id!r}: the module "
                    f"{module!r} cannot be imported ({type(error).__name__}: {detail}); "
                    "install it, or check the part of env.id before ':'."
                ) from None
        spec = gymnasium.registry.get(name)
    if spec is None:
        raise ConfigError(
            f"{blame(source, 'env.id')}: env.id: {env.id!r}: importing {module} registers no "
            f"environment named {name!r}; give an id it registers."
        )
    return spec


def config_time_limit(config: Config) -> int | None:
    """The time limit a config's episodes have (``None``: none), from the registry.

    ``env.kwargs.max_episode_steps``, else the id's registered one, as
    :attr:`EnvInfo.max_episode_steps` has it; the world is not made.

    Raises:
        ConfigError: as :func:`registered_spec`.
    """
    limit = config.env.kwargs.get(
        "max_episode_steps", registered_spec(config.env).max_episode_steps
    )
    return None if limit is None else int(limit)


def config_threshold(config: Config) -> float | None:
    """The reward threshold a config's runs are judged by (``None`` without one).

    From the config and Gymnasium's registry (the id's registered threshold and time limit):
    the world is not made, so a run directory's reader can ask cheaply.

    Raises:
        ConfigError: as :func:`registered_spec`.
    """
    if config.train.reward_threshold is not None:
        return config.train.reward_threshold
    return _threshold_of(config, registered_spec(config.env))


def _threshold_of(config: Config, spec: Any) -> float | None:
    """:func:`config_threshold` given the environment's spec (``None``: it has none)."""
    threshold = config.train.reward_threshold
    if threshold is None and spec is not None and spec.reward_threshold is not None:
        max_steps = config.env.kwargs.get("max_episode_steps", spec.max_episode_steps)
        threshold = _default_threshold(config.env.id, float(spec.reward_threshold), max_steps)
    return threshold


def _default_threshold(env_id: str, registered_threshold: float, max_steps: Any) -> float:
    """The solve threshold when the config gives none: the environment's registered one.

    Where the profile says so (CartPole), it scales with a changed time limit:
    ``threshold * max_episode_steps / registered max_episode_steps`` (475 of 500 steps
    becomes 950 of 1000).
    """
    import gymnasium

    if not profile_for(env_id).threshold_scales:
        return registered_threshold
    if not isinstance(max_steps, int) or isinstance(max_steps, bool):
        return registered_threshold
    registered_steps = gymnasium.spec(env_id).max_episode_steps
    if not registered_steps or max_steps <= 0 or max_steps == registered_steps:
        return registered_threshold
    return registered_threshold * max_steps / registered_steps


def q_table_bytes(bins: tuple[int, ...], n_actions: int) -> int:
    """Bytes of a float64 Q-table of shape ``(*bins, n_actions)``."""
    return math.prod(bins) * n_actions * 8


def has_display() -> bool:
    """Whether a window can be opened here (see :func:`display_problem`)."""
    return display_problem() is None


def display_problem(timeout: float = 2.0) -> str | None:
    """Why Gymnasium's window cannot be shown here, or ``None`` when it can.

    On Linux and BSD, an X11 or Wayland display must be set *and* answer: its socket is
    connected to (``/tmp/.X11-unix/X<n>`` for ``DISPLAY=:n``, TCP port ``6000+n`` on a
    host, ``$XDG_RUNTIME_DIR/$WAYLAND_DISPLAY``), because pygame otherwise falls back to
    its offscreen driver and shows nothing. ``SDL_VIDEODRIVER=dummy`` (or ``offscreen``)
    draws nowhere either. macOS and Windows open windows without these variables.
    """
    if sys.platform == "darwin" or sys.platform.startswith("win"):
        return None
    x11, wayland = os.environ.get("DISPLAY"), os.environ.get("WAYLAND_DISPLAY")
    if not x11 and not wayland:
        return "neither DISPLAY nor WAYLAND_DISPLAY is set"
    problems = []
    if wayland:
        problem = _wayland_problem(wayland)
        if problem is None:
            return _driver_problem()
        problems.append(problem)
    if x11:
        problem = _x11_problem(x11, timeout)
        if problem is None:
            return _driver_problem()
        problems.append(problem)
    return "; ".join(problems)


def _driver_problem() -> str | None:
    drivers = {d.strip().lower() for d in os.environ.get("SDL_VIDEODRIVER", "").split(",")}
    if drivers and drivers <= {"dummy", "offscreen"}:
        return (
            f"SDL_VIDEODRIVER={os.environ['SDL_VIDEODRIVER']} is set, which makes pygame draw "
            "the window nowhere; unset it"
        )
    return None


def _x11_problem(display: str, timeout: float) -> str | None:
    """Connect to the X server of ``display`` (``[host]:number[.screen]``)."""
    import socket

    host, _, rest = display.rpartition(":")
    number = rest.split(".")[0]
    if not number.isdigit():
        return f"DISPLAY={display} is not an X display name such as :0"
    if host in ("", "unix") or host.startswith("/"):
        path = host if host.startswith("/") else f"/tmp/.X11-unix/X{number}"
        candidates = [path]
        if sys.platform.startswith("linux"):
            candidates.append("\0" + path)  # the abstract socket Xorg also listens on
        for candidate in candidates:
            with socket.socket(socket.AF_UNIX, socket.SOCK_STREAM) as connection:
                connection.settimeout(timeout)
                try:
                    connection.connect(candidate)
                except OSError:
                    continue
                return None
        return f"DISPLAY={display} cannot be reached (no X server listens on {path})"
    port = 6000 + int(number)
    try:
        socket.create_connection((host.strip("[]"), port), timeout=timeout).close()
    except OSError as error:
        reason = error.strerror or str(error) or type(error).__name__
        return f"DISPLAY={display} cannot be reached (no X server at {host}, port {port}: {reason})"
    return None


def _wayland_problem(name: str) -> str | None:
    """Connect to the Wayland compositor's socket."""
    import socket

    runtime = os.environ.get("XDG_RUNTIME_DIR")
    if not os.path.isabs(name) and not runtime:
        return f"WAYLAND_DISPLAY={name} is set but XDG_RUNTIME_DIR, where its socket is, is not"
    path = name if os.path.isabs(name) else os.path.join(runtime or "", name)
    with socket.socket(socket.AF_UNIX, socket.SOCK_STREAM) as connection:
        try:
            connection.connect(path)
        except OSError:
            return f"WAYLAND_DISPLAY={name} cannot be reached (nothing listens on {path})"
    return None
