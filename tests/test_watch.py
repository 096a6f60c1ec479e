"""Watching and recording the greedy policy during training (train --watch, --video-every)."""

from __future__ import annotations

from pathlib import Path

import pytest
from PIL import Image

from tests.conftest import invoke
from tests.test_cli import assert_refused

QUICK = ("--episodes", "120", "--set", "train.stop_when_solved=false", "--quiet")


def test_video_every_records_gifs_and_changes_no_result(tmp_path: Path) -> None:
    recorded = invoke("train", *QUICK, "--video-every", "50", "--out", tmp_path / "recorded")
    plain = invoke("train", *QUICK, "--out", tmp_path / "plain")
    assert recorded.exit_code == 0 and plain.exit_code == 0, recorded.output + plain.output
    videos = sorted(path.name for path in (tmp_path / "recorded" / "videos").iterdir())
    assert videos == ["episode-000050.gif", "episode-000100.gif"]
    with Image.open(tmp_path / "recorded" / "videos" / videos[0]) as gif:
        assert gif.format == "GIF" and gif.n_frames > 1
    for name in ("q_table.npy", "metrics.csv", "visits.npy"):
        assert (tmp_path / "recorded" / name).read_bytes() == (
            tmp_path / "plain" / name
        ).read_bytes()


def test_watch_without_a_display_is_refused_before_anything_is_written(
    in_tmp: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    assert_refused(invoke("train", "--watch", "10", "--out", in_tmp / "run"), "--watch")
    assert not (in_tmp / "run").exists()


def test_watching_several_seeds_is_refused(in_tmp: Path) -> None:
    result = invoke("train", "--seeds", "0-1", "--video-every", "10", "--out", in_tmp / "run")
    assert_refused(result, "--video-every", "--seed N")
    assert not (in_tmp / "run").exists()
