"""`cartpole-q eval` and the summary's evaluations: limits, and where episodes were played."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from tests.conftest import invoke
from tests.test_cli import assert_refused


@pytest.fixture(scope="module")
def quick_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("runs") / "quick"
    result = invoke("train", "--episodes", "20", "--out", out)
    assert result.exit_code == 0, result.output
    return out


@pytest.mark.parametrize("episodes", ["1000000000000", "10000001"])
def test_eval_caps_the_episode_count(quick_run: Path, episodes: str) -> None:
    # 10**12 episodes used to allocate their returns at once: a MemoryError traceback
    assert_refused(invoke("eval", quick_run, "--episodes", episodes), "--episodes", "10,000,000")


@pytest.mark.parametrize(("engine", "where"), [("numba", "twin"), ("gymnasium", "gymnasium")])
def test_summary_says_where_its_evaluations_were_played(
    tmp_path: Path, engine: str, where: str
) -> None:
    out = tmp_path / engine
    result = invoke("train", "--engine", engine, "--out", out, "--quiet")
    assert result.exit_code == 0, result.output
    summary = json.loads((out / "summary.json").read_text())
    assert summary["eval"]["played_in"] == where
    assert summary["first_greedy_success"]["played_in"] == where
