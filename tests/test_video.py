"""eval --video FILE.mp4: real MP4 files, written and read back (frame count, size, rate).

The MP4 tests need the ``[video]`` extra (imageio-ffmpeg writes, imageio reads back);
they are skipped without it, and the refusal without it is tested by hiding the module.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from PIL import Image

from cartpole_q.config import load_config
from cartpole_q.envs.gym import inspect_env
from cartpole_q.errors import UserError
from cartpole_q.evaluation import evaluate
from cartpole_q.store.video import VideoRecorder, check_renderer, offscreen_rendering
from tests.conftest import invoke
from tests.test_cli import assert_refused

RENDERED = ["default", "mountaincar", "acrobot", "frozenlake", "taxi", "cliffwalking", "blackjack"]
"""a shipped config of every environment that draws itself"""
UNRENDERED = ["cartpole_q/WindyGridworld-v0", "cartpole_q/RandomWalk-v0", "cartpole_q/DynaMaze-v0"]


def _mp4_frames(path: Path) -> tuple[list[np.ndarray], dict[str, Any]]:
    iio = pytest.importorskip("imageio.v3")
    return list(iio.imiter(path, plugin="FFMPEG")), iio.immeta(path, plugin="FFMPEG")


@pytest.fixture
def encoder() -> None:
    pytest.importorskip("imageio_ffmpeg")
    pytest.importorskip("imageio")


class _PaintedEnv:
    """Renders one uniform colour per episode, at a given frame rate."""

    def __init__(self, fps: float, size: tuple[int, int]) -> None:
        self.metadata = {"render_fps": fps}
        self.colour = (0, 0, 0)
        self._size = size

    def render(self) -> np.ndarray:
        width, height = self._size
        return np.full((height, width, 3), self.colour, dtype=np.uint8)


def test_an_mp4_holds_every_step_at_the_environments_rate(encoder: None, tmp_path: Path) -> None:
    env = _PaintedEnv(25, (96, 64))
    path = tmp_path / "painted.mp4"
    colours = [(250, 30, 30), (30, 30, 250)]
    with VideoRecorder(path, episodes=2) as recorder:
        for episode, (length, colour) in enumerate(zip([5, 3], colours, strict=True)):
            env.colour = colour
            for step in range(length + 1):
                recorder.on_frame(env, episode, step)
        recorder.on_frame(env, 2, 0)  # a third episode is not recorded
        assert recorder.save() == path
    frames, meta = _mp4_frames(path)
    assert len(frames) == 6 + 4  # each episode's steps and its reset
    assert {frame.shape for frame in frames} == {(64, 96, 3)}
    assert meta["fps"] == 25.0 and meta["codec"] == "h264"
    # away from the caption, each frame keeps its episode's colour (H.264 is lossy)
    corners = [frame[-10:, -10:].reshape(-1, 3).mean(axis=0) for frame in frames]
    for corner, colour in zip(corners, [colours[0]] * 6 + [colours[1]] * 4, strict=True):
        assert np.abs(corner - np.array(colour)).max() < 24
    assert not list(tmp_path.glob(".*.tmp"))


@pytest.mark.parametrize("name", RENDERED)
def test_every_environment_with_a_renderer_records_gif_and_mp4(
    encoder: None, name: str, tmp_path: Path
) -> None:
    config = load_config(Path(name), {"env.kwargs.max_episode_steps": 6})
    check_renderer(config.env.id)
    env_info = inspect_env(config)
    q_table = np.zeros((*env_info.state_shape, env_info.n_actions))
    sizes, calls = set(), []
    for suffix in (".mp4", ".gif"):
        path = tmp_path / f"video{suffix}"
        with VideoRecorder(path, episodes=1) as recorder:

            def on_frame(
                env: Any, episode: int, step: int, recorder: VideoRecorder = recorder
            ) -> None:
                if episode == 0:
                    calls.append(step)
                    sizes.add(env.render().shape)
                recorder.on_frame(env, episode, step)

            with offscreen_rendering():
                evaluate(
                    q_table, config, episodes=2, seed=0, render_mode="rgb_array", on_frame=on_frame
                )
            recorder.save()
    (shape,) = sizes
    steps = len(calls) // 2  # the same greedy episode, played for each file
    assert 2 <= steps <= 7  # a reset and at most 6 steps
    frames, _meta = _mp4_frames(tmp_path / "video.mp4")
    assert len(frames) == steps and {frame.shape for frame in frames} == {shape}
    with Image.open(tmp_path / "video.gif") as gif:
        assert gif.size == (shape[1], shape[0]) and gif.n_frames >= 1


@pytest.mark.parametrize("env_id", UNRENDERED)
def test_an_environment_without_a_renderer_is_refused(env_id: str) -> None:
    with pytest.raises(UserError, match="no renderer"):
        check_renderer(env_id)


def test_video_every_without_a_renderer_is_refused_before_training(in_tmp: Path) -> None:
    result = invoke("train", "-c", "windy_gridworld", "--video-every", "5", "--out", in_tmp / "r")
    assert_refused(result, "--video-every", "cartpole_q/WindyGridworld-v0", "no renderer")
    assert not (in_tmp / "r").exists()


@pytest.fixture(scope="module")
def cartpole_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("video") / "run"
    assert invoke("train", "--episodes", "30", "--out", out, "-q").exit_code == 0
    return out


def test_eval_video_mp4_is_a_playable_file_of_every_step(
    encoder: None, cartpole_run: Path, tmp_path: Path
) -> None:
    video = tmp_path / "policy.mp4"
    result = invoke(
        "eval", cartpole_run, "--episodes", "2", "--video-episodes", "2", "--max-steps", "15",
        "--video", video, "--json",
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    report = json.loads(result.stdout)  # stdout stays pure JSON
    # CartPole's return is its length: both episodes, each with its reset frame
    lengths = [int(report["min"]), int(report["max"])]
    assert 2 * report["mean"] == sum(lengths)
    frames, meta = _mp4_frames(video)
    assert len(frames) == sum(lengths) + 2
    assert {frame.shape for frame in frames} == {(400, 600, 3)}
    assert meta["fps"] == 50.0
    assert video.read_bytes()[4:8] == b"ftyp"  # an MP4 container


def test_eval_video_mp4_without_the_extra_names_it(
    cartpole_run: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setitem(sys.modules, "imageio_ffmpeg", None)  # import fails as if not installed
    video = tmp_path / "v.mp4"
    result = invoke("eval", cartpole_run, "--episodes", "1", "--video", video)
    assert_refused(result, str(video), 'pip install "cartpole-q[video]"', "imageio-ffmpeg")
    assert not video.exists()
