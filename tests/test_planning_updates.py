"""Chapter 8's planning studies (Figures 8.7, 8.8): the re-derivation agrees exactly, the command works.

``tests/reference_planning_updates.py`` re-derives both computations from docs/algorithms.md
("Planning updates") without the package; the package's curves must be its floats, byte for
byte (Figure 8.8 on the compiled loop and on plain Python).
"""

from __future__ import annotations

import csv
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml

from cartpole_q.engines.trajectory import task_curves
from cartpole_q.experiments import updates
from cartpole_q.rl.planning_updates import (
    Curve,
    Task,
    problem_draws,
    rms_over_problems,
    sample_update_errors,
)
from tests.conftest import REPO, invoke, write_yaml
from tests.reference_planning_updates import rms_curve, start_values

BOOK = REPO / "examples" / "book"


@pytest.mark.parametrize("branching", [2, 10, 37])
def test_figure_8_7_curves_are_the_re_derivations_byte_for_byte(branching: int) -> None:
    seeds = list(range(7))
    sample, _ = sample_update_errors(seeds, branching)
    assert rms_over_problems(sample).tolist() == rms_curve(seeds, branching)


def test_the_expected_update_is_exact_after_b_computations_and_1_before() -> None:
    sample, expected = sample_update_errors(list(range(20)), 50)
    assert (expected[:, :50] == 1.0).all() and (expected[:, 50:] == 0.0).all()
    assert (sample[:, 0] == 1.0).all()
    # one sample update with alpha = 1 forgets the start: the estimate is the sampled value
    values, picks = problem_draws(0, 50)
    assert math.isclose(sample[0, 1], values[picks[0]] - np.mean(values), abs_tol=1e-12)


@pytest.mark.parametrize("branching", [2, 10])
def test_figure_8_7_follows_the_books_sqrt_b_minus_1_over_b_t(branching: int) -> None:
    # E[error_t^2] = E[population variance of the b values] / t = ((b - 1) / b) / t
    # (sampling with replacement), so over many problems the RMS error is close to it.
    sample, _ = sample_update_errors(list(range(4000)), branching)
    rms = rms_over_problems(sample)
    for t in range(1, 2 * branching + 1):
        formula = math.sqrt((branching - 1) / (branching * t))
        assert abs(rms[t] / formula - 1) < 0.05, (t, rms[t], formula)


@pytest.mark.parametrize("compiled", [True, False])
@pytest.mark.parametrize(("states", "branching"), [(12, 1), (15, 3)])
def test_figure_8_8_curves_are_the_re_derivations_byte_for_byte(
    compiled: bool, states: int, branching: int
) -> None:
    for seed in (0, 5):
        uniform, on_policy = task_curves(
            seed, Task(states, 2, branching, 0.1), Curve(240, 20, 0.1, 1e-9), compiled=compiled
        )
        settings = (seed, states, 2, branching, 240, 20, 0.1, 0.1, 1e-9)
        assert uniform.tolist() == start_values(*settings, on_policy=False)
        assert on_policy.tolist() == start_values(*settings, on_policy=True)


@pytest.mark.parametrize("compiled", [True, False])
def test_figure_8_8_in_small_chunks_is_figure_8_8_in_one(compiled: bool, monkeypatch: Any) -> None:
    from cartpole_q.engines import trajectory

    task, curve = Task(15, 2, 3, 0.1), Curve(240, 20, 0.1, 1e-9)
    whole = task_curves(2, task, curve, compiled=compiled)
    asked: list[int] = []

    def never() -> bool:
        asked.append(1)
        return False

    monkeypatch.setattr(trajectory, "CHUNK_WORK", 4)  # two updates (b = 3) a chunk
    chunked = task_curves(2, task, curve, compiled=compiled, should_stop=never)
    assert chunked is not None
    assert [curve.tolist() for curve in chunked] == [curve.tolist() for curve in whole]
    assert len(asked) >= 2 * 240 // 2  # two updates a chunk, in both runs


def test_figure_8_8_stops_between_chunks_with_none() -> None:
    asked: list[int] = []

    def stop() -> bool:
        asked.append(1)
        return len(asked) > 1

    huge = Curve(10**7, 1000, 0.1, 1e-9)
    assert task_curves(0, Task(2000, 2, 1, 0.1), huge, should_stop=stop) is None
    assert len(asked) == 2  # one chunk, not ten million updates


def test_a_task_valued_at_the_start_is_the_policy_of_action_0() -> None:
    uniform, on_policy = task_curves(3, Task(10, 2, 2, 0.1), Curve(20, 10, 0.1, 1e-9))
    assert uniform[0] == on_policy[0]  # Q = 0: the greedy policy takes action 0 everywhere


def small_study(tmp_path: Path, figure: str, /, **changes: Any) -> Path:
    data = yaml.safe_load((BOOK / f"{figure}.yaml").read_text(encoding="utf-8"))
    if figure.startswith("fig8_7"):
        data.update(seeds="0-4", branching=[2, 10])
    else:
        data.update(seeds="0-1", panels=[{"states": 20, "branching": [1, 3], "updates": 200,
                                          "every": 50}])  # fmt: skip
    data.update(changes)
    for key, value in changes.items():
        if value is None:
            del data[key]
    return write_yaml(tmp_path / f"{figure}.yaml", data)


def rows(path: Path) -> list[dict[str, str]]:
    with path.open(encoding="utf-8", newline="") as handle:
        return list(csv.DictReader(handle))


def test_updates_draws_figure_8_7_with_its_data(tmp_path: Path) -> None:
    path = small_study(tmp_path, "fig8_7_expected_vs_sample")
    out = tmp_path / "study"
    result = invoke("updates", path, "--out", out)
    assert result.exit_code == 0, result.output
    assert "b = 10: t = b/10: " in result.stdout and "then 0 (the largest" in result.stdout
    figure = out / "fig8_7_expected_vs_sample.png"
    assert result.stdout.splitlines()[-1] == str(out) and figure.stat().st_size > 0
    data = rows(figure.with_suffix(".csv"))
    b10 = [float(r["y"]) for r in data if r["series"] == "sample updates, b = 10"]
    assert b10 == rms_curve(list(range(5)), 10)
    assert [float(r["x"]) for r in data if r["series"] == "sample updates, b = 10"][10] == 1.0
    expected = [(float(r["x"]), float(r["y"])) for r in data if r["series"] == "expected updates"]
    assert expected == [(0.0, 1.0), (1.0, 1.0), (1.0, 0.0), (2.0, 0.0)]
    again = invoke("updates", path, "--out", out)
    assert again.exit_code == 2 and "points at a non-empty directory" in again.stderr


def test_updates_draws_figure_8_8_with_its_data(tmp_path: Path) -> None:
    path = small_study(tmp_path, "fig8_8_trajectory_sampling")
    out = tmp_path / "study"
    result = invoke("updates", path, "--out", out)
    assert result.exit_code == 0, result.output
    assert "b = 3, on-policy vs uniform at " in result.stdout
    data = rows(out / "fig8_8_trajectory_sampling.csv")
    series = [r for r in data if r["series"] == "b = 3, on-policy" and r["panel"] == "20 states"]
    curves = [start_values(s, 20, 2, 3, 200, 50, 0.1, 0.1, 1e-9, True) for s in (0, 1)]
    assert [float(r["x"]) for r in series] == [0.0, 50.0, 100.0, 150.0, 200.0]
    assert [float(r["y"]) for r in series] == [(a + b) / 2 for a, b in zip(*curves, strict=True)]
    assert all(float(r["y_low"]) <= float(r["y"]) <= float(r["y_high"]) for r in series)


@pytest.mark.parametrize(
    ("figure", "change", "message"),
    [
        ("fig8_7_expected_vs_sample", {"branchin": [2]}, "unknown key 'branchin'; did you mean"),
        ("fig8_7_expected_vs_sample", {"branching": [1, 2]}, "branching: must be a list of whole numbers >= 2"),
        ("fig8_7_expected_vs_sample", {"branching": None}, "branching: must be a list"),
        ("fig8_7_expected_vs_sample", {"seeds": None}, "seeds: is missing"),
        ("fig8_7_expected_vs_sample", {"seeds": "x"}, "seeds:"),
        ("fig8_7_expected_vs_sample", {"initial_error": -1}, "initial_error: must not be negative"),
        ("fig8_7_expected_vs_sample", {"epsilon": 0.1}, "epsilon: an expected_vs_sample study takes no epsilon"),
        ("fig8_7_expected_vs_sample", {"figure": {"kind": "pie"}}, "figure.kind: must be one of expected_vs_sample"),
        ("fig8_8_trajectory_sampling", {"branching": [2]}, "branching: a trajectory_sampling study takes no branching (it takes panels, "),
        ("fig8_8_trajectory_sampling", {"panels": []}, "panels: must be a list such as"),
        ("fig8_8_trajectory_sampling", {"panels": [{"states": 10}]}, "panels[0].branching: is missing"),
        ("fig8_8_trajectory_sampling", {"panels": [{"states": 10, "branching": [1], "updates": 100, "every": 30}]}, "panels[0].every: must divide updates (100)"),
        ("fig8_8_trajectory_sampling", {"panels": [{"states": 0, "branching": [1], "updates": 100, "every": 10}]}, "panels[0]: states: must be a whole number >= 1"),
        ("fig8_8_trajectory_sampling", {"panels": [{"state": 10}]}, "panels[0]: unknown key 'state'"),
        ("fig8_8_trajectory_sampling", {"termination": 0}, "termination: must be in (0, 1]"),
        ("fig8_8_trajectory_sampling", {"epsilon": 2}, "epsilon: must be in [0, 1]"),
        ("fig8_8_trajectory_sampling", {"tolerance": "x"}, "tolerance: must be a number"),
    ],
)  # fmt: skip
def test_updates_refuses_bad_study_files_with_exit_code_2(
    tmp_path: Path, figure: str, change: dict[str, Any], message: str
) -> None:
    path = small_study(tmp_path, figure, **change)
    result = invoke("updates", path, "--out", tmp_path / "out")
    assert result.exit_code == 2, result.output
    assert message in result.stderr, result.stderr
    assert result.stderr.startswith(f"error: {path}") and "Traceback" not in result.stderr
    assert not (tmp_path / "out").exists()


def test_updates_refuses_a_missing_file(tmp_path: Path) -> None:
    result = invoke("updates", tmp_path / "nope.yaml")
    assert result.exit_code == 2 and "study file not found" in result.stderr


def test_the_shipped_study_files_load() -> None:
    seven = updates.load_study(BOOK / "fig8_7_expected_vs_sample.yaml")
    assert seven.branching == (2, 10, 100, 1000, 10000) and len(seven.seeds) == 100
    eight = updates.load_study(BOOK / "fig8_8_trajectory_sampling.yaml")
    assert len(eight.seeds) == 200 and [p.states for p in eight.panels] == [1000, 10000]
