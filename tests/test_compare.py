"""`cartpole-q compare`: the probability that one run's seeds beat another's."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from tests.conftest import invoke
from tests.test_cli import assert_refused


@pytest.fixture(scope="module")
def two_runs(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    root = tmp_path_factory.mktemp("compare")
    good, poor = root / "default", root / "short"
    assert invoke("train", "--seeds", "0-3", "--workers", "1", "-q", "--out", good).exit_code == 0
    short = ("--seeds", "0-3", "--workers", "1", "-q", "--episodes", "20", "--out", poor)
    assert invoke("train", *short).exit_code == 0
    return good, poor


def test_a_better_run_wins_every_pair(two_runs: tuple[Path, Path]) -> None:
    good, poor = two_runs
    result = invoke("compare", good, poor, "--json")
    assert result.exit_code == 0, result.output
    figures = json.loads(result.stdout)
    # every seed of the solved runs scores 500, every 20-episode seed far less
    assert (figures["probability_of_improvement"], figures["low"], figures["high"]) == (1, 1, 1)
    assert figures["seeds_a"] == figures["seeds_b"] == 4
    reverse = json.loads(invoke("compare", poor, good, "--json").stdout)
    assert reverse["probability_of_improvement"] == 0.0


def test_a_run_against_itself_is_even(two_runs: tuple[Path, Path]) -> None:
    good, _ = two_runs
    figures = json.loads(
        invoke("compare", good, good, "--json", "--metric", "solved_episode").stdout
    )
    assert figures["probability_of_improvement"] == 0.5
    assert figures["low"] <= 0.5 <= figures["high"]
    text = invoke("compare", good, good).stdout
    assert "P(A better than B) = 0.500" in text


def test_compare_refuses_bad_input(two_runs: tuple[Path, Path], tmp_path: Path) -> None:
    good, poor = two_runs
    assert_refused(invoke("compare", good, poor, "--metric", "speed"), "--metric")
    assert_refused(invoke("compare", good, tmp_path / "nowhere"), "does not exist")
