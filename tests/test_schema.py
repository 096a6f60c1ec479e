"""``cartpole-q schema``: a stock validator accepts every shipped file and refuses bad ones.

The bad files are the readers' own test fixtures (read from those tests' parameters, so a
new fixture is checked here too): each one the schema can express (an unknown key, a wrong
type, a number out of range, a bad choice, a rule between keys that names no computed
value) must be refused by the schema as well. The few that only the world, arithmetic or
the run can judge are listed in :data:`READER_ONLY` with the reason.
"""

from __future__ import annotations

import dataclasses
import json
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest
import yaml
from jsonschema import Draft202012Validator

from cartpole_q.config import Config, ConfigError, load_config, load_yaml_text
from cartpole_q.config.json_schema import config_schema
from cartpole_q.config.overrides import algorithm_param_keys, merge, nest
from cartpole_q.config.schema import key_of, sections
from cartpole_q.experiments import bandits, planning, study_kinds, sweep_spec, tune_spec, updates
from cartpole_q.experiments.schemas import study_schema, tune_schema
from tests import test_bandits as bandit_tests
from tests import test_config as config_tests
from tests import test_dynamic_programming as dp_tests
from tests import test_planning_updates as updates_tests
from tests import test_sweep as sweep_tests
from tests.conftest import REPO, invoke

CONFIG, STUDY, TUNE = config_schema(), study_schema(), tune_schema()
SHIPPED_CONFIGS = sorted((REPO / "cartpole_q" / "configs").glob("*.yaml"))
EXAMPLES = sorted((REPO / "examples").rglob("*.yaml"))
BOOK = REPO / "examples" / "book"


def _errors(schema: dict[str, Any], data: Any) -> list[str]:
    return [error.message for error in Draft202012Validator(schema).iter_errors(data)]


def _read(path: Path) -> Any:
    return load_yaml_text(path.read_text(encoding="utf-8"))


def test_the_schemas_are_valid_draft_2020_12_schemas() -> None:
    for schema in (CONFIG, STUDY, TUNE):
        Draft202012Validator.check_schema(schema)
        assert schema["$schema"] == "https://json-schema.org/draft/2020-12/schema"
        assert schema["$id"] and schema["title"]


@pytest.mark.parametrize(
    "path", [*SHIPPED_CONFIGS, REPO / "cartpole_q" / "default.yaml"], ids=lambda p: p.name
)
def test_every_shipped_config_is_valid(path: Path) -> None:
    assert _errors(CONFIG, _read(path)) == []


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: str(p.relative_to(REPO)))
def test_every_example_file_is_a_valid_study_or_tune_file(path: Path) -> None:
    data = _read(path)
    assert _errors(STUDY, data) == []
    if "trials" in data:  # a tune file
        assert _errors(TUNE, data) == []


@pytest.mark.parametrize(
    "text",
    [
        "agent:\n  alpha: 5e-4\n  gamma: 1e0\ntrain:\n  episodes: 1e3\n",  # YAML's strings
        "agent:\n  epsilon: {k: 25}\n",  # merges into the default's log schedule
        "agent:\n  epsilon: {type: log, k: 25}\n",  # (its end, too)
        "agent:\n  alpha: sample_average\n",
        "agent:\n  alpha: {type: sample_average}\n",
        "discretization:\n  tilings: 8\nagent:\n  alpha: 1.5\n",  # Q's step on tiles
        "discretization: null\nenv: {id: FrozenLake-v1}\n",
        "env: null\ntrain: {seeds: '0-9,20', reward_threshold: null}\n",
        "agent: {algorithm: sarsa_lambda, lambda: 0.5, trace: dutch}\n",
        "env: {physics: {length: 0.75, kinematics_integrator: semi-implicit euler}}\n",
        "agent: {algorithm: td, policy_run: null}\n",
    ],
)
def test_configs_the_reader_takes_are_valid(text: str) -> None:
    load_config(load_yaml_text(text))  # the reader takes it
    assert _errors(CONFIG, load_yaml_text(text)) == []


@pytest.mark.parametrize(
    ("path", "kind"),
    [(BOOK / "fig2_2_epsilon_greedy.yaml", "bandit"), (BOOK / "fig4_1_small_gridworld.yaml", "dp")],
)
def test_a_file_without_kind_is_told_by_its_figure_and_a_wrong_kind_is_refused(
    path: Path, kind: str
) -> None:
    data = _read(path)
    assert data.pop("kind") == kind
    assert _errors(STUDY, data) == []  # figure.kind says what it is
    assert _errors(STUDY, {**data, "kind": "sweep"}) != []
    assert _errors(STUDY, {**data, "kind": "pie"}) != []


# -- the schema's keys are the readers' -----------------------------------------------------


def _section_keys(record: type) -> set[str]:
    names = {item.name for item in dataclasses.fields(record) if key_of(item).kind != "params"}
    has_params = any(key_of(item).kind == "params" for item in dataclasses.fields(record))
    return names | (set(algorithm_param_keys()) if has_params else set())


def _keys(schema: dict[str, Any]) -> set[str]:
    return set(schema["properties"])


def test_the_config_schemas_keys_are_the_dataclasses_fields() -> None:
    assert list(CONFIG["properties"]) == [item.name for item in dataclasses.fields(Config)]
    for section, record in sections().items():
        assert _keys(CONFIG["properties"][section]) == _section_keys(record), section
    assert STUDY["$defs"]["config"]["properties"] == CONFIG["properties"]


def test_the_study_schemas_keys_are_the_readers_key_constants() -> None:
    kinds = STUDY["$defs"]
    assert set(STUDY["properties"]["kind"]["enum"]) == set(study_kinds.registered())
    sweep, bandit, dp, planned = kinds["sweep"], kinds["bandit"], kinds["dp"], kinds["updates"]
    assert _keys(sweep) == {"kind", *sweep_spec.SWEEP_KEYS}
    assert _keys(sweep["properties"]["figure"]) == set(sweep_spec.FIGURE_KEYS)
    assert _keys(bandit) == {"kind", *bandits.STUDY_KEYS}
    assert _keys(bandit["properties"]["testbed"]) == set(bandits.TESTBED_KEYS)
    assert _keys(bandit["properties"]["curves"]["items"]) == set(bandits.CURVE_KEYS)
    assert _keys(bandit["properties"]["figure"]) == set(bandits.FIGURE_KEYS)
    assert _keys(bandit["properties"]["book"]["items"]) == set(bandits.BOOK_KEYS)
    assert _keys(dp) == {"kind", *planning.STUDY_KEYS}
    assert _keys(dp["properties"]["figure"]) == set(planning.FIGURE_KEYS)
    assert _keys(dp["properties"]["book"]["items"]) == set(planning.BOOK_KEYS)
    assert _keys(planned) == {"kind", *updates.STUDY_KEYS}
    assert _keys(planned["properties"]["figure"]) == set(updates.FIGURE_KEYS)
    assert _keys(planned["properties"]["panels"]["items"]) == set(updates.PANEL_KEYS)
    assert _keys(TUNE) == set(tune_spec.TUNE_KEYS) == _keys(kinds["tune"])
    assert _keys(kinds["tune.range"]) == set(tune_spec.RANGE_KEYS)


def test_axes_and_dimensions_name_every_config_key_but_the_seeds() -> None:
    dotted = set()
    for item in dataclasses.fields(Config):
        dotted.add(item.name)
        if item.name in sections():
            dotted |= {f"{item.name}.{key}" for key in _section_keys(sections()[item.name])}
    expected = dotted - set(sweep_spec.FORBIDDEN_AXES)
    assert _keys(STUDY["$defs"]["sweep"]["properties"]["grid"]) == expected
    assert _keys(STUDY["$defs"]["sweep"]["properties"]["zip"]) == expected
    assert _keys(TUNE["properties"]["space"]) == expected


# -- bad files: what the readers refuse, the schema refuses ----------------------------------


def _fixtures(test: Callable[..., Any]) -> list[tuple[Any, ...]]:
    """The parameters of a parametrized test, as tuples."""
    (mark,) = [mark for mark in test.pytestmark if mark.name == "parametrize"]  # type: ignore[attr-defined]
    return [tuple(p.values) if hasattr(p, "values") else tuple(p) for p in mark.args[1]]


def _config_text(text: str) -> Callable[[Path], Any]:
    return lambda _: load_yaml_text(text)


def _config_overrides(overrides: dict[str, Any]) -> Callable[[Path], Any]:
    def build(_: Path) -> Any:
        data: dict[str, Any] = {}
        for dotted, value in overrides.items():
            data = merge(data, nest(dotted, value))
        return data

    return build


def _bandit(change: dict[str, Any]) -> Callable[[Path], Any]:
    return lambda tmp: _read(bandit_tests.small_study(tmp, "fig2_2_epsilon_greedy", **change))


def _dp(change: dict[str, Any]) -> Callable[[Path], Any]:
    return lambda _: {
        **yaml.safe_load((BOOK / "fig4_1_small_gridworld.yaml").read_text()),
        **change,
    }


def _updates(figure: str, change: dict[str, Any]) -> Callable[[Path], Any]:
    return lambda tmp: _read(updates_tests.small_study(tmp, figure, **change))


def _bad_files() -> Iterator[tuple[str, str, str, Callable[[Path], Any]]]:
    """Every refused file of the readers' tests: its source, message, schema and builder."""
    for text, message in _fixtures(config_tests.test_bad_config_names_file_and_field):
        yield "config file", message, "config", _config_text(text)
    for overrides, message in _fixtures(
        config_tests.test_bad_overrides_raise_config_error_naming_the_key
    ):
        yield "config overrides", message, "config", _config_overrides(overrides)
    for overrides, message in _fixtures(
        config_tests.test_sample_averages_are_refused_where_they_have_no_meaning
    ):
        both = {"agent.alpha": "sample_average", **overrides}
        yield "sample averages", message, "config", _config_overrides(both)
    for data, message in _fixtures(sweep_tests.test_bad_sweep_files_are_refused_naming_the_key):
        yield "sweep", message, "study", lambda _, data=data: data
    for change, message in _fixtures(
        bandit_tests.test_bandit_refuses_bad_study_files_with_exit_code_2
    ):
        yield "bandit", message, "study", _bandit(change)
    for change, message in _fixtures(dp_tests.test_dp_refuses_bad_study_files_with_exit_code_2):
        yield "dp", message, "study", _dp(change)
    for figure, change, message in _fixtures(
        updates_tests.test_updates_refuses_bad_study_files_with_exit_code_2
    ):
        yield "updates", message, "study", _updates(figure, change)


BAD_FILES = list(_bad_files())

_LENGTHS = "it compares values with each other (lengths, indices, order): a schema cannot"
_WORLD = "the world the env.id names (its model, states and actions) judges it"
_RUN = "only running the algorithm finds it"
_NO_JSON = "JSON has no NaN or infinity, so no JSON Schema can refuse them"
READER_ONLY = {
    ("config file", "not valid YAML"): "the YAML parser refuses it, before any schema",
    ("config file", "tag that is not allowed"): "the YAML parser refuses it, before any schema",
    ("config file", "duplicate key 'seed'"): "the YAML parser refuses it, before any schema",
    ("config file", "discretization.low[2]: must be a finite number"): _NO_JSON,
    ("config file", "discretization.high[1]: must be a finite number"): _NO_JSON,
    ("config file", "entry 0 (2.4) must be below"): _LENGTHS,
    ("config file", "discretization.low: has 3 entries but discretization.bins has 4"): _LENGTHS,
    ("config file", "runs backwards"): _LENGTHS,
    ("config overrides", "'agent..gamma' is not a config key"): "no file can write that key",
    ("sweep", "same number of values (agent.alpha has 2, agent.gamma has 1)"): _LENGTHS,
    ("sweep", "zip.agent.alpha: is a grid axis too"): "it compares the keys of grid and zip",
    ("sweep", "agent and agent.alpha: one key holds the other"): "it compares axes' keys",
    ("sweep", "is not a file (a base path is relative to the sweep file)"): "a missing file",
    ("bandit", "book[0].curve: a curve's index in `curves` (0 to 2), got 7"): _LENGTHS,
    ("bandit", "book[0].step: 101"): _LENGTHS,
    ("bandit", "book[0].above: a curve's index"): _LENGTHS,
    ("dp", "CartPole-v1"): _WORLD,
    ("dp", "env.id"): _WORLD,
    ("dp", "book[0].state: 99 is not a state"): _WORLD,
    ("dp", "made only 426"): _RUN,
    ("dp", "policy: action 7 does not exist"): _WORLD,
    ("dp", "did not converge in 11 sweeps"): _RUN,
    ("dp", "figure.show: sweep 10 is beyond max_sweeps (5)"): _LENGTHS,
    ("dp", "cartpole_q/SmallGridworld-v0 is not the gambler's problem"): _WORLD,
    ("dp", "p_h"): "the environment judges its own arguments (env.kwargs)",
    ("updates", "panels[0].every: must divide updates (100)"): _LENGTHS,
}
"""the readers' refusals a schema cannot express, and why"""


def test_every_reader_only_fixture_is_one_of_the_readers_fixtures() -> None:
    assert set(READER_ONLY) <= {(source, message) for source, message, _, _ in BAD_FILES}


@pytest.mark.parametrize(
    ("source", "message", "schema", "build"),
    BAD_FILES,
    ids=[f"{source}: {message[:50]}" for source, message, _, _ in BAD_FILES],
)
def test_what_the_readers_refuse_the_schema_refuses(
    tmp_path: Path, source: str, message: str, schema: str, build: Callable[[Path], Any]
) -> None:
    if (source, message) in READER_ONLY:
        pytest.skip(READER_ONLY[source, message])
    data = build(tmp_path)
    assert _errors({"config": CONFIG, "study": STUDY}[schema], data) != [], (
        f"the {schema} schema takes what the {source} reader refuses ({message}): {data}"
    )


@pytest.mark.parametrize(
    ("change", "why"),
    [
        ({"tirals": 5}, "an unknown key"),
        ({"trials": 0}, "trials out of range"),
        ({"objective": "speed"}, "an objective that is none"),
        ({"pruner": True, "objective": "iqm_eval_return"}, "the pruner scores success rates"),
        ({"space": {}}, "nothing searched"),
        ({"space": {"seed": {"low": 0, "high": 9}}}, "the seeds are the file's"),
        ({"space": {"agent.alpah": {"low": 0.1, "high": 0.5}}}, "a key that is none"),
        ({"space": {"agent.alpha": {"low": 0, "high": 1, "log": True}}}, "log touching 0"),
        ({"space": {"agent.alpha": {"low": 0.1, "high": 1, "log": True, "step": 0.1}}}, "log step"),
        ({"space": {"agent.gamma": {"low": 0.9, "high": 1.5}}}, "beyond the key's range"),
        ({"space": {"agent.n": {"low": 1.5, "high": 4, "int": True}}}, "an int range of halves"),
        ({"space": {"agent.algorithm": {"choices": ["dqn"]}}}, "a choice the key refuses"),
        ({"space": {"agent.gamma": {"choices": []}}}, "no choices"),
        ({"sampler": {"type": "grid"}}, "a sampler that is none"),
        ({"base": {"agent": {"gamma": 2}}}, "a base the config schema refuses"),
    ],
)
def test_bad_tune_files_are_refused(change: dict[str, Any], why: str) -> None:
    data = {**_read(REPO / "examples" / "rescue_blog.yaml"), **change}
    with pytest.raises(ConfigError):
        tune_spec.load_tune(data)
    assert _errors(TUNE, data) != [], why
    assert _errors(STUDY, data) != [], why


# -- the command -----------------------------------------------------------------------------


def test_the_command_prints_the_schema_and_writes_it_with_out(tmp_path: Path) -> None:
    result = invoke("schema", "config")
    assert result.exit_code == 0, result.output
    printed = json.loads(result.stdout)
    assert printed.pop("$comment").startswith("written by `cartpole-q schema config`")
    assert printed == CONFIG
    out = tmp_path / "cartpole-q-study.schema.json"
    result = invoke("schema", "study", "--out", out)
    assert result.exit_code == 0, result.output
    assert result.stdout.splitlines() == [str(out)]
    written = json.loads(out.read_text(encoding="utf-8"))
    assert written.pop("$comment") and written == STUDY
    bad = invoke("schema", "studies")
    assert bad.exit_code == 2 and len(bad.stderr.strip().splitlines()) == 1
    missing = invoke("schema", "--out", tmp_path / "no" / "such" / "dir.json")
    assert missing.exit_code == 2 and missing.stderr.startswith("error: ")
