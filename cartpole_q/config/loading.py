"""Loading a run configuration: a file, a name or a mapping, over the default, overridden.

A config file may give only some keys; every key it leaves out takes the value of the
embedded default (``cartpole_q/default.yaml``). Loading never constructs Python objects
from YAML tags and never returns a half-checked config: it returns a frozen
:class:`Config` or raises :class:`ConfigError`, whose message names the file and field.

This module imports neither numba nor gymnasium, so that ``cartpole-q --help`` stays fast.

>>> config = load_config()
>>> config.env.id, config.discretization.bins
('CartPole-v1', (1, 1, 2, 10))
>>> load_config(overrides={"agent.alpha": "5e-4"}).agent.alpha
Schedule(kind='constant', start=0.0005, end=0.0005, rate=1.0)
"""

from __future__ import annotations

import os
import re
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from cartpole_q.config.overrides import (
    OVERRIDE_SOURCE,
    Provenance,
    check_known_keys,
    leaf_paths,
    merge,
    nest,
    refuse_study_file,
)
from cartpole_q.config.schema import Config
from cartpole_q.config.validation import read_config
from cartpole_q.config.yaml_io import default_raw, read_yaml_mapping, resolve_config_path
from cartpole_q.families import profile_for

ConfigSource = str | os.PathLike[str] | Mapping[str, Any]
"""What :func:`load_config` reads: a YAML file, a shipped config's name, or a mapping."""


def load_config(
    path: ConfigSource | None = None,
    overrides: Mapping[str, Any] | None = None,
    *,
    source: str | None = None,
    override_source: str | None = None,
) -> Config:
    """Load, complete and validate a config.

    Overrides merge exactly as a config file does: a section or schedule mapping merges
    key by key (``{"agent": {"gamma": 0.9}}`` keeps ``agent.alpha``; ``agent.epsilon.k``
    keeps the schedule's other fields), anything else replaces, and unknown keys are
    refused with the closest valid key suggested.

    >>> load_config("blog").name
    'blog'
    >>> load_config({"agent": {"gamma": 0.9}}, {"agent.epsilon.k": 25}).agent.epsilon
    Schedule(kind='log', start=1.0, end=0.0, rate=25.0)

    Args:
        path: a YAML file, the name of a shipped config (``"blog"``, see
            :func:`shipped_configs`), or a mapping laid out like a config file; ``None``
            loads the embedded default alone.
        overrides: dotted keys (``"train.episodes"``, ``"env.kwargs.max_episode_steps"``)
            or section names with mappings, and the values that replace the file's (as
            ``--set`` gives them on the command line); applied in order.
        source: how errors name ``path`` (default: the file, or "config mapping").
        override_source: how errors name the overrides (default: "overrides", this
            argument; the command line passes "command line", a sweep names its file and
            point).

    Returns:
        The validated, frozen config.

    Raises:
        ConfigError: the file cannot be read or parsed, or a key or value is invalid.
    """
    raw = default_raw()
    named = "default config"
    if isinstance(path, Mapping):
        named = "config mapping"
        user: Mapping[Any, Any] = path
    elif path is not None:
        file = resolve_config_path(path)
        named = str(path) if file == Path(path) else str(file)
        user = read_yaml_mapping(file)
        refuse_study_file(user, named)
    else:
        user = {}
    named = source or named
    override_source = override_source or OVERRIDE_SOURCE
    check_known_keys(user, named)
    raw = merge(raw, user)
    overridden: list[str] = []
    for dotted, value in (overrides or {}).items():
        nested = nest(dotted, value, override_source)
        check_known_keys(nested, override_source)
        raw = merge(raw, nested)
        overridden.extend(leaf_paths(nested))
    raw = _without_default_grid(raw, user, overridden)
    raw = _named_after_env(raw, user, overridden)
    return read_config(raw, Provenance(named, tuple(overridden), override_source))


def _named_after_env(
    raw: dict[str, Any], user: Mapping[Any, Any], overridden: list[str]
) -> dict[str, Any]:
    """Name a run of another environment after it when the config gives no ``name``.

    The default's ``name: default`` describes its CartPole run; a config that moves to
    another ``env.id`` without naming itself (``--set env.id=FrozenLake-v1``) gets a
    name made from that id, so that its directory reads ``runs/frozenlake-...``. A
    ``name`` given by the file or an override is kept, ``default`` included.

    >>> load_config(overrides={"env.id": "FrozenLake-v1"}).name
    'frozenlake'
    >>> load_config({"name": "default", "env": {"id": "FrozenLake-v1"}}).name, load_config().name
    ('default', 'default')
    """
    default = default_raw()
    env = raw.get("env")
    env_id = env.get("id") if isinstance(env, dict) else None
    if "name" in user or "name" in overridden or raw.get("name") != default["name"]:
        return raw
    if not isinstance(env_id, str) or env_id == default["env"]["id"]:
        return raw
    return {**raw, "name": name_for_env(env_id) or default["name"]}


def name_for_env(env_id: str) -> str:
    """A run-name prefix made from an environment id: lower case, no namespace or version.

    >>> name_for_env("FrozenLake-v1"), name_for_env("cartpole_q/WindyGridworld-v0")
    ('frozenlake', 'windygridworld')
    >>> name_for_env("my_package.envs:Maze 2-v3")
    'maze-2'
    """
    stem = re.split(r"[/:]", env_id)[-1]
    stem = re.sub(r"-v\d+$", "", stem).lower()
    return re.sub(r"[^a-z0-9_-]+", "-", stem).strip("-")[:64]


def _without_default_grid(
    raw: dict[str, Any], user: Mapping[Any, Any], overridden: list[str]
) -> dict[str, Any]:
    """Drop the embedded default's grid for an environment other than CartPole.

    The default's ``discretization`` describes CartPole's four dimensions. A config that
    gives no ``discretization`` (neither the file nor an override) takes it only on
    CartPole; elsewhere it has none, which Discrete and Tuple-of-Discrete observations
    need (a Box observation then asks for one, see ``inspect_env``).
    """
    given = "discretization" in user or any(
        path == "discretization" or path.startswith("discretization.") for path in overridden
    )
    env = raw.get("env")
    if given or not isinstance(env, dict) or not isinstance(env.get("id"), str):
        return raw
    if profile_for(env["id"]).default_grid:
        return raw
    return {**raw, "discretization": None}
