"""Whole-process wall time of the commands a user runs, in a fresh interpreter each time.

    python benchmarks/wall_clock.py [--repeats 5] [--seeds 0-99] [--only eval [--run DIR]]

Rows: `cartpole-q --help`; `cartpole-q train` on the default config with a cold numba
cache (compiling) and a warm one (loading it), beside the floor that imports alone set
(measured in the same run); `cartpole-q train --seeds` on all cores; `cartpole-q eval` of
that multi-seed run (its eval.episodes, 100 per seed) in gymnasium.make and on the compiled
twin (`--engine numba`, warm cache), and their ratio, both measured in this run.
Each figure is the median of --repeats runs (one run for the cold and many-seed rows; the
gymnasium.make eval, tens of seconds, at most 3). `--only eval` measures the eval rows
alone, on the multi-seed run `--run DIR` (trained first when not given).
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path


def wall(args: list[str], env: dict[str, str] | None = None) -> float:
    """Seconds one `python -m cartpole_q ...` process takes, start to exit."""
    started = time.perf_counter()
    subprocess.run([sys.executable, "-m", "cartpole_q", *args], check=True, env=env,
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)  # fmt: skip
    return time.perf_counter() - started


def wall_python(code: str) -> float:
    """Seconds a fresh `python -c CODE` takes: the floor that imports alone set."""
    started = time.perf_counter()
    subprocess.run([sys.executable, "-c", code], check=True)
    return time.perf_counter() - started


IMPORT_FLOOR = "import numpy, numba, gymnasium"
IMPORT_FLOOR_PLOTTING = IMPORT_FLOOR + "; import matplotlib.figure, matplotlib.backends.backend_agg"


Row = tuple[str, float | None]
"""a row's name and seconds (``None``: the name says it all, e.g. a ratio)"""


def print_rows(rows: list[Row]) -> None:
    """One line per row, the seconds aligned."""
    for name, seconds in rows:
        print(name if seconds is None else f"{name:45s} {seconds:7.2f} s")


def eval_rows(run: Path, repeats: int) -> list[Row]:
    """`cartpole-q eval RUN` in gymnasium.make and on the twin, and how many times faster.

    The twin's play is loaded once first, so its row is the warm-cache figure; the two
    commands alternate, so that a change in the machine's load touches both alike.
    """
    wall(["eval", str(run), "--engine", "numba"])  # the greedy play into numba's cache
    real: list[float] = []
    twin: list[float] = []
    for repeat in range(repeats):
        if repeat < 3:
            real.append(wall(["eval", str(run)]))
        twin.append(wall(["eval", str(run), "--engine", "numba"]))
    gymnasium, numba = statistics.median(real), statistics.median(twin)
    return [
        (f"cartpole-q eval {run.name} (gymnasium.make)", gymnasium),
        (f"cartpole-q eval {run.name} --engine numba", numba),
        (f"  eval: the twin is {gymnasium / numba:.1f}x faster than gymnasium.make", None),
    ]


def main() -> None:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--seeds", default="0-99")
    parser.add_argument("--only", choices=["eval"], help="measure these rows alone")
    parser.add_argument("--run", type=Path, help="with --only eval: an existing multi-seed run")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as scratch:
        root = Path(scratch)
        if args.only == "eval":
            run = args.run
            if run is None:
                run = root / "seeds"
                wall(["train", "-q", "--seeds", args.seeds, "--out", str(run)])
            print_rows(eval_rows(run, args.repeats))
            return
        cold_env = {**os.environ, "NUMBA_CACHE_DIR": str(root / "cold-cache")}
        rows: list[Row] = [
            ("cartpole-q --help", statistics.median(wall(["--help"]) for _ in range(args.repeats))),
            (
                "cartpole-q train, cold numba cache",
                wall(["train", "-q", "--out", str(root / "cold")], cold_env),
            ),
        ]
        wall(["train", "-q", "--out", str(root / "warm-up")])  # fill the normal cache
        warm = [
            wall(["train", "-q", "--out", str(root / f"warm-{i}")]) for i in range(args.repeats)
        ]
        rows.append(("cartpole-q train, warm cache", statistics.median(warm)))
        rows.append(
            (
                "  import floor: numpy + numba + gymnasium",
                statistics.median(wall_python(IMPORT_FLOOR) for _ in range(args.repeats)),
            )
        )
        rows.append((
            "  import floor + matplotlib Figure, Agg",
            statistics.median(wall_python(IMPORT_FLOOR_PLOTTING) for _ in range(args.repeats)),
        ))  # fmt: skip
        rows.append((f"cartpole-q train --seeds {args.seeds} ({os.cpu_count()} cores)",
                     wall(["train", "-q", "--seeds", args.seeds, "--out", str(root / "seeds")])))  # fmt: skip
        rows.extend(eval_rows(root / "seeds", args.repeats))
    print_rows(rows)


if __name__ == "__main__":
    main()
