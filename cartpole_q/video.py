"""Animated GIFs of the greedy policy, from Gymnasium's ``rgb_array`` rendering.

Frames come from ``env.render()`` (pygame, from the ``gymnasium[classic-control]``
extra), keep the renderer's size, and carry the episode and step. Every
third step is kept and shown for three steps' time, so the GIF plays in real time.
"""

from __future__ import annotations

import io
import os
from pathlib import Path
from typing import Any

# pygame needs a video driver even to draw off screen; "dummy" works without a display.
os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")

FRAME_STRIDE = 3
"""keep every third step (CartPole renders at 50 steps per second)"""
FRAME_MILLISECONDS = 60
"""three steps of 20 ms each"""


class GifRecorder:
    """Collects rendered frames through ``on_frame`` and writes them as a GIF.

    Args:
        path: the GIF file to write.
        episodes: how many episodes, from the first, to record.
    """

    def __init__(self, path: Path, episodes: int = 1) -> None:
        from cartpole_q.errors import UserError

        if path.is_dir():
            raise UserError(
                f"{path}: --video is a directory; give a file name such as {path / 'policy.gif'}."
            )
        if not path.parent.exists():
            raise UserError(f"{path}: the directory {path.parent} does not exist.")
        self._path = path
        self._episodes = episodes
        self._frames: list[Any] = []

    def on_frame(self, env: Any, episode: int, step: int) -> None:
        """Record a frame after a reset (step 0) or a step of a recorded episode."""
        if episode >= self._episodes or step % FRAME_STRIDE:
            return
        from PIL import Image, ImageDraw

        frame = Image.fromarray(env.render())
        draw = ImageDraw.Draw(frame)
        draw.text((10, 8), f"episode {episode + 1}   step {step}", fill=(0, 0, 0), font=_font())
        self._frames.append(frame.convert("P", palette=Image.Palette.ADAPTIVE, colors=32))

    def save(self) -> Path:
        """Write the GIF atomically; return its path."""
        from cartpole_q.errors import UserError
        from cartpole_q.rundir import atomic_write_bytes

        if not self._frames:
            raise UserError(f"{self._path}: no frames were recorded.")
        buffer = io.BytesIO()
        first, *rest = self._frames
        first.save(
            buffer, format="GIF", save_all=True, append_images=rest,
            duration=FRAME_MILLISECONDS, loop=0, optimize=False,
        )  # fmt: skip
        atomic_write_bytes(self._path, buffer.getvalue())
        return self._path


def _font() -> Any:
    from PIL import ImageFont

    try:
        return ImageFont.load_default(size=18)
    except TypeError:  # Pillow < 10.1 has only the small bitmap font
        return ImageFont.load_default()
