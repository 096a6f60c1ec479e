"""Pictures: PNG sizes, policy maps that match the table, GIFs that decode, progress output."""

from __future__ import annotations

import io
import json
from pathlib import Path

import numpy as np
import pytest
from PIL import Image
from rich.console import Console

from cartpole_q.figures import (
    Curve,
    MapDimensions,
    SeedBand,
    action_names,
    bootstrap_band,
    dimension_names,
    figure_png,
    moving_average,
    policy_figure,
    project_policy,
    reward_curve_figure,
)
from cartpole_q.progress import NullReporter, PlainReporter, RichReporter
from cartpole_q.store.video import FINAL_FRAME_MILLISECONDS, VideoRecorder
from cartpole_q.training import Progress
from tests.conftest import invoke


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("pictures") / "run"
    assert invoke("train", "--out", out, "-q").exit_code == 0
    return out


def decoded(data: bytes | Path) -> Image.Image:
    image = Image.open(io.BytesIO(data) if isinstance(data, bytes) else data)
    image.load()
    return image


def test_policy_map_shows_the_argmax_of_a_hand_made_table() -> None:
    # bins (1, 1, 2, 3): pole side x 3 angular-velocity bins, 2 actions
    q = np.zeros((1, 1, 2, 3, 2))
    q[0, 0, 0] = [[1.0, 0.0], [0.0, 2.0], [5.0, 4.0]]
    q[0, 0, 1] = [[0.0, 3.0], [7.0, 1.0], [0.5, 0.6]]
    visits = np.ones_like(q, dtype=np.int64)
    figure = policy_figure(
        q, visits, MapDimensions((2, 3), [-2.4, -3, -0.2, -2], [2.4, 3, 0.2, 2], list("abcd")), "t"
    )
    shown = np.asarray(figure.axes[0].images[0].get_array())
    assert shown.tolist() == np.argmax(q[0, 0], axis=-1).tolist() == [[0, 1, 0], [1, 0, 1]]
    values = np.asarray(figure.axes[1].images[0].get_array())
    assert values.tolist() == q[0, 0].max(axis=-1).tolist()
    assert decoded(figure_png(figure)).size == (1350, 420)


def test_policy_projection_weights_other_dimensions_by_visits() -> None:
    q = np.zeros((2, 1, 2))  # dimension 0 is averaged out
    q[0, 0] = [1.0, 0.0]  # visited often: prefers action 0
    q[1, 0] = [0.0, 3.0]  # visited once: prefers action 1
    visits = np.zeros((2, 1, 2), dtype=np.int64)
    visits[0, 0, 0], visits[1, 0, 1] = 9, 1
    # as a (2, 1, 1) grid: dimensions 1 and 2 are drawn, dimension 0 is averaged out
    q_map, value_map, visit_map = project_policy(
        q.reshape(2, 1, 1, 2), visits.reshape(2, 1, 1, 2), (1, 2)
    )
    # weights 9/10 and 1/10: Q = 0.9 * [1, 0] + 0.1 * [0, 3] = [0.9, 0.3]
    assert q_map[0, 0].tolist() == pytest.approx([0.9, 0.3])
    assert visit_map.tolist() == [[10.0]]
    assert value_map[0, 0] == pytest.approx(0.9)


def test_unvisited_states_are_blank_in_the_policy_map() -> None:
    q = np.arange(8, dtype=float).reshape(1, 1, 2, 2, 2)
    visits = np.zeros_like(q, dtype=np.int64)
    visits[0, 0, 1, 1, 0] = 3
    figure = policy_figure(q, visits, MapDimensions((2, 3), [0] * 4, [1] * 4, list("abcd")), "t")
    shown = figure.axes[0].images[0].get_array()
    assert np.ma.getmaskarray(shown).tolist() == [[True, True], [True, False]]


def test_policy_plot_command(run_dir: Path, tmp_path: Path) -> None:
    out = tmp_path / "policy.png"
    result = invoke("plot", run_dir, "--policy", "--out", out)
    assert result.exit_code == 0, result.output
    assert decoded(out).size == (1350, 420)
    assert (
        invoke("plot", run_dir, "--policy", "--dims", "3,2", "--out", out, "--force").exit_code == 0
    )
    for bad in ("2", "2,2", "1,9", "a,b"):
        result = invoke("plot", run_dir, "--policy", "--dims", bad, "--out", out)
        assert result.exit_code == 2 and "--dims" in result.stderr
    result = invoke("plot", run_dir, run_dir, "--policy")
    assert result.exit_code == 2 and "exactly one" in result.stderr


def test_reward_curve_with_seed_band_decodes() -> None:
    rng = np.random.default_rng(0)
    band = SeedBand("default", [rng.uniform(0, 500, n) for n in (150, 180, 200)], [150, 180, None])
    figure = reward_curve_figure([band, Curve("single", rng.uniform(0, 500, 120), None)], 475.0)
    assert decoded(figure_png(figure)).size == (800, 450)
    labels = [text.get_text() for text in figure.axes[0].get_legend().get_texts()]
    assert labels[0] == "default: mean of 3 seeds, 95% CI, median solve 165"
    assert labels[-1] == "reward threshold 475"


def test_policy_map_has_one_labelled_colour_per_action() -> None:
    q = np.random.default_rng(0).normal(size=(1, 1, 4, 5, 3))
    names = action_names("MountainCar-v0", 3)
    figure = policy_figure(
        q, None, MapDimensions((2, 3), [0] * 4, [1] * 4, list("abcd")), "t", names
    )
    image = figure.axes[0].images[0]
    assert image.cmap.N == 3 and image.norm(np.array([0, 1, 2])).tolist() == [0, 1, 2]
    bar = figure.axes[3]  # the colour bar next to the first panel
    figure_png(figure)  # draw, so that tick labels exist
    labels = [label.get_text() for label in bar.get_yticklabels()]
    assert labels == ["0: accelerate left", "1: don't accelerate", "2: accelerate right"]
    assert action_names("CartPole-v1", 2) == ["push left", "push right"]
    assert action_names("Acrobot-v1", 3) == ["torque -1", "torque 0", "torque +1"]
    assert action_names("CartPole-v1", 3) is None


def test_known_environments_name_their_axes() -> None:
    assert dimension_names("CartPole-v1", 4)[0] == "cart position (m)"
    assert dimension_names("MountainCar-v0", 2) == ["position", "velocity"]
    assert dimension_names("Acrobot-v1", 6)[:2] == ["cos θ1", "sin θ1"]
    assert dimension_names("Acrobot-v1", 6)[4].startswith("θ1 velocity")
    assert dimension_names("Mine-v0", 2) == ["observation 0", "observation 1"]


def test_seed_band_label_says_the_faint_lines_are_seed_averages() -> None:
    rng = np.random.default_rng(0)
    band = SeedBand("s", [rng.uniform(0, 500, 120) for _ in range(3)], [None] * 3)
    axes = reward_curve_figure([band], 475.0).axes[0]
    label = axes.get_title()  # under the title: a long y label would be cut off
    assert "each episode" not in label and "each seed" in label
    assert axes.get_ylabel() == "return"


def test_runs_with_different_thresholds_draw_each() -> None:
    rng = np.random.default_rng(0)
    curves = [
        Curve("short", rng.uniform(0, 100, 50), None, threshold=95.0),
        Curve("long", rng.uniform(0, 500, 50), None, threshold=475.0),
    ]
    figure = reward_curve_figure(curves, None)
    labels = [text.get_text() for text in figure.axes[0].get_legend().get_texts()]
    assert "short: reward threshold 95" in labels and "long: reward threshold 475" in labels
    same = [Curve("a", curves[0].returns, None, 475.0), Curve("b", curves[1].returns, None, 475.0)]
    labels = [
        t.get_text() for t in reward_curve_figure(same, None).axes[0].get_legend().get_texts()
    ]
    assert labels[-1] == "reward threshold 475" and len(labels) == 3


def test_an_interrupted_run_says_so_on_its_plot(run_dir: Path, tmp_path: Path) -> None:
    curve = Curve("run", np.arange(40.0), None, interrupted=True)
    labels = [
        t.get_text() for t in reward_curve_figure([curve], 475.0).axes[0].get_legend().get_texts()
    ]
    assert labels[0] == "run (interrupted at episode 40)"
    band = SeedBand("seeds", [np.arange(40.0)] * 3, [None] * 3, interrupted=2)
    labels = [
        t.get_text() for t in reward_curve_figure([band], 475.0).axes[0].get_legend().get_texts()
    ]
    assert labels[0].endswith(", 2 interrupted")


def test_bootstrap_band_brackets_the_mean() -> None:
    curves = np.random.default_rng(1).normal(100, 10, size=(20, 50))
    mean, low, high = bootstrap_band(curves, np.random.default_rng(2))
    assert np.allclose(mean, curves.mean(axis=0))
    assert (low <= mean).all() and (mean <= high).all()
    # the 95% band of a mean of 20 samples of sd 10 is about +-4.4 wide
    assert 2.0 < float(np.median(high - low)) / 2 < 7.0
    same = np.tile(np.arange(5.0), (4, 1))
    assert bootstrap_band(same, np.random.default_rng(0))[1].tolist() == list(range(5))


def test_moving_average_uses_a_trailing_window() -> None:
    values = np.arange(1, 201, dtype=float)
    average = moving_average(values)
    assert average[0] == 1.0 and average[99] == 50.5 and average[199] == 150.5


def test_video_gif_decodes_with_the_renderer_size(run_dir: Path, tmp_path: Path) -> None:
    gif = tmp_path / "policy.gif"
    result = invoke("eval", run_dir, "--episodes", "2", "--video", gif, "--json")
    assert result.exit_code == 0, result.output
    assert json.loads(result.stdout)["episodes"] == 2  # stdout stays pure JSON
    image = Image.open(gif)
    assert image.format == "GIF" and image.size == (600, 400)
    # a 500-step episode: every third step from 0 to 498, and the final step 500
    assert image.n_frames == 500 // 3 + 2
    durations = []
    for index in range(image.n_frames):
        image.seek(index)
        image.load()
        durations.append(image.info["duration"])
    # CartPole's 50 steps per second: three steps are 60 ms, the last two 40 ms
    assert set(durations[:-2]) == {60} and durations[-2:] == [40, FINAL_FRAME_MILLISECONDS]


class _FakeEnv:
    """An environment that only renders: a uniform frame at a given frame rate."""

    def __init__(self, fps: float, colour: tuple[int, int, int]) -> None:
        self.metadata = {"render_fps": fps}
        self._frame = np.full((120, 300, 3), colour, dtype=np.uint8)

    def render(self) -> np.ndarray:
        return self._frame


def _record(path: Path, env: _FakeEnv, lengths: list[int]) -> Image.Image:
    recorder = VideoRecorder(path, episodes=len(lengths))
    for episode, length in enumerate(lengths):
        for step in range(length + 1):
            recorder.on_frame(env, episode, step)
    recorder.save()
    return Image.open(path)


def test_gif_timing_follows_the_environments_frame_rate(tmp_path: Path) -> None:
    # Acrobot renders 15 steps per second: three steps last 200 ms
    image = _record(tmp_path / "slow.gif", _FakeEnv(15, (255, 255, 255)), [7, 4])
    durations = []
    for index in range(image.n_frames):
        image.seek(index)
        durations.append(image.info["duration"])
    # episode 1: steps 0, 3, 6, 7 (final); episode 2: steps 0, 3, 4 (final)
    assert durations == [200, 200, 70, 500, 200, 70, 500]


def test_gif_text_is_readable_on_dark_frames(tmp_path: Path) -> None:
    image = _record(tmp_path / "dark.gif", _FakeEnv(50, (0, 0, 0)), [3]).convert("L")
    text_area = np.asarray(image)[:30, :200]
    assert (text_area > 200).sum() > 100  # white letters
    image = _record(tmp_path / "light.gif", _FakeEnv(50, (255, 255, 255)), [3]).convert("L")
    assert (np.asarray(image)[:30, :200] < 50).sum() > 100  # their black outline


def test_render_without_a_display_is_refused(
    run_dir: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    result = invoke("eval", run_dir, "--render")
    assert result.exit_code == 2 and "--render needs a display" in result.stderr
    assert "Traceback" not in result.output


def _progress(episode: int) -> Progress:
    return Progress(episode, 100, 200.0, 150.5, 0.1, episode * 200, 0.5, None)


def test_plain_reporter_prints_every_tenth_without_control_codes() -> None:
    stream = io.StringIO()
    reporter = PlainReporter(stream)
    reporter.start("run", "demo", 100)
    for episode in range(1, 101):
        reporter.update("run", _progress(episode))
    reporter.finish("run", "demo: done")
    lines = stream.getvalue().splitlines()
    assert (
        len(lines) == 11
        and lines[0].startswith("demo: episode 10/100")
        and lines[-1] == "demo: done"
    )
    assert "\x1b" not in stream.getvalue()


def test_rich_reporter_draws_a_bar_on_a_terminal() -> None:
    stream = io.StringIO()
    reporter = RichReporter(Console(file=stream, force_terminal=True, width=150), min_interval=0.0)
    reporter.start("run", "demo", 100)
    reporter.update("run", _progress(50))
    reporter.finish("run", "demo: solved")
    reporter.close()
    output = stream.getvalue()
    # the outcome is printed above the bar, which ends at the 50 episodes the update reported
    assert "\x1b" in output and "50/50" in output and "demo: solved" in output and "done" in output


def test_null_reporter_prints_nothing(capsys: pytest.CaptureFixture[str]) -> None:
    reporter = NullReporter()
    reporter.start("run", "demo", 10)
    reporter.update("run", _progress(5))
    reporter.finish("run", "done")
    assert capsys.readouterr() == ("", "")


def test_run_files_follow_the_umask(run_dir: Path) -> None:
    import os

    umask = os.umask(0)
    os.umask(umask)
    for path in run_dir.iterdir():
        assert path.stat().st_mode & 0o777 == 0o666 & ~umask, path
