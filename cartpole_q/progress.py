"""Progress output while training: a live bar on a terminal, plain lines otherwise.

Reporters are cheap to call after every chunk of episodes: the live bar redraws at most
ten times a second, from the caller's thread (no refresh thread, so that worker processes
can be forked safely), and plain lines are printed every tenth of the run. A sweep has
one bar for all its runs.
"""

from __future__ import annotations

import sys
import time
from collections.abc import Hashable
from dataclasses import dataclass
from typing import IO, Any, Protocol

from cartpole_q.training import Progress


class Reporter(Protocol):
    """Receives training progress for one or more runs."""

    def start(self, key: Hashable, label: str, episodes: int) -> None:
        """A run (``key``) starts; ``episodes`` is its configured length."""
        ...

    def update(self, key: Hashable, progress: Progress) -> None:
        """A run advanced."""
        ...

    def finish(self, key: Hashable, line: str) -> None:
        """A run ended; ``line`` says how."""
        ...

    def close(self) -> None:
        """All runs ended."""
        ...


class NullReporter:
    """Prints nothing (``--quiet``)."""

    def start(self, key: Hashable, label: str, episodes: int) -> None:
        """Ignore."""

    def update(self, key: Hashable, progress: Progress) -> None:
        """Ignore."""

    def finish(self, key: Hashable, line: str) -> None:
        """Ignore."""

    def close(self) -> None:
        """Ignore."""


def progress_line(label: str, progress: Progress) -> str:
    """One plain line describing a run's progress.

    The rate is training env steps per second of training time (periodic evaluations
    excluded), the same figure as ``summary.json``'s ``steps_per_second``.

    >>> p = Progress(150, 1000, 500.0, 480.25, 0.0, 60000, 2.0, None, train_seconds=1.5)
    >>> progress_line("seed 0", p)
    'seed 0: episode 150/1000  return 500  avg100 480.2  epsilon 0.000  40,000 train steps/s'
    """
    rate = progress.train_steps_per_second
    solved = f"  solved at {progress.solved_episode}" if progress.solved_episode else ""
    return (
        f"{label}: episode {progress.episode}/{progress.episodes}  return {progress.last_return:g}  "
        f"avg100 {progress.moving_average:.1f}  epsilon {progress.epsilon:.3f}  "
        f"{rate:,.0f} train steps/s{solved}"
    )


class PlainReporter:
    """Plain lines, no control codes: for logs, pipes and CI."""

    def __init__(self, stream: IO[str] | None = None, every_fraction: float = 0.1) -> None:
        self._stream = stream or sys.stdout
        self._every_fraction = every_fraction
        self._labels: dict[Any, str] = {}
        self._next_line_at: dict[Any, int] = {}
        self._step: dict[Any, int] = {}
        self._single = True

    def start(self, key: Hashable, label: str, episodes: int) -> None:
        """Remember the run; lines come every tenth of its episodes."""
        self._labels[key] = label
        self._step[key] = max(1, int(episodes * self._every_fraction))
        self._next_line_at[key] = self._step[key]
        self._single = len(self._labels) == 1

    def update(self, key: Hashable, progress: Progress) -> None:
        """Print a line when the run crosses the next tenth (single runs only)."""
        if not self._single or progress.episode < self._next_line_at.get(key, 0):
            return
        step = self._step[key]
        self._next_line_at[key] = (progress.episode // step + 1) * step
        print(progress_line(self._labels[key], progress), file=self._stream, flush=True)

    def finish(self, key: Hashable, line: str) -> None:
        """Print how the run ended."""
        print(line, file=self._stream, flush=True)

    def close(self) -> None:
        """Nothing to close."""


def compact_rate(steps_per_second: float) -> str:
    """A rate in few characters.

    >>> compact_rate(950.0), compact_rate(148_781.0), compact_rate(28_233_949.0)
    ('950/s', '149k/s', '28.2M/s')
    """
    if steps_per_second >= 1e6:
        return f"{steps_per_second / 1e6:.1f}M/s"
    if steps_per_second >= 1e3:
        return f"{steps_per_second / 1e3:.0f}k/s"
    return f"{steps_per_second:.0f}/s"


class RichReporter:
    """A live rich progress display: one bar per run (or per worker), fitting 80 columns.

    Each bar shows the episode, the last return, the 100-episode average, epsilon, env
    steps per second and the time left; each finished run's outcome is printed above.
    """

    def __init__(self, console: Any | None = None, min_interval: float = 0.1) -> None:
        from rich.console import Console
        from rich.progress import (
            BarColumn,
            MofNCompleteColumn,
            TextColumn,
            TimeRemainingColumn,
        )
        from rich.progress import (
            Progress as RichProgress,
        )

        self._console = console or Console()
        self._progress = RichProgress(
            TextColumn("[bold]{task.description}"),
            BarColumn(bar_width=None),
            MofNCompleteColumn(),
            TextColumn("{task.fields[stats]}"),
            TextColumn("eta"),
            TimeRemainingColumn(),
            console=self._console,
            # Redrawn by update() itself (throttled): no refresh thread, so that worker
            # processes can be forked safely (see experiments.multiseed).
            auto_refresh=False,
            expand=True,
        )
        self._tasks: dict[Any, Any] = {}
        self._last_update: dict[Any, float] = {}
        self._latest: dict[Any, Progress] = {}
        self._min_interval = min_interval
        self._progress.start()

    def start(self, key: Hashable, label: str, episodes: int) -> None:
        """Add a bar for the run (or reuse the bar of ``key`` for its next run)."""
        if key in self._tasks:
            self._progress.reset(self._tasks[key], total=episodes, description=label, stats="")
        else:
            self._tasks[key] = self._progress.add_task(label, total=episodes, stats="")
        self._last_update[key] = 0.0
        self._latest.pop(key, None)

    def update(self, key: Hashable, progress: Progress) -> None:
        """Move the run's bar (throttled, so the bar never slows training)."""
        self._latest[key] = progress
        now = time.monotonic()
        if now - self._last_update.get(key, 0.0) < self._min_interval:
            return
        self._last_update[key] = now
        self._draw(key, progress)

    def _draw(self, key: Hashable, progress: Progress) -> None:
        stats = (
            f"ret {progress.last_return:>4g} avg100 {progress.moving_average:5.1f} "
            f"eps {progress.epsilon:.2f} {compact_rate(progress.train_steps_per_second):>7}"
        )
        self._progress.update(self._tasks[key], completed=progress.episode, stats=stats)
        self._progress.refresh()

    def finish(self, key: Hashable, line: str) -> None:
        """Print how the run ended above the bars, and complete its bar at the real count.

        The last update may have been throttled away: the bar is drawn once more from the
        latest progress, so it ends on the episode the run really ended on.
        """
        self._progress.console.print(line, highlight=False)
        task = self._tasks.get(key)
        if task is None:
            return
        latest = self._latest.pop(key, None)
        if latest is not None:
            self._draw(key, latest)
        completed = self._progress.tasks[task].completed or 1
        self._progress.update(task, total=completed, stats="done")
        self._progress.refresh()

    def close(self) -> None:
        """Stop the live display, leaving the final bars on screen."""
        self._progress.stop()


def make_reporter(quiet: bool, stream: IO[str] | None = None) -> Reporter:
    """The reporter for the output: none when quiet, a bar on a terminal, else plain lines."""
    stream = stream or sys.stdout
    if quiet:
        return NullReporter()
    if stream.isatty():
        return RichReporter()
    return PlainReporter(stream)


# -- sweeps: one bar for the whole sweep ---------------------------------------------------


class SweepProgress(Protocol):
    """Receives a sweep's progress: runs (point x seed) finished, points complete."""

    def start(self, total_runs: int, done_runs: int, total_points: int, done_points: int) -> None:
        """The sweep starts; ``done_runs`` were finished before (``--resume``)."""
        ...

    def advance(self, done_runs: int, done_points: int) -> None:
        """More runs finished."""
        ...

    def close(self) -> None:
        """The sweep ended."""
        ...


class NullSweepProgress:
    """Prints nothing (``--quiet``)."""

    def start(self, total_runs: int, done_runs: int, total_points: int, done_points: int) -> None:
        """Ignore."""

    def advance(self, done_runs: int, done_points: int) -> None:
        """Ignore."""

    def close(self) -> None:
        """Ignore."""


@dataclass(frozen=True)
class Units:
    """What a many-runs progress display counts: ``sweep: 10/100 runs, 1/10 points``."""

    title: str = "sweep"
    items: str = "runs"
    groups: str = "points"


ROBUSTNESS_UNITS = Units("robustness", "evaluations", "grid points")
"""``robustness`` counts (seed, grid point) evaluations and complete grid points"""


def sweep_line(done_runs: int, total_runs: int, done_points: int, total_points: int,
               rate: float, eta: float | None, units: Units = Units()) -> str:  # fmt: skip
    """One plain line of sweep progress.

    >>> sweep_line(1000, 10000, 10, 100, 171.4, 52.5)
    'sweep: 1,000/10,000 runs, 10/100 points, 171 runs/s, eta 52 s'
    """
    tail = "" if eta is None else f", eta {eta:.0f} s"
    return (
        f"{units.title}: {done_runs:,}/{total_runs:,} {units.items}, {done_points}/"
        f"{total_points} {units.groups}, {rate:,.0f} {units.items}/s{tail}"
    )


class PlainSweepProgress:
    """A plain line every tenth of the sweep (for logs, pipes and CI)."""

    def __init__(self, stream: IO[str] | None = None, units: Units = Units()) -> None:
        self._units = units
        self._stream = stream or sys.stdout
        self._total = self._points = self._first = 0
        self._next = 0
        self._started = 0.0

    def start(self, total_runs: int, done_runs: int, total_points: int, done_points: int) -> None:
        """Remember the totals."""
        self._total, self._points, self._first = total_runs, total_points, done_runs
        self._next = done_runs + max(1, total_runs // 10)
        self._started = time.monotonic()

    def advance(self, done_runs: int, done_points: int) -> None:
        """Print a line when the sweep crosses the next tenth."""
        if done_runs < self._next and done_runs < self._total:
            return
        self._next = done_runs + max(1, self._total // 10)
        rate, eta = _rate_and_eta(self._started, done_runs - self._first, self._total - done_runs)
        line = sweep_line(done_runs, self._total, done_points, self._points, rate, eta, self._units)
        print(line, file=self._stream, flush=True)

    def close(self) -> None:
        """Nothing to close."""


def _rate_and_eta(started: float, runs: int, left: int) -> tuple[float, float | None]:
    elapsed = time.monotonic() - started
    rate = runs / elapsed if elapsed > 0 else 0.0
    return rate, (left / rate if rate > 0 else None)


class RichSweepProgress:
    """A live bar: runs done of all, points complete, runs per second, time left."""

    def __init__(self, console: Any | None = None, units: Units = Units()) -> None:
        from rich.console import Console
        from rich.progress import BarColumn, MofNCompleteColumn, TextColumn, TimeRemainingColumn
        from rich.progress import Progress as RichProgress

        self._progress = RichProgress(
            TextColumn(f"[bold]{units.title}"),
            BarColumn(bar_width=None),
            MofNCompleteColumn(),
            TextColumn(units.items + "  {task.fields[points]}  {task.fields[rate]}"),
            TextColumn("eta"),
            TimeRemainingColumn(),
            console=console or Console(),
            auto_refresh=False,  # no refresh thread: workers can be forked safely
            expand=True,
        )
        self._task: Any = None
        self._points = self._first = 0
        self._started = 0.0
        self._units = units

    def start(self, total_runs: int, done_runs: int, total_points: int, done_points: int) -> None:
        """Show the bar."""
        self._points, self._first, self._started = total_points, done_runs, time.monotonic()
        self._task = self._progress.add_task(
            "sweep", total=total_runs, completed=done_runs,
            points=f"{done_points}/{total_points} {self._units.groups}", rate="",
        )  # fmt: skip
        self._progress.start()
        self._progress.refresh()

    def advance(self, done_runs: int, done_points: int) -> None:
        """Move the bar."""
        rate, _ = _rate_and_eta(self._started, done_runs - self._first, 0)
        self._progress.update(
            self._task, completed=done_runs,
            points=f"{done_points}/{self._points} {self._units.groups}",
            rate=f"{rate:,.0f} {self._units.items}/s",
        )  # fmt: skip
        self._progress.refresh()

    def close(self) -> None:
        """Stop the live display, leaving the final bar on screen."""
        self._progress.stop()


def make_sweep_progress(
    quiet: bool, stream: IO[str] | None = None, units: Units = Units()
) -> SweepProgress:
    """The sweep's progress display: none when quiet, a bar on a terminal, else lines."""
    stream = stream or sys.stdout
    if quiet:
        return NullSweepProgress()
    if stream.isatty():
        from rich.console import Console

        return RichSweepProgress(Console(file=stream), units)
    return PlainSweepProgress(stream, units)
