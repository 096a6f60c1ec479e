"""Progress output: the bar ends on the real episode count; rates mean what they say."""

from __future__ import annotations

import io

from rich.console import Console

from cartpole_q.config import load_config
from cartpole_q.progress import PlainReporter, RichReporter, progress_line
from cartpole_q.training import Progress, train


def _progress(episode: int, env_steps: int, train_seconds: float) -> Progress:
    return Progress(episode, 1000, 500.0, 480.0, 0.0, env_steps, 9.0, None, train_seconds)


def test_bar_ends_on_the_episode_the_run_ended_on() -> None:
    console = Console(file=io.StringIO(), force_terminal=True, width=80)
    reporter = RichReporter(console=console, min_interval=3600.0)  # every later update throttled
    reporter.start("run", "seed 0", 1000)
    reporter.update("run", _progress(10, 300, 0.1))
    reporter.update("run", _progress(173, 50_000, 0.2))  # throttled away
    reporter.finish("run", "seed 0: solved at episode 173")
    task = reporter._progress.tasks[0]
    reporter.close()
    assert task.completed == 173 and task.total == 173


def test_rate_is_training_steps_over_training_time() -> None:
    # elapsed (9 s) includes periodic evaluations; the rate must not use it
    line = progress_line("run", _progress(150, 60_000, 1.5))
    assert "40,000 train steps/s" in line


def test_first_progress_after_a_resume_counts_the_earlier_training_time() -> None:
    config = load_config(
        overrides={
            "train.stop_when_solved": False,
            "train.episodes": 60,
            "train.eval_every": 0,
            "train.checkpoint_every": 20,
        }
    )
    checkpoints = []
    polls = iter([False, True])
    first = train(
        config,
        should_stop=lambda: next(polls, True),
        on_checkpoint=checkpoints.append,
        final_eval=False,
    )
    assert first.interrupted and checkpoints
    seen: list[Progress] = []
    train(config, resume=checkpoints[-1], on_progress=seen.append, final_eval=False)
    resumed = seen[0]
    # cumulative steps over cumulative training time, like summary.json's steps_per_second
    assert resumed.train_seconds >= checkpoints[-1].train_seconds
    assert resumed.train_steps_per_second == resumed.env_steps / resumed.train_seconds


def test_plain_reporter_names_its_rate() -> None:
    stream = io.StringIO()
    reporter = PlainReporter(stream)
    reporter.start("run", "run", 10)
    reporter.update("run", _progress(5, 1000, 0.01))
    assert "train steps/s" in stream.getvalue()


def test_a_workers_last_progress_reaches_the_parent_before_its_outcome() -> None:
    import multiprocessing

    from cartpole_q.experiments.workers import _PipeReporter

    receiver, sender = multiprocessing.Pipe(duplex=False)
    reporter = _PipeReporter(sender, min_interval=3600.0)
    reporter.update("w", _progress(10, 300, 0.1))
    reporter.update("w", _progress(173, 50_000, 0.2))  # throttled
    reporter.finish("w", "seed 0: solved at episode 173")
    messages = []
    while receiver.poll():
        messages.append(receiver.recv())
    assert [m[0] for m in messages][-2:] == ["update", "finish"]
    assert messages[-2][2] == 173
