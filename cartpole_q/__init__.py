"""cartpole-q: tabular Q-learning on Gymnasium's CartPole-v1, solved in seconds.

The Python API, for notebooks and scripts (imported lazily, so the command line starts fast):

- :func:`load_config` -- read and validate a YAML config (``None``: the embedded default);
- :func:`train` -- train a config, returning a :class:`~cartpole_q.training.TrainResult`;
- :func:`evaluate` -- play a Q-table's greedy policy in ``gymnasium.make``;
- :func:`write_run` / :func:`load_run` -- save a result as a run directory, read one back.
"""

from __future__ import annotations

from importlib import import_module
from typing import TYPE_CHECKING, Any

__version__ = "0.1.0"
__all__ = ["__version__", "evaluate", "load_config", "load_run", "train", "write_run"]

_LAZY = {
    "load_config": "cartpole_q.config",
    "train": "cartpole_q.training",
    "evaluate": "cartpole_q.evaluation",
    "load_run": "cartpole_q.rundir",
    "write_run": "cartpole_q.rundir",
}

if TYPE_CHECKING:
    from cartpole_q.config import load_config
    from cartpole_q.evaluation import evaluate
    from cartpole_q.rundir import load_run, write_run
    from cartpole_q.training import train


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        return getattr(import_module(_LAZY[name]), name)
    raise AttributeError(f"module 'cartpole_q' has no attribute {name!r}")
