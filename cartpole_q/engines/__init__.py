"""Training engines: ``gymnasium`` (real environments) and ``numba`` (compiled twins).

Both drive the same compiled step functions with the same random draws; choosing one
changes speed, never results. Engine modules are imported only when an engine is made, so
this package costs nothing to import.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from cartpole_q.config import Config, ConfigError, Provenance, blame
from cartpole_q.engines.base import AgentParams, Engine
from cartpole_q.envs.gym import EnvInfo

if TYPE_CHECKING:  # the registry loads when an engine is made, not when this is imported
    from cartpole_q.envs.registry import TwinSettings


def resolve_engine(config: Config, env_info: EnvInfo, source: str | Provenance = "config") -> str:
    """Return the engine that will run: ``auto`` becomes numba where a twin exists.

    See :func:`engine_and_twin`, which also gives the twin's settings.
    """
    return engine_and_twin(config, env_info, source)[0]


def engine_and_twin(
    config: Config, env_info: EnvInfo, source: str | Provenance = "config"
) -> tuple[str, TwinSettings | None]:
    """The engine that will run (``auto`` resolved) and, on the numba engine, its twin.

    ``auto`` becomes numba where a twin exists. A config with ``train.info_metric`` runs on
    the gymnasium engine: the compiled twins report no ``info``, so ``auto`` takes
    gymnasium and ``numba`` is refused.

    Raises:
        ConfigError: ``engine: numba`` was asked for an environment no twin reproduces, or
            with ``train.info_metric`` (the message names the id or key).
    """
    from cartpole_q.envs.registry import TwinSettings, twin_settings

    if config.engine == "gymnasium":
        return "gymnasium", None
    info_key = config.train.info_metric
    if info_key is not None:
        if config.engine == "numba":
            raise ConfigError(
                f"{blame(source, 'engine')}: engine: numba cannot record train.info_metric "
                f"({info_key}): the compiled twins report no info. Use engine: gymnasium (or "
                "auto, which takes it for such a config), or leave train.info_metric out."
            )
        return "gymnasium", None
    settings = twin_settings(
        config.env.id, config.env.kwargs, env_info.max_episode_steps, config.env.physics
    )
    if isinstance(settings, TwinSettings):
        return "numba", settings
    if config.engine == "numba":
        raise ConfigError(
            f"{blame(source, 'engine')}: engine: numba cannot run this config: {settings}. Use engine: "
            "gymnasium (or auto, which falls back to it)."
        )
    return "gymnasium", None


def _twin(config: Config, env_info: EnvInfo, twin: TwinSettings | None) -> TwinSettings:
    """``twin``, or the config's twin settings when the caller has none."""
    if twin is not None:
        return twin
    from cartpole_q.envs.registry import TwinSettings, twin_settings

    settings = twin_settings(
        config.env.id, config.env.kwargs, env_info.max_episode_steps, config.env.physics
    )
    assert isinstance(settings, TwinSettings), settings  # engine_and_twin checked it
    return settings


def check_prediction(config: Config, env_info: EnvInfo) -> None:
    """A prediction run's policy and true values, checked before any file is written.

    The policy of ``agent.policy_run`` is read and checked against this config's world and
    table, and the true values are solved (kept for the run in this process): a policy
    with no values (``agent.gamma`` 1 and an episode that may never end) is refused here,
    not after the run directory exists. Nothing happens for a control algorithm.

    Raises:
        ConfigError: naming ``agent.policy_run`` or ``agent.policy``.
    """
    from cartpole_q.engines.base import prediction_truth
    from cartpole_q.rl.algorithms import get as get_algorithm

    if get_algorithm(config.agent.algorithm).predicts:
        prediction_truth(config, env_info)


def make_engine(
    name: str,
    config: Config,
    env_info: EnvInfo,
    env_seed: int,
    env_rng_state: dict[str, Any] | None = None,
    twin: TwinSettings | None = None,
    greedy_loop: bool | None = None,
) -> Engine:
    """Build the named engine for a config, seeding its environment with ``env_seed``.

    ``env_rng_state`` restores a checkpointed environment generator instead; ``twin`` is
    the twin's settings when the caller has them (a :class:`~cartpole_q.engines.plan.Plan`);
    ``greedy_loop`` is the numba engine's (see
    :class:`~cartpole_q.engines.numba_engine.NumbaEngine`).
    """
    params = AgentParams.from_config(config, env_info)
    if name == "numba":
        from cartpole_q.engines.numba_engine import NumbaEngine

        settings = _twin(config, env_info, twin)
        return NumbaEngine(
            settings, params, env_seed, env_rng_state, config.env.randomize, greedy_loop
        )
    from cartpole_q.engines.gymnasium_engine import GymnasiumEngine
    from cartpole_q.envs.models import GREEDY_STEP_CAP

    step_cap = None if env_info.max_episode_steps else GREEDY_STEP_CAP
    return GymnasiumEngine(config, params, env_seed, env_rng_state, step_cap)


def loop_names(
    config: Config,
    env_info: EnvInfo,
    engine: str,
    twin: TwinSettings | None = None,
    greedy_loop: bool | None = None,
) -> tuple[str, ...]:
    """The compiled loops a run of ``config`` on ``engine`` calls, as numba's cache names them.

    On the numba engine, the training loops its epsilon plays over ``train.episodes`` (see
    :func:`~cartpole_q.engines.base.loops_played`) on ``twin`` (the config's twin when
    ``None``), the greedy loop after exploring episodes only where
    :func:`~cartpole_q.engines.base.exploring_plays_greedy` says (as the engine decides);
    on the gymnasium engine, its step functions (named by the one that learns).
    """
    from cartpole_q.engines.base import (
        epsilon_record,
        exploring_plays_greedy,
        kernel_name,
        loops_played,
        step_function_name,
    )
    from cartpole_q.rl.algorithms import get as get_algorithm

    algorithm = get_algorithm(config.agent.algorithm)
    grid = config.discretization
    tiled = grid is not None and grid.tilings > 1
    averaged = config.agent.alpha.averages
    if engine == "numba":
        settings = _twin(config, env_info, twin)
        randomized = bool(config.env.randomize)
        epsilon, episodes = epsilon_record(config), config.train.episodes
        names = {
            greedy: kernel_name(algorithm.key, settings.twin.key, randomized, tiled, greedy, averaged)
            for greedy in (False, True)
        }  # fmt: skip
        played = loops_played(epsilon, 0, episodes)
        limit = settings.max_episode_steps
        if exploring_plays_greedy(greedy_loop, names[True], epsilon, episodes, limit):
            played = (False,)
        return tuple(names[greedy] for greedy in played)
    kind = "tiles" if tiled else "values"  # (every other observation as float64 values)
    return (step_function_name("next_step", algorithm.key, kind, averaged),)


def compile_notice(
    config: Config, env_info: EnvInfo, engine: str, twin: TwinSettings | None = None
) -> str | None:
    """What to tell a user before a run whose compiled loop is not in numba's cache yet.

    Returns:
        A sentence (the first run on a machine compiles for several seconds), or ``None``
        when the loop is cached. An algorithm registered from outside the package (a
        plug-in) compiles once per version of its module, for longer: nothing of it is
        cached with the package's loops.
    """
    from cartpole_q.numba_cache import is_cached
    from cartpole_q.rl.algorithms import get as get_algorithm

    if all(is_cached(name) for name in loop_names(config, env_info, engine, twin)):
        return None
    module = get_algorithm(config.agent.algorithm).step.__module__
    if module.partition(".")[0] != __name__.partition(".")[0]:
        when = f"once per version of its module {module}, up to a minute"
    else:
        when = "once per machine and version, a few seconds"
    return (
        f"compiling the training loop for {config.agent.algorithm} on {config.env.id} "
        f"({engine} engine): {when}..."
    )
