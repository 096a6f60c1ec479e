"""What a new user met at the edges of the study commands and prediction runs (issue 47).

Each test failed on the code before the fix: a traceback (exit 1) where a one-paragraph
refusal belongs, a NaN printed with exit 0, or a prediction sweep reported as a failed
control sweep.
"""

from __future__ import annotations

import csv
import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from cartpole_q.store import sweepdir
from tests.conftest import invoke, write_yaml
from tests.test_cli import assert_refused

WALK = {
    "env": {"id": "cartpole_q/RandomWalk5-v0"},
    "agent": {"algorithm": "td", "policy": "random", "gamma": 1.0, "alpha": 0.1, "q_init": 0.5},
    "train": {"episodes": 20, "eval_every": 0, "checkpoint_every": 0},
    "eval": {"episodes": 1},
}


# -- item 3: a --set value that is not UTF-8 -------------------------------------------------


@pytest.mark.parametrize(
    "command", [("train", "--episodes", 1), ("optimum", "FrozenLake-v1")], ids=["train", "optimum"]
)
def test_a_set_value_that_is_not_utf8_is_refused_naming_it(
    command: tuple[Any, ...], tmp_path: Path
) -> None:
    # the shell's $'agent.gamma=\xff' reaches Python as a surrogate escape
    with_out = ("--out", tmp_path / "run") if command[0] == "train" else ()
    result = invoke(*command, "--set", "agent.gamma=\udcff", *with_out)
    assert_refused(result, "--set 'agent.gamma=\\udcff'", "not UTF-8 text")
    assert not (tmp_path / "run").exists()


# -- items 4 and 5: a prediction run reports its error -------------------------------------


def test_a_prediction_run_reports_its_error_not_a_solve(tmp_path: Path) -> None:
    config = write_yaml(tmp_path / "walk.yaml", WALK)
    result = invoke("train", "-c", config, "--out", tmp_path / "run")
    assert result.exit_code == 0, result.output
    assert "not solved" not in result.output
    summary = json.loads((tmp_path / "run" / "summary.json").read_text())
    with (tmp_path / "run" / "metrics.csv").open(newline="") as file:
        last = list(csv.DictReader(file))[-1]
    assert summary["rms_error"] == float(last["rms_error"])  # the error after the last episode
    assert summary["v_table"] == {"episode": 20, "source": "last episode"}
    assert "q_table" not in summary
    assert f"RMS error {summary['rms_error']:.4g}" in result.output
    from cartpole_q import load_run

    assert load_run(tmp_path / "run").result.rms_error == summary["rms_error"]


def test_a_prediction_sweep_reports_every_runs_error_and_each_points_mean(tmp_path: Path) -> None:
    sweep = write_yaml(
        tmp_path / "s.yaml",
        {"name": "walk", "base": WALK, "seeds": "0-2", "grid": {"agent.alpha": [0.05, 0.2]}},
    )
    out = tmp_path / "sweep"
    result = invoke("sweep", sweep, "--out", out, "--workers", 1)
    assert result.exit_code == 0, result.output
    assert "RMS error after the last episode" in result.output
    with (out / sweepdir.RESULTS_FILE).open(newline="") as file:
        rows = list(csv.DictReader(file))
    curves = np.load(sweepdir.curves_path(out, "000"))
    assert float(rows[0]["rms_error"]) == float(curves["seed-000.rms_error"][-1])
    with (out / sweepdir.POINTS_FILE).open(newline="") as file:
        points = list(csv.DictReader(file))
    for point in points:
        errors = [float(row["rms_error"]) for row in rows if row["point"] == point["point"]]
        assert point["seeds"] == "3"  # every seed ran, though none is evaluated greedily
        assert float(point["mean_rms_error"]) == float(np.mean(errors))
        assert float(point["mean_rms_error_low"]) <= float(point["mean_rms_error"])
    drawn = (out / "sweep.csv").read_text()
    assert "RMS error after the last episode" in drawn and "success rate" not in drawn


# -- item 8: overflow refused, not printed as NaN -------------------------------------------

BANDIT = {
    "name": "b",
    "testbed": {"k": 10, "mean": 0, "spread": 1},
    "seeds": "0-1",
    "steps": 10,
    "curves": [{"method": "epsilon_greedy", "epsilon": 0.1}],
    "figure": {"kind": "curves", "file": "b.png"},
}


def test_a_testbed_whose_rewards_overflow_is_refused_when_read(tmp_path: Path) -> None:
    study = write_yaml(tmp_path / "b.yaml", {**BANDIT, "testbed": {"spread": 1.0e308}})
    result = invoke("bandit", study, "--out", tmp_path / "b.png")
    assert_refused(result, "testbed.spread: must be within", "1e+308")
    assert not (tmp_path / "b.png").exists()


def test_a_curve_that_overflowed_is_refused_with_its_step() -> None:
    from cartpole_q.errors import RunError
    from cartpole_q.experiments.bandits import Curve, _check_finite

    curve = Curve("wild", "gradient", {"alpha": 1.0}, "alpha", (0.5, 2.0))
    averages = np.array([[0.1, 0.2, 0.3], [0.1, np.inf, np.nan]])
    with pytest.raises(RunError, match=r"'wild' \(alpha 2\) overflowed: .* at step 2 is inf"):
        _check_finite(curve, averages, "b.yaml")


# -- item 2: sizes bounded when read --------------------------------------------------------

UPDATES = {"name": "u", "seeds": "0-1"}
BOOK = Path(__file__).resolve().parents[1] / "examples" / "book"


@pytest.mark.parametrize(
    ("command", "study", "named"),
    [
        ("bandit", {**BANDIT, "steps": 10**12}, ("steps: must be at most 10,000,000",)),
        (
            "bandit",
            {**BANDIT, "steps": 5_000_000,
             "curves": [{"method": "epsilon_greedy", "vary": "epsilon", "values": [0.1] * 60}]},
            ("steps: 60 learners' curves of 5,000,000 steps would take", "GiB of memory"),
        ),
        (
            "updates",
            {**UPDATES, "branching": [10**12], "figure": {"kind": "expected_vs_sample"}},
            ("branching: must be at most 10,000,000",),
        ),
        (
            "updates",
            {**UPDATES, "seeds": "0-99", "branching": [5_000_000],
             "figure": {"kind": "expected_vs_sample"}},
            ("branching: 100 problems of branching factor 5,000,000 would take", "GiB"),
        ),
        (
            "updates",
            {**UPDATES, "panels": [{"states": 10**12, "branching": [1], "updates": 10, "every": 5}],
             "figure": {"kind": "trajectory_sampling"}},
            ("panels[0].states: must be at most",),
        ),
        (
            "updates",
            {**UPDATES, "panels": [{"states": 10**7, "branching": [40], "updates": 10, "every": 5}],
             "figure": {"kind": "trajectory_sampling"}},
            ("panels[0].states: a task of 10,000,000 states", "GiB of memory"),
        ),
        (
            "updates",
            {**UPDATES, "scales": [1], "max_updates": 10**21, "figure": {"kind": "until_optimal"}},
            ("max_updates: must be at most",),
        ),
        (
            "updates",
            {**UPDATES, "scales": [100000], "figure": {"kind": "until_optimal"}},
            ("scales: must be at most 100",),
        ),
    ],
    ids=["bandit-steps", "bandit-memory", "branching", "branching-memory", "panel-states",
         "panel-memory", "max-updates", "maze-scale"],
)  # fmt: skip
def test_a_size_no_study_needs_is_refused_when_read(
    command: str, study: dict[str, Any], named: tuple[str, ...], tmp_path: Path
) -> None:
    path = write_yaml(tmp_path / "s.yaml", study)
    assert_refused(invoke(command, path, "--out", tmp_path / "s.png"), *named)
    assert not list(tmp_path.glob("s.*[!l]"))  # nothing written (the study file aside)


# -- item 10: messages that pointed the wrong way --------------------------------------------


def test_optimum_names_its_own_gamma_option_when_values_are_undefined() -> None:
    result = invoke("optimum", "cartpole_q/Gridworld-v0", "--policy", "random")
    assert_refused(result, "not defined at --gamma 1", "give --gamma below 1")
    assert "agent.gamma" not in result.stderr


def test_a_rule_of_another_world_names_the_world_that_declares_it(tmp_path: Path) -> None:
    sets = ("--set", "env.id=FrozenLake-v1", "--set", "agent.algorithm=td")
    result = invoke("train", *sets, "--set", "agent.policy=left", "--out", tmp_path / "r")
    assert_refused(result, "left is not a rule FrozenLake-v1 declares", "cartpole_q/OneState-v0")
    assert "stick_20" not in result.stderr


@pytest.mark.parametrize("value", [-1, 0, True, "many"])
def test_dp_max_sweeps_says_the_same_range_for_every_bad_value(tmp_path: Path, value: Any) -> None:
    import yaml

    study = yaml.safe_load((BOOK / "fig4_1_small_gridworld.yaml").read_text(encoding="utf-8"))
    path = write_yaml(tmp_path / "s.yaml", {**study, "max_sweeps": value})
    assert_refused(invoke("dp", path, "--check"), "max_sweeps: must be a whole number >= 1, got")


def test_dp_max_sweeps_is_bounded_by_the_memory_of_the_recorded_sweeps(tmp_path: Path) -> None:
    import yaml

    study = yaml.safe_load((BOOK / "fig4_2_car_rental.yaml").read_text(encoding="utf-8"))
    path = write_yaml(tmp_path / "s.yaml", {**study, "max_sweeps": 999_999})
    assert_refused(invoke("study", path, "--check"), "max_sweeps: 999,999 recorded sweeps", "GiB")


@pytest.mark.parametrize(
    ("name", "command"),
    [("fig2_2_epsilon_greedy", "study"), ("fig4_1_small_gridworld", "study"),
     ("fig7_2_n_step_td", "study")],
)  # fmt: skip
def test_train_given_a_study_file_names_the_command_that_runs_it(
    name: str, command: str, tmp_path: Path
) -> None:
    path = BOOK / f"{name}.yaml"
    result = invoke("train", "-c", path, "--out", tmp_path / "r")
    assert_refused(result, "is a study file", f"run it with `cartpole-q {command} {path}`")
    tune = Path(__file__).resolve().parents[1] / "examples" / "rescue_blog.yaml"
    assert_refused(invoke("train", "-c", tune), "is a tune file", "`cartpole-q tune")


def test_a_prediction_runs_refusals_point_to_what_it_has(tmp_path: Path) -> None:
    lake = tmp_path / "lake"
    sets = ("--set", "env.id=FrozenLake-v1", "--set", "train.episodes=20")
    assert invoke("train", *sets, "--out", lake, "-q").exit_code == 0
    walk = tmp_path / "walk"
    prediction = ("--set", "agent.algorithm=td", "--set", "agent.policy=greedy",
                  "--set", f"agent.policy_run={lake}", "--set", "train.checkpoint_every=10")  # fmt: skip
    assert invoke("train", *sets, *prediction, "--out", walk, "-q").exit_code == 0
    # eval: no policy, and it says where the error it measured is drawn
    assert_refused(invoke("eval", walk), "is a prediction run", "--metric rms_error")
    # the evaluated run moved: the resume says how to go on
    lake.rename(tmp_path / "moved")
    result = invoke("train", "--resume", walk, "--episodes", 30)
    assert_refused(result, f"agent.policy_run: {lake} does not exist", "put the directory back")


# -- items 9 and 11: dp draws any grid world; figures name the book's states -----------------


@pytest.mark.parametrize("env_id", ["FrozenLake-v1", "CliffWalking-v1"])
def test_dp_draws_frozenlake_and_cliffwalking_as_grids(env_id: str, tmp_path: Path) -> None:
    path = write_yaml(tmp_path / "s.yaml", {
        "kind": "dp", "name": "g", "env": {"id": env_id}, "algorithm": "value_iteration",
        "gamma": 0.9, "figure": {"kind": "grid", "greedy": True},
    })  # fmt: skip
    result = invoke("study", path, "--out", tmp_path / "out", "-q")
    assert result.exit_code == 0, result.output
    rows = (tmp_path / "out" / "g.csv").read_text(encoding="utf-8").splitlines()
    cells = {line.split(",")[2:4][0] + "," + line.split(",")[3] for line in rows[1:]}
    columns = 4 if env_id.startswith("Frozen") else 12
    assert f"{columns - 1},3" in cells  # the bottom-right cell of a 4-row grid


def test_example_6_2s_values_figure_names_the_states_a_to_e(tmp_path: Path) -> None:
    from cartpole_q.config import load_config
    from cartpole_q.envs.models import state_labels

    walk = load_config({"env": {"id": "cartpole_q/RandomWalk5-v0"}}).env
    assert state_labels(walk) == {1: "A", 2: "B", 3: "C", 4: "D", 5: "E"}
    nineteen = load_config({"env": {"id": "cartpole_q/RandomWalk-v0"}}).env
    assert state_labels(nineteen) == {}


def test_help_says_what_is_there() -> None:
    """Issue 47 item 11: help that omitted a metric, a figure kind, or named a missing option."""
    import re

    def text(*args: str) -> str:
        result = invoke(*args, "--help")
        assert result.exit_code == 0
        return re.sub(r"[\s│]+", " ", result.output)  # Typer's box, folded

    assert "rms_error" in text("plot")
    updates = text("updates")
    assert "until_optimal" in updates and "trajectory_sampling" in updates
    assert "--backend" not in text("compile")
    commands = re.findall(r"^│ (\w+) ", invoke("--help").output, re.MULTILINE)
    assert commands[0] == "train" and commands.index("study") < commands.index("bandit")


def test_optimum_solves_a_continuing_world_dp_solves(tmp_path: Path) -> None:
    """Issue 47 item 9: optimum refused cartpole_q/CarRental-v0 although dp solves it."""
    import json

    result = invoke("optimum", "cartpole_q/CarRental-v0")
    assert_refused(result, "a continuing task", "give --gamma below 1")
    result = invoke("optimum", "cartpole_q/CarRental-v0", "--gamma", "0.9", "--json")
    assert result.exit_code == 0, result.output
    found = json.loads(result.stdout)
    # policy iteration (Figure 4.2's study) ends at the optimal policy: the same values
    assert (
        invoke("study", BOOK / "fig4_2_car_rental.yaml", "--out", tmp_path / "s", "-q").exit_code
        == 0
    )
    values = np.load(tmp_path / "s" / "runs" / "0000.npz")["values"][-1]
    assert found["optimum"]["return"] == pytest.approx(float(np.mean(values)), abs=1e-6)
    assert len(found["policy"]) == 441
