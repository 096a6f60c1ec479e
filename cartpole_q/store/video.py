"""Videos of the greedy policy (GIF, or MP4 with an FFmpeg encoder), from ``rgb_array`` frames.

Frames come from ``env.render()`` (pygame, from the ``gymnasium[classic-control]``
extra), keep the renderer's size, and carry the episode and step in white letters with
a black outline, readable on light and dark frames alike. The clock is the
environment's own ``metadata["render_fps"]`` (50 steps per second for CartPole, 30 for
MountainCar, 15 for Acrobot):

- a GIF keeps every third step, each shown for three steps' time, plus the final step
  of every episode, held for half a second;
- an MP4 keeps every step (a recorded episode of ``n`` steps gives ``n + 1`` frames, its
  reset included), at ``render_fps`` frames per second, H.264 in ``yuv420p`` so that
  browsers and phones play it. It needs the optional ``[video]`` extra
  (``pip install "cartpole-q[video]"``: imageio-ffmpeg, which brings its own FFmpeg).

Every environment whose ``metadata["render_modes"]`` has ``rgb_array`` can be recorded
(CartPole, MountainCar, Acrobot, FrozenLake, Taxi, CliffWalking, Blackjack); the others
(Sutton & Barto's worlds under ``cartpole_q/``) are refused before anything is played.
"""

from __future__ import annotations

import contextlib
import io
import os
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from cartpole_q.errors import UserError

VIDEO_SUFFIXES = (".gif", ".mp4")
"""the extensions ``eval --video`` writes"""
FRAME_STRIDE = 3
"""a GIF keeps every third step"""
DEFAULT_FPS = 50.0
"""steps per second of an environment that does not say (CartPole's)"""
FINAL_FRAME_MILLISECONDS = 500
"""how long a GIF holds the last frame of each episode"""
TEXT_COLOUR = (255, 255, 255)
OUTLINE_COLOUR = (0, 0, 0)


def mp4_encoder(path: Path) -> Any:
    """Return the ``imageio_ffmpeg`` module, which writes ``path``.

    Raises:
        UserError: it is not installed (or finds no FFmpeg), saying what to install.
    """
    try:
        import imageio_ffmpeg

        imageio_ffmpeg.get_ffmpeg_exe()
    except (ImportError, RuntimeError):
        raise UserError(
            f"{path}: --video: writing .mp4 needs an FFmpeg encoder, from the optional video "
            'extra: install it with `pip install "cartpole-q[video]"` (imageio-ffmpeg), or '
            "write a GIF (--video FILE.gif)."
        ) from None
    return imageio_ffmpeg


def check_renderer(env_id: str, option: str = "--video") -> None:
    """Refuse to record an environment that cannot draw itself, before anything is played.

    An environment class that declares no ``rgb_array`` among its
    ``metadata["render_modes"]`` has no renderer. An id whose class cannot be looked up
    here (a plug-in's ``module:Env``) is left to ``gymnasium.make``, which names the problem.

    Args:
        env_id: the run's ``env.id``.
        option: the option that asked for frames, for the message.

    Raises:
        UserError: the environment has no ``rgb_array`` renderer.
    """
    import gymnasium
    from gymnasium.envs.registration import load_env_creator

    try:
        entry_point = gymnasium.spec(env_id).entry_point
        creator = load_env_creator(entry_point) if isinstance(entry_point, str) else entry_point
    except Exception:  # whatever the lookup raises: gymnasium.make will say it better
        return
    metadata = getattr(creator, "metadata", None)
    if not isinstance(metadata, dict) or "render_modes" not in metadata:
        return
    modes = list(metadata["render_modes"])
    if "rgb_array" not in modes:
        raise UserError(
            f"{option}: env.id {env_id!r} has no renderer to record (its render_modes are "
            f"{modes}, without 'rgb_array'); recordings work for environments that draw "
            "themselves, such as CartPole, MountainCar, Acrobot, FrozenLake, Taxi, "
            "CliffWalking and Blackjack."
        )


@contextmanager
def offscreen_rendering() -> Iterator[None]:
    """Let pygame draw without a display while recording, and only then.

    pygame needs a video driver even to draw off screen; ``dummy`` works without a
    display. It is restored afterwards so that a later ``--render`` in the same process
    still opens a real window.
    """
    previous = os.environ.get("SDL_VIDEODRIVER")
    os.environ["SDL_VIDEODRIVER"] = "dummy"
    os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")
    try:
        yield
    finally:
        if previous is None:
            os.environ.pop("SDL_VIDEODRIVER", None)
        else:
            os.environ["SDL_VIDEODRIVER"] = previous


class VideoRecorder:
    """Collects rendered frames through ``on_frame`` and writes them as a GIF or an MP4.

    The output is checked when the recorder is made, before any episode is played.

    Args:
        path: the ``.gif`` or ``.mp4`` file to write.
        episodes: how many episodes, from the first, to record.
        force: replace ``path`` if it exists.

    Raises:
        UserError: another extension, MP4 without an encoder, an existing file without
            ``force``, or a directory where no file can be created.
    """

    def __init__(self, path: Path, episodes: int = 1, force: bool = False) -> None:
        from cartpole_q.store.atomic import check_output_file

        self._format = check_output_file(path, "--video", VIDEO_SUFFIXES, force)
        self._encoder = mp4_encoder(path) if self._format == ".mp4" else None
        self._path = path
        self._episodes = episodes
        self._stride = FRAME_STRIDE if self._format == ".gif" else 1
        self._fps: float | None = None
        self._frames: list[Any] = []
        """GIF frames (palette images)"""
        self._steps: list[tuple[int, int]] = []
        """``(episode, step)`` of each GIF frame"""
        self._pending: tuple[int, int, Any] | None = None
        """the latest step off the stride: the episode's last frame if no step follows"""
        self._mp4: Any = None
        self._mp4_file: Path | None = None
        self._directory: tempfile.TemporaryDirectory[str] | None = None

    @property
    def frames(self) -> int:
        """How many frames have been recorded."""
        return len(self._steps)

    def on_frame(self, env: Any, episode: int, step: int) -> None:
        """Record a frame after a reset (step 0) or a step of a recorded episode."""
        if step == 0 or episode >= self._episodes:
            self._flush()
        if episode >= self._episodes:
            return
        if self._fps is None:
            fps = (getattr(env, "metadata", None) or {}).get("render_fps")
            self._fps = float(fps) if fps else DEFAULT_FPS
        if step % self._stride == 0:
            self._pending = None
            self._add(episode, step, env.render())
        else:
            self._pending = (episode, step, env.render())

    def save(self) -> Path:
        """Write the video atomically; return its path."""
        from cartpole_q.store.atomic import atomic_write_bytes

        self._flush()
        if not self._steps:
            raise UserError(f"{self._path}: no frames were recorded.")
        data = self._mp4_bytes() if self._format == ".mp4" else self._gif_bytes()
        atomic_write_bytes(self._path, data)
        return self._path

    def close(self) -> None:
        """Stop the encoder and remove its temporary files (also after a failure)."""
        if self._mp4 is not None:
            # A broken encoder is already being reported; closing it must not hide that.
            with contextlib.suppress(Exception):
                self._mp4.close()
            self._mp4 = None
        if self._directory is not None:
            self._directory.cleanup()
            self._directory = None

    def __enter__(self) -> VideoRecorder:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.close()

    def _flush(self) -> None:
        if self._pending is not None:
            self._add(*self._pending)
            self._pending = None

    def _add(self, episode: int, step: int, pixels: Any) -> None:
        from PIL import Image, ImageDraw

        frame = Image.fromarray(pixels)
        ImageDraw.Draw(frame).text(
            (10, 8), f"episode {episode + 1}   step {step}", fill=TEXT_COLOUR,
            font=_font(), stroke_width=2, stroke_fill=OUTLINE_COLOUR,
        )  # fmt: skip
        self._steps.append((episode, step))
        if self._format == ".mp4":
            self._send_mp4(frame)
        else:
            # Octree quantisation is several times faster than median cut, and as good here.
            self._frames.append(frame.quantize(32, method=Image.Quantize.FASTOCTREE))

    def _durations(self) -> list[int]:
        """Milliseconds of each GIF frame: the steps until the next frame, at ``render_fps``.

        Rounded to 10 ms, the resolution a GIF stores.
        """
        step_ms = 1000.0 / (self._fps or DEFAULT_FPS)
        durations = []
        for (episode, step), (next_episode, next_step) in zip(
            self._steps, [*self._steps[1:], (-1, 0)], strict=True
        ):
            if next_episode == episode:
                milliseconds = (next_step - step) * step_ms
            else:
                milliseconds = max(FINAL_FRAME_MILLISECONDS, self._stride * step_ms)
            durations.append(max(10, 10 * round(milliseconds / 10)))
        return durations

    def _gif_bytes(self) -> bytes:
        buffer = io.BytesIO()
        first, *rest = self._frames
        first.save(
            buffer, format="GIF", save_all=True, append_images=rest,
            duration=self._durations(), loop=0, optimize=False,
        )  # fmt: skip
        return buffer.getvalue()

    def _send_mp4(self, frame: Any) -> None:
        import numpy as np

        try:
            if self._mp4 is None:
                self._directory = tempfile.TemporaryDirectory(prefix="cartpole-q-video-")
                self._mp4_file = Path(self._directory.name) / "video.mp4"
                width, height = frame.size
                self._mp4 = self._encoder.write_frames(  # type: ignore[union-attr]
                    str(self._mp4_file), (width, height), fps=self._fps or DEFAULT_FPS,
                    codec="libx264", pix_fmt_out="yuv420p", macro_block_size=2,
                    ffmpeg_log_level="error",
                )  # fmt: skip
                self._mp4.send(None)
            self._mp4.send(np.ascontiguousarray(np.asarray(frame.convert("RGB"))))
        except (OSError, RuntimeError) as error:
            self.close()
            raise UserError(f"{self._path}: FFmpeg could not encode the video ({error}).") from None

    def _mp4_bytes(self) -> bytes:
        try:
            self._mp4.close()
            self._mp4 = None
            return self._mp4_file.read_bytes()  # type: ignore[union-attr]
        except (OSError, RuntimeError) as error:
            raise UserError(f"{self._path}: FFmpeg could not encode the video ({error}).") from None
        finally:
            self.close()


GifRecorder = VideoRecorder
"""the name this class had when it wrote GIFs only"""


def _font() -> Any:
    from PIL import ImageFont

    try:
        return ImageFont.load_default(size=18)
    except TypeError:  # Pillow < 10.1 has only the small bitmap font
        return ImageFont.load_default()
