"""Whole-process wall time of the commands a user runs, in a fresh interpreter each time.

    python benchmarks/wall_clock.py [--repeats 5] [--seeds 0-99]

Rows: `cartpole-q --help`; `cartpole-q train` on the default config with a cold numba
cache (compiling) and a warm one (loading it), beside the floor that imports alone set
(measured in the same run); `cartpole-q train --seeds` on all cores.
Each figure is the median of --repeats runs (one run for the cold and many-seed rows).
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


def main() -> None:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--seeds", default="0-99")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as scratch:
        root = Path(scratch)
        cold_env = {**os.environ, "NUMBA_CACHE_DIR": str(root / "cold-cache")}
        rows = [
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
    for name, seconds in rows:
        print(f"{name:45s} {seconds:7.2f} s")


if __name__ == "__main__":
    main()
