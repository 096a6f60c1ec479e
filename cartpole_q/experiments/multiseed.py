"""Many seeds in one command: one contract run per seed, in parallel, and an aggregate.

The parent directory holds the config (with ``train.seeds``), one ``seed-NNN``
subdirectory per seed (each a complete single run whose ``config.yaml`` reproduces it
alone), and an aggregate ``summary.json`` written last. Seeds run in worker processes,
one per core; a seed's results do not depend on which worker ran it, or when.
"""

from __future__ import annotations

import dataclasses
import os
import time
from collections.abc import Callable, Iterator, Sequence
from contextlib import suppress
from pathlib import Path
from typing import Any

import numpy as np

from cartpole_q.config import format_seeds, load_config
from cartpole_q.errors import RunError
from cartpole_q.experiments.run import Prepared, execute_run, prepare
from cartpole_q.experiments.workers import (
    JobHandle,
    chunk_size,
    default_workers,
    execute,
    map_jobs,
)
from cartpole_q.progress import NullReporter, Reporter
from cartpole_q.store import rundir
from cartpole_q.store.atomic import write_json


def seed_dir(parent: Path, seed: int, seeds: tuple[int, ...]) -> Path:
    """The subdirectory of one seed: ``seed-007`` when the largest seed has up to 3 digits."""
    width = max(3, len(str(max(seeds))))
    return parent / f"seed-{seed:0{width}d}"


def run_seeds(
    prepared: Prepared,
    parent: Path,
    *,
    workers: int,
    reporter: Reporter | None = None,
    should_stop: Callable[[], bool] | None = None,
    resume: bool = False,
    seed_plots: bool = False,
) -> dict[str, Any]:
    """Train every seed of ``prepared.config`` under ``parent`` and write the aggregate.

    Args:
        prepared: the checked multi-seed config.
        parent: the parent run directory, holding the multi-seed ``config.yaml``.
        workers: worker processes; 1 trains in this process, one seed after another.
        reporter: receives each worker's progress and each seed's outcome.
        should_stop: polled while waiting; when true, workers stop at the end of their
            current episode and unstarted seeds are left for ``--resume``.
        resume: keep finished seeds, resume interrupted ones, start the rest.
        seed_plots: draw each seed's ``reward_curve.png`` (about 0.15 s per seed) and the
            parent's, which shows every seed with a band. Without it no figure is drawn,
            so that many seeds train in seconds (``cartpole-q plot DIR`` draws it later).

    Returns:
        The aggregate summary (also written as ``parent/summary.json``).
    """
    reporter = reporter or NullReporter()
    config = prepared.config
    seeds = config.train.seeds
    assert seeds is not None
    started = time.perf_counter()
    if resume:
        (parent / rundir.SUMMARY_FILE).unlink(missing_ok=True)
    jobs: list[tuple[int, Path, bool]] = []
    for seed in seeds:
        child = seed_dir(parent, seed, seeds)
        if resume and _finished(child):
            continue
        # A started seed resumes from its checkpoint (or from episode 0 if it has none).
        child_resume = resume and (child / rundir.CONFIG_FILE).is_file()
        if not child_resume:
            child.mkdir(parents=True, exist_ok=True)
            rundir.write_config(child, config.for_seed(seed))
        jobs.append((seed, child, child_resume))

    finished: list[int] = []

    def on_item(index: int, item: tuple[int, bool]) -> None:
        seed, interrupted = item
        if not interrupted:
            finished.append(seed)

    # Several seeds per job: a worker loads the config and the compiled loop once per
    # job, not once per seed.
    items = [(str(child), seed, child_resume) for seed, child, child_resume in jobs]
    size = chunk_size(len(items), workers)
    chunks = [(items[i : i + size], seed_plots) for i in range(0, len(items), size)]
    execute(
        _train_seeds, chunks, on_item, workers=workers, should_stop=should_stop, reporter=reporter
    )
    interrupted = len(finished) < len(jobs)

    summary = aggregate(parent, seeds, time.perf_counter() - started, interrupted)
    if seed_plots:
        _plot_seeds(parent)
    write_json(parent / rundir.SUMMARY_FILE, summary)
    return summary


def _plot_seeds(parent: Path) -> None:
    """Draw the parent's ``reward_curve.png``: every finished seed's returns, with a band."""
    from cartpole_q.experiments.plots import plot_rewards

    with suppress(RunError):  # no seed has finished: there is nothing to draw
        plot_rewards([parent], parent / rundir.CURVE_FILE, force=True)


def _train_seeds(
    handle: JobHandle, items: Sequence[tuple[str, int, bool]], plot: bool
) -> Iterator[tuple[int, bool]]:
    """Job: train seeds into their directories, one after another.

    Each item is (seed directory, seed, resume). The seeds share one config but their
    seed, so it is checked against its environment once.

    Yields:
        ``(seed, interrupted)`` as each started seed ends; a stop leaves the rest out.
    """
    env_info = None
    reporter = handle.reporter()
    for child, seed, resume in items:
        if handle.should_stop():
            return
        path = Path(child)
        config = load_config(path / rundir.CONFIG_FILE)
        if env_info is None:
            prepared = prepare(config, str(path / rundir.CONFIG_FILE))
            env_info = prepared.env_info
        else:
            prepared = dataclasses.replace(prepared, config=config)
        outcome = execute_run(
            path, prepared, resume=resume, should_stop=handle.should_stop, reporter=reporter,
            key=f"worker {os.getpid()}", label=f"seed {seed}", plot=plot,
        )  # fmt: skip
        yield seed, outcome.result.interrupted


def _finished(child: Path) -> bool:
    summary = rundir.read_summary(child)
    return summary is not None and not summary.get("interrupted", True)


def _spread(values: list[float]) -> dict[str, float] | None:
    if not values:
        return None
    q25, median, q75 = np.percentile(values, [25, 50, 75])
    return {"median": float(median), "q25": float(q25), "q75": float(q75)}


def aggregate(
    parent: Path, seeds: tuple[int, ...], wall_seconds: float, interrupted: bool
) -> dict[str, Any]:
    """Summarise the seeds' runs: success rate, solve episodes and env steps, eval means.

    Every statistic (``success_rate`` included) is over the finished seeds (``finished`` of
    ``runs``); the others are counted in ``unfinished`` and named in ``interrupted_seeds``
    (stopped early, listed in ``per_seed`` too) and ``no_result_seeds`` (not started, or
    killed before writing a result), both in ``--seeds`` syntax.
    """
    per_seed: dict[str, dict[str, Any]] = {}
    threshold = None
    engine = None
    for seed in seeds:
        child = seed_dir(parent, seed, seeds)
        summary = rundir.read_summary(child)
        if summary is None:
            continue
        threshold = summary.get("reward_threshold", threshold)
        engine = summary.get("engine", engine)
        per_seed[str(seed)] = {
            "path": child.name,
            "solved_episode": summary.get("solved_episode"),
            "env_steps_to_solve": summary.get("env_steps_to_solve"),
            "eval_mean": (summary.get("eval") or {}).get("mean"),
            "first_greedy_success": summary.get("first_greedy_success"),
            "episodes": summary.get("episodes"),
            "interrupted": summary.get("interrupted", False),
        }
    finished = [run for run in per_seed.values() if not run["interrupted"]]
    eval_means = [run["eval_mean"] for run in finished if run["eval_mean"] is not None]
    successes = sum(1 for mean in eval_means if threshold is not None and mean >= threshold)
    solved = [run["solved_episode"] for run in finished if run["solved_episode"] is not None]
    steps = [run["env_steps_to_solve"] for run in finished if run["env_steps_to_solve"] is not None]
    greedy = [
        run["first_greedy_success"]["env_steps"] for run in finished if run["first_greedy_success"]
    ]
    interrupted_seeds = [seed for seed in seeds if per_seed.get(str(seed), {}).get("interrupted")]
    no_result = [seed for seed in seeds if str(seed) not in per_seed]
    return {
        "seeds": format_seeds(seeds),
        "runs": len(seeds),
        "finished": len(finished),
        "unfinished": len(seeds) - len(finished),
        "interrupted_seeds": format_seeds(interrupted_seeds),
        "no_result_seeds": format_seeds(no_result),
        "interrupted": interrupted or len(finished) < len(seeds),
        "engine": engine,
        "reward_threshold": threshold,
        "successes": successes,
        "success_rate": successes / len(finished) if finished else None,
        "solved_runs": len(solved),
        "solved_episode": _spread(solved),
        "env_steps_to_solve": _spread(steps),
        "first_greedy_success_env_steps": _spread(greedy),
        "eval_mean": (
            None
            if not eval_means
            else {
                "mean": float(np.mean(eval_means)),
                "min": float(np.min(eval_means)),
                "median": float(np.median(eval_means)),
            }
        ),
        "wall_seconds": round(wall_seconds, 3),
        "per_seed": per_seed,
        "versions": rundir.versions(),
    }


def load_seed_runs(parent: Path) -> list[rundir.Run]:
    """Load every seed run of a multi-seed parent directory that has a result.

    Raises:
        RunError: no seed run of ``parent`` is complete.
    """
    config = load_config(parent / rundir.CONFIG_FILE)
    seeds = config.train.seeds
    assert seeds is not None
    runs = [
        rundir.load_run(seed_dir(parent, seed, seeds))
        for seed in seeds
        if (seed_dir(parent, seed, seeds) / rundir.SUMMARY_FILE).is_file()
    ]
    if not runs:
        raise RunError(f"{parent}: none of its seed runs has finished.")
    return runs


@dataclasses.dataclass(frozen=True)
class SeedStatus:
    """Which seeds of a multi-seed run have finished, and why the others have not."""

    finished: list[tuple[int, Path]]
    missing: list[tuple[int, Path]]  # no directory
    unfinished: list[tuple[int, Path]]  # not started, interrupted or killed

    def note(self, parent: Path) -> str | None:
        """One line naming the seeds left out, or None when every seed finished."""
        if not self.missing and not self.unfinished:
            return None
        total = len(self.finished) + len(self.missing) + len(self.unfinished)
        parts = []
        if self.missing:
            parts.append(
                f"{_names(self.missing)} {'is' if len(self.missing) == 1 else 'are'} missing"
            )
        if self.unfinished:
            verb = "has" if len(self.unfinished) == 1 else "have"
            parts.append(f"{_names(self.unfinished)} {verb} not finished")
        return (
            f"{parent}: {len(self.missing) + len(self.unfinished)} of {total} seeds not evaluated: "
            f"{'; '.join(parts)} (finish them with `cartpole-q train --resume {parent}`)"
        )


def _names(items: list[tuple[int, Path]], limit: int = 8) -> str:
    names = [path.name for _, path in items]
    shown = ", ".join(names[:limit])
    return shown if len(names) <= limit else f"{shown} and {len(names) - limit} more"


def seed_status(parent: Path) -> SeedStatus:
    """Sort the seeds of a multi-seed run into finished, missing and unfinished."""
    config = load_config(parent / rundir.CONFIG_FILE)
    seeds = config.train.seeds
    assert seeds is not None
    status = SeedStatus([], [], [])
    for seed in seeds:
        child = seed_dir(parent, seed, seeds)
        if not child.is_dir():
            status.missing.append((seed, child))
        elif _finished(child):
            status.finished.append((seed, child))
        else:
            status.unfinished.append((seed, child))
    return status


def _evaluate_one(
    handle: JobHandle | None,
    path: str,
    episodes: int | None,
    seed: int | None,
    physics: dict[str, Any] | None = None,
    max_steps: int | None = None,
) -> dict[str, Any]:
    from cartpole_q.evaluation import evaluate, exact_report, under_conditions

    run = rundir.load_run(path)
    config = under_conditions(run.config, physics, max_steps)
    report = evaluate(run.q_table, config, episodes=episodes, seed=seed)
    result = {"run_seed": run.config.seed, "path": run.path.name, **report.to_dict()}
    exact = exact_report(config, run.q_table)
    if not isinstance(exact, str):
        result["exact"] = exact.to_dict()
    return result


def exact_summary(results: list[dict[str, Any]]) -> dict[str, Any] | None:
    """The seeds' exact greedy returns against the optimum (``None`` without a model).

    ``within_0.01`` counts the seeds whose gap is at most 0.01, ``within_1%`` those within
    1% of the optimum's magnitude (both as the issue's acceptance states them).
    """
    exact = [result["exact"] for result in results if "exact" in result]
    if not exact:
        return None
    optimum = exact[0]["optimum"]["return"]
    greedy = np.array([item["greedy"]["return"] for item in exact])
    gaps = optimum - greedy
    tolerance = 1e-9 * max(1.0, abs(optimum))  # the same value, up to rounding
    return {
        "note": exact[0]["note"],
        "optimum": optimum,
        "greedy_median": float(np.median(greedy)),
        "greedy_min": float(np.min(greedy)),
        "gap_max": float(np.max(gaps)),
        "within_0.01": int(np.sum(gaps <= 0.01 + tolerance)),
        "within_1%": int(np.sum(gaps <= 0.01 * abs(optimum) + tolerance)),
        "optimal": int(np.sum(gaps <= tolerance)),
        "seeds": len(exact),
    }


def evaluate_seeds(
    parent: Path,
    *,
    episodes: int | None = None,
    seed: int | None = None,
    workers: int | None = None,
    physics: dict[str, Any] | None = None,
    max_steps: int | None = None,
) -> dict[str, Any]:
    """Evaluate every finished seed of a multi-seed run in ``gymnasium.make``, in parallel.

    ``physics`` and ``max_steps`` play under other conditions (see ``under_conditions``).

    Returns:
        ``runs`` (one ``eval --json`` object per finished seed, with ``run_seed`` and
        ``path``), ``successes`` (means at or above the threshold), ``reward_threshold``,
        ``episodes``, the ``mean`` and ``min`` of the seeds' means, ``seeds`` (how many
        the run has), the seed directories left out (``missing``: absent, ``unfinished``:
        interrupted or not started) and ``note``, a line naming them (None if none).

    Raises:
        RunError: a finished seed's directory is damaged, or no seed has finished.
    """
    status = seed_status(parent)
    if not status.finished:
        raise RunError(f"{parent}: none of its seed runs has finished; {status.note(parent)}")
    paths = [str(path) for _, path in status.finished]
    # Loading every seed first refuses a damaged one before any work starts.
    for path in paths:
        rundir.load_run(path)
    workers = workers or default_workers(len(paths))
    jobs = [(path, episodes, seed, physics, max_steps) for path in paths]
    results = map_jobs(_evaluate_one, jobs, workers)
    from cartpole_q.envs.gym import inspect_env
    from cartpole_q.evaluation import under_conditions

    first = rundir.load_run(paths[0])
    reward_threshold = first.summary.get("reward_threshold")
    if physics or max_steps is not None:  # the horizon may scale CartPole's threshold
        conditions = under_conditions(first.config, physics, max_steps)
        reward_threshold = inspect_env(conditions).reward_threshold
    means = [result["mean"] for result in results]
    exact = exact_summary(results)
    return {
        **({"exact": exact} if exact else {}),
        "runs": results,
        "successes": sum(
            1 for m in means if reward_threshold is not None and m >= reward_threshold
        ),
        "reward_threshold": reward_threshold,
        "episodes": results[0]["episodes"],
        "mean": float(np.mean(means)),
        "min": float(np.min(means)),
        "seeds": len(status.finished) + len(status.missing) + len(status.unfinished),
        "missing": [path.name for _, path in status.missing],
        "unfinished": [path.name for _, path in status.unfinished],
        "note": status.note(parent),
    }
