"""The run configuration: its schema, and loading it from YAML, names and overrides.

This package imports neither numpy, numba nor gymnasium, so that the command line starts
fast.

>>> config = load_config()
>>> config.env.id, config.discretization.bins
('CartPole-v1', (1, 1, 2, 10))
"""

from cartpole_q.config.loading import (
    NOT_SET,
    OVERRIDE_SOURCE,
    Provenance,
    blame,
    check_known_keys,
    config_differences,
    default_raw,
    default_yaml_text,
    load_config,
    mapping_differences,
    parse_assignment,
    parse_seeds,
    read_yaml_mapping,
    resolve_config_path,
    shipped_configs,
    shown_value,
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
    Schedule,
    TrainConfig,
    format_seeds,
)
from cartpole_q.errors import ConfigError
from cartpole_q.rl.schedules import SCHEDULE_KINDS

__all__ = [
    "ENGINES",
    "MAX_EPISODES",
    "MAX_SEED",
    "MAX_SEEDS",
    "NOT_SET",
    "OVERRIDE_SOURCE",
    "SCHEDULE_KINDS",
    "AgentConfig",
    "Config",
    "ConfigError",
    "DiscretizationConfig",
    "EnvConfig",
    "EvalConfig",
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
    "mapping_differences",
    "parse_assignment",
    "parse_seeds",
    "read_yaml_mapping",
    "resolve_config_path",
    "shipped_configs",
    "shown_value",
]
