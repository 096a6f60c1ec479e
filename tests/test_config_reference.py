"""One config schema: the dataclasses' metadata, the default file and the README agree."""

from __future__ import annotations

import dataclasses
import difflib
import subprocess
import sys

import pytest

from cartpole_q.config import Config, ConfigError, Provenance, default_raw, load_config
from cartpole_q.config.overrides import algorithm_param_keys
from cartpole_q.config.reference import HEADER, reference_table
from cartpole_q.config.schema import SCHEDULE_FORMS, key_of, sections
from cartpole_q.rl.schedules import SCHEDULE_KINDS
from tests.conftest import REPO


def _readme_table() -> str:
    # The README's ## Configuration moved to the documentation's configuration reference.
    section = (REPO / "docs" / "reference" / "configuration.md").read_text(encoding="utf-8")
    start = section.index(HEADER)
    return section[start : section.index("\n\n", start) + 1]


def test_the_readme_config_table_is_the_generated_one() -> None:
    # A fresh process: the registries hold the package's algorithms and environments only,
    # not the plug-ins other tests register.
    generated = subprocess.run(
        [sys.executable, "-m", "cartpole_q.config.reference"],
        capture_output=True, text=True, check=True, cwd=REPO,
    ).stdout  # fmt: skip
    readme = _readme_table()
    stale = "\n".join(difflib.unified_diff(readme.splitlines(), generated.splitlines(), "docs/reference/configuration.md", "schema", lineterm=""))  # fmt: skip
    assert readme == generated, (
        "the config table of docs/reference/configuration.md differs from the schema; paste "
        f"the output of `python -m cartpole_q.config.reference` there:\n{stale}"
    )


def _schema_keys(record: type, prefix: str = "") -> list[str]:
    """Every key a config file may hold, as the schema declares it (the algorithms' aside)."""
    keys: list[str] = []
    for item in dataclasses.fields(record):
        kind = key_of(item).kind
        if kind == "section":
            keys.append(f"{prefix}{item.name}")
            keys.extend(_schema_keys(sections()[item.name], f"{prefix}{item.name}."))
        elif kind != "params":
            keys.append(f"{prefix}{item.name}")
    return keys


def _file_keys(data: dict, prefix: str = "") -> list[str]:
    keys: list[str] = []
    for key, value in data.items():
        keys.append(f"{prefix}{key}")
        if key in sections():
            keys.extend(_file_keys(value, f"{prefix}{key}."))
    return keys


def test_default_yaml_has_every_schema_key_in_the_schema_order() -> None:
    assert _file_keys(default_raw()) == _schema_keys(Config)


def test_the_resolved_config_lists_its_keys_in_the_default_files_order() -> None:
    assert _file_keys(load_config().to_dict()) == _file_keys(default_raw())


def test_every_key_has_a_row_with_its_default_and_every_row_is_a_key() -> None:
    rows = {row[0].strip("| `"): row[1] for row in _rows(reference_table())}
    untitled = {item.name for item in dataclasses.fields(Config) if not key_of(item).doc}
    params = {f"agent.{key}" for key in algorithm_param_keys()}
    assert set(rows) == {key for key in _schema_keys(Config) if key not in untitled} | params
    assert rows["agent.gamma"] == f"`{default_raw()['agent']['gamma']}`"
    assert rows["train.seeds"] == "`null`"


def _rows(table: str) -> list[list[str]]:
    return [line.split(" | ") for line in table.splitlines()[2:]]


def test_an_algorithms_own_keys_get_rows_from_its_params() -> None:
    import tests.plugin_algorithm  # noqa: F401  (registers fixed_behaviour_expected_sarsa)

    table = reference_table()
    assert (
        "| `agent.behaviour` | `0.2` | the fixed exploration rate it acts with ([0, 1]; "
        "`fixed_behaviour_expected_sarsa` only) |"
    ) in table
    assert "`true_online_td_lambda` or `fixed_behaviour_expected_sarsa`" in table  # the last
    # the same Param checks the value
    with pytest.raises(ConfigError, match=r"agent\.behaviour: must be in \[0, 1\], got 2\.$"):
        load_config(
            overrides={"agent.algorithm": "fixed_behaviour_expected_sarsa", "agent.behaviour": 2}
        )


def test_ranges_in_the_docs_are_the_ranges_checked() -> None:
    table = reference_table()
    assert "| `agent.alpha` | `0.3` | learning rate in (0, 1]:" in table
    with pytest.raises(ConfigError, match=r"agent\.alpha: must be in \(0, 1\]"):
        load_config(overrides={"agent.alpha": 0})
    assert "`tau` (0, 1]" in table
    with pytest.raises(ConfigError, match=r"env\.physics\.tau: must be in \(0, 1\]"):
        load_config(overrides={"env.physics.tau": 0})


def test_schedule_forms_cover_every_schedule_kind() -> None:
    assert tuple(SCHEDULE_FORMS) == SCHEDULE_KINDS


def test_an_entry_of_an_overridden_list_blames_the_override() -> None:
    where = Provenance("c.yaml", ("discretization.low",), "command line")
    assert where.of("discretization.low[2]") == "command line"
    assert where.of("discretization.lower[2]") == "c.yaml"
