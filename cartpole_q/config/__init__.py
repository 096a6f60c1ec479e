"""The run configuration: its schema, and loading it from YAML, names and overrides.

One module per concern: :mod:`~cartpole_q.config.schema` (the dataclasses and their keys'
metadata), :mod:`~cartpole_q.config.yaml_io` (safe YAML, the shipped configs),
:mod:`~cartpole_q.config.overrides` (``--set``, merging, unknown keys),
:mod:`~cartpole_q.config.validation` (the readers and the cross-key rules),
:mod:`~cartpole_q.config.diff` (what differs between configs),
:mod:`~cartpole_q.config.loading` (:func:`load_config`, putting them together) and
:mod:`~cartpole_q.config.reference` (the configuration page's key table, generated).

This package imports neither numba nor gymnasium, so that the command line starts fast.

>>> config = load_config()
>>> config.env.id, config.discretization.bins
('CartPole-v1', (1, 1, 2, 10))
"""

from cartpole_q.config.diff import NOT_SET, config_differences, mapping_differences, shown_value
from cartpole_q.config.loading import load_config
from cartpole_q.config.messages import QUOTE_LIMIT, shorten, shown
from cartpole_q.config.overrides import (
    COMMAND_LINE,
    OVERRIDE_SOURCE,
    Provenance,
    blame,
    check_known_keys,
    parse_assignment,
)
from cartpole_q.config.schema import (
    ENGINES,
    MAX_EPISODES,
    MAX_SEED,
    MAX_SEEDS,
    AgentConfig,
    Config,
    DiscretizationConfig,
    EnvConfig,
    EvalConfig,
    Key,
    Schedule,
    TrainConfig,
    format_seeds,
)
from cartpole_q.config.validation import parse_seeds
from cartpole_q.config.yaml_io import (
    MAX_YAML_BYTES,
    default_raw,
    default_yaml_text,
    load_yaml_text,
    read_yaml_mapping,
    resolve_config_path,
    shipped_configs,
)
from cartpole_q.errors import ConfigError
from cartpole_q.rl.schedules import SCHEDULE_KINDS

__all__ = [
    "COMMAND_LINE",
    "ENGINES",
    "MAX_EPISODES",
    "MAX_SEED",
    "MAX_SEEDS",
    "MAX_YAML_BYTES",
    "NOT_SET",
    "OVERRIDE_SOURCE",
    "QUOTE_LIMIT",
    "SCHEDULE_KINDS",
    "AgentConfig",
    "Config",
    "ConfigError",
    "DiscretizationConfig",
    "EnvConfig",
    "EvalConfig",
    "Key",
    "Provenance",
    "Schedule",
    "TrainConfig",
    "blame",
    "check_known_keys",
    "config_differences",
    "default_raw",
    "default_yaml_text",
    "format_seeds",
    "load_config",
    "load_yaml_text",
    "mapping_differences",
    "parse_assignment",
    "parse_seeds",
    "read_yaml_mapping",
    "resolve_config_path",
    "shipped_configs",
    "shorten",
    "shown",
    "shown_value",
]
