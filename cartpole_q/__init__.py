"""cartpole-q: tabular Q-learning on Gymnasium's CartPole-v1, solved in seconds.

The Python API, for notebooks and scripts (imported lazily, so the command line starts fast):

- :func:`load_config` -- read and validate a config: a YAML file, a shipped config's name
  (``"blog"``), or a mapping (``{"agent": {"gamma": 0.9}}``); ``None``: the embedded default;
- :func:`train` -- train a config (a :class:`~cartpole_q.config.Config`, or anything
  :func:`load_config` takes), returning a :class:`~cartpole_q.training.TrainResult`;
- :func:`evaluate` -- play a Q-table's greedy policy in ``gymnasium.make``;
- :func:`write_run` / :func:`load_run` -- save a result as a run directory, read one back.

Importing the package registers Sutton & Barto's worlds (``cartpole_q/WindyGridworld-v0``
and others, :mod:`cartpole_q.families`) with Gymnasium, once Gymnasium is imported.
"""

from __future__ import annotations

from importlib import import_module
from typing import TYPE_CHECKING, Any

from cartpole_q.families.registration import register_when_gymnasium_is_imported

__version__ = "0.1.0"
__all__ = ["__version__", "evaluate", "load_config", "load_run", "train", "write_run"]

_LAZY = {
    "load_config": "cartpole_q.config",
    "evaluate": "cartpole_q.evaluation",
    "load_run": "cartpole_q.store.rundir",
    "write_run": "cartpole_q.store.rundir",
}

if TYPE_CHECKING:
    from collections.abc import Mapping
    from os import PathLike

    from cartpole_q.config import Config, load_config
    from cartpole_q.evaluation import evaluate
    from cartpole_q.store.rundir import load_run, write_run
    from cartpole_q.training import TrainResult


def train(
    config: Config | str | PathLike[str] | Mapping[str, Any] | None = None,
    *,
    quiet: bool = False,
    **options: Any,
) -> TrainResult:
    """Train a config; see :func:`cartpole_q.training.train` for ``options``.

    A run whose training loop is not in numba's cache yet (the first on a machine, or the
    first of an algorithm of your own) compiles it first, for seconds up to a minute; it
    says so on stderr, as ``cartpole-q train`` does.

    Args:
        config: a loaded config, or what :func:`load_config` takes: a YAML file
            (``"configs/blog.yaml"``), a shipped config's name, a mapping merged onto the
            default (``{"seed": 3}``), or ``None`` for the embedded default.
        quiet: print nothing, not even that the loop is being compiled.
        **options: passed on (``on_progress``, ``should_stop``, ...).

    Raises:
        ConfigError: the config is invalid or does not fit its environment.
    """
    import sys

    from cartpole_q.config import Config, load_config
    from cartpole_q.engines import compile_notice
    from cartpole_q.engines.plan import plan_run
    from cartpole_q.training import train as train_config

    if not isinstance(config, Config):
        config = load_config(config)
    plan = plan_run(config, env_info=options.pop("env_info", None))
    if not quiet:
        resume = options.get("resume")
        if resume is not None and resume.engine != plan.engine:
            notice = compile_notice(config, plan.env_info, resume.engine)
        else:
            notice = compile_notice(config, plan.env_info, plan.engine, plan.twin)
        if notice is not None:
            print(notice, file=sys.stderr, flush=True)
    return train_config(plan, **options)


# Every use of the package (the command line imports it too) can make the worlds' ids.
register_when_gymnasium_is_imported()


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        return getattr(import_module(_LAZY[name]), name)
    raise AttributeError(f"module 'cartpole_q' has no attribute {name!r}")
