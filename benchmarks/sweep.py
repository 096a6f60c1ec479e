"""A sweep's throughput against the compute-only bound, measured in the same run.

    python benchmarks/sweep.py [--points 100] [--seeds 0-99] [--workers N] [--repeats 1]

The sweep: the default config with `agent.gamma` at --points values from 0.99 to 1.0,
each on every seed of --seeds (100 x 100 = 10,000 runs, each trained and evaluated as
`cartpole-q train` does). It runs as the command a user types, `cartpole-q sweep FILE
--yes -q`, in a fresh process: the wall time is the whole command (start-up, worker
processes, files, points.csv and sweep.png included).

The bound: the same runs in one process with no files, `training.train` in a loop (on
every tenth point, all seeds, to keep the benchmark short), times the workers: what the
sweep would reach if running runs cost nothing but their compute. Both figures come from
this run, on this machine; with --repeats the median is quoted.
"""

from __future__ import annotations

import argparse
import csv
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import yaml

from cartpole_q.config import load_config, parse_seeds
from cartpole_q.engines.plan import plan_run
from cartpole_q.envs.gym import inspect_env
from cartpole_q.training import train


def sweep_file(directory: Path, points: int, seeds: str) -> Path:
    """Write the benchmark's sweep file."""
    gammas = [float(g) for g in np.round(np.linspace(0.99, 1.0, points), 6)]
    path = directory / "bench.yaml"
    data = {"name": "bench", "seeds": seeds, "grid": {"agent.gamma": gammas}}
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def run_command(path: Path, out: Path, workers: int) -> float:
    """Wall seconds of `cartpole-q sweep` in a fresh process."""
    started = time.perf_counter()
    subprocess.run(
        [sys.executable, "-m", "cartpole_q", "sweep", str(path), "--out", str(out), "--yes",
         "-q", "--workers", str(workers)],
        check=True, stdout=subprocess.DEVNULL,
    )  # fmt: skip
    return time.perf_counter() - started


def bound(gammas: list[float], seeds: tuple[int, ...]) -> float:
    """Runs per second of the same runs in one process, no files (every tenth point)."""
    sample = gammas[:: max(1, len(gammas) // 10)]
    configs = [load_config(None, {"agent.gamma": gamma}) for gamma in sample]
    info = inspect_env(configs[0])
    plans = [plan_run(config, env_info=info) for config in configs]
    train(plans[0].for_seed(seeds[0]))  # load the compiled loop first
    started = time.perf_counter()
    for plan in plans:
        for seed in seeds:
            train(plan.for_seed(seed))
    return len(configs) * len(seeds) / (time.perf_counter() - started)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=int, default=100)
    parser.add_argument("--seeds", default="0-99")
    parser.add_argument("--workers", type=int, default=os.cpu_count() or 1)
    parser.add_argument("--repeats", type=int, default=1)
    args = parser.parse_args()
    seeds = parse_seeds(args.seeds)
    runs = args.points * len(seeds)
    with tempfile.TemporaryDirectory() as tmp:
        path = sweep_file(Path(tmp), args.points, args.seeds)
        gammas = yaml.safe_load(path.read_text())["grid"]["agent.gamma"]
        walls, bounds = [], []
        for repeat in range(args.repeats):
            out = Path(tmp) / f"out-{repeat}"
            walls.append(run_command(path, out, args.workers))
            with (out / "results.csv").open() as file:
                assert sum(1 for _ in csv.DictReader(file)) == runs
            bounds.append(bound(gammas, seeds))
    wall = statistics.median(walls)
    one_process = statistics.median(bounds)
    ideal = one_process * args.workers
    rate = runs / wall
    print(
        f"sweep: {args.points} points x {len(seeds)} seeds = {runs:,} runs, {args.workers} workers"
    )
    print(f"  whole command (cartpole-q sweep):   {wall:8.1f} s  {rate:8.1f} runs/s")
    print(f"  compute-only, one process, no files:          {one_process:8.1f} runs/s")
    print(f"  compute-only bound x {args.workers} workers:               {ideal:8.1f} runs/s")
    print(f"  sweep / bound:                               {rate / ideal:8.1%}")
    if args.repeats > 1:
        print(f"  (medians of {args.repeats}; walls {', '.join(f'{w:.1f}' for w in walls)} s)")


if __name__ == "__main__":
    main()
