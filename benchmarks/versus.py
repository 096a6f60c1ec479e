"""This checkout against another one, side by side in one run: training throughput and start-up.

    python benchmarks/versus.py --baseline /path/to/other/checkout [--repeats 5] [--quick]
        [--skip-cold] [--algorithms A,B,... [--only-algorithms]]

The baseline is any checkout of cartpole-q (``git worktree add /tmp/base <commit>``). Each
figure is measured in a fresh interpreter per side, the two sides interleaved (A B A B ...),
and the median of ``--repeats`` is quoted with the ratio this / baseline, so that a noisy
machine's drift cancels out. Each side keeps its own numba cache directory.

Rows:
  numba, <algorithm>       env steps/s of the default config with each algorithm (design.md's
                           four, or --algorithms; both checkouts must have them)
  numba, <environment>     env steps/s of Q-learning on MountainCar-v0 and Acrobot-v1 twins
  gymnasium / blog loop    the gymnasium engine's rate over the blog tutorial's loop, measured
                           in the same interpreter (so the ratio is that side's own)
  train, warm              whole-process `cartpole-q train` of the default config, cache warm
  train, cold              the same with an empty numba cache (compilation included)
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
CHECKOUT = HERE.parent

MEASURE = r"""
import json, sys, time
sys.path.insert(0, {benchmarks!r})
from throughput import blog_loop, engine_rate, MOUNTAINCAR, ACROBOT
what, arg, episodes = sys.argv[1], sys.argv[2], int(sys.argv[3])
if what == "algorithm":
    engine_rate(None, "numba", 5, 0, algorithm=arg)
    steps, seconds = engine_rate(None, "numba", episodes, 0, algorithm=arg)
    print(json.dumps(steps / seconds))
elif what == "environment":
    config = {{"mountaincar": MOUNTAINCAR, "acrobot": ACROBOT}}[arg]
    engine_rate(config, "numba", 2, 0)
    steps, seconds = engine_rate(config, "numba", episodes, 0)
    print(json.dumps(steps / seconds))
else:
    engine_rate(None, "gymnasium", 2, 0)
    blog_steps, blog_seconds = blog_loop(episodes, 0)
    steps, seconds = engine_rate(None, "gymnasium", episodes, 0)
    print(json.dumps((steps / seconds) / (blog_steps / blog_seconds)))
"""


def side_env(checkout: Path, cache: Path) -> dict[str, str]:
    """The environment a side runs in: its checkout first on the path, its own cache."""
    return {
        **os.environ,
        "PYTHONPATH": str(checkout),
        "XDG_CACHE_HOME": str(cache),
        "PYTHONDONTWRITEBYTECODE": "1",
    }


def measure(checkout: Path, cache: Path, what: str, arg: str, episodes: int) -> float:
    """One figure, in a fresh interpreter on one side."""
    code = MEASURE.format(benchmarks=str(HERE))
    done = subprocess.run(
        [sys.executable, "-c", code, what, arg, str(episodes)],
        env=side_env(checkout, cache), capture_output=True, text=True, check=True,
    )  # fmt: skip
    return float(json.loads(done.stdout.strip().splitlines()[-1]))


def train_seconds(checkout: Path, cache: Path, out: Path) -> float:
    """Wall seconds of a whole `cartpole-q train` process."""
    started = time.perf_counter()
    subprocess.run(
        [sys.executable, "-m", "cartpole_q", "train", "--out", str(out), "-q"],
        env=side_env(checkout, cache), capture_output=True, check=True, cwd=out.parent,
    )  # fmt: skip
    return time.perf_counter() - started


def main() -> None:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--baseline", type=Path, required=True, help="another checkout")
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--quick", action="store_true", help="fewer episodes (a rough check)")
    parser.add_argument("--skip-cold", action="store_true", help="leave out the cold start")
    parser.add_argument(
        "--algorithms",
        default="q_learning,sarsa,expected_sarsa,double_q_learning",
        help="comma-separated agent.algorithm values to compare",
    )
    parser.add_argument("--only-algorithms", action="store_true", help="only the algorithms' rows")
    args = parser.parse_args()
    scale = 0.2 if args.quick else 1.0
    sides = {"this": CHECKOUT, "baseline": args.baseline.resolve()}
    work = Path(tempfile.mkdtemp(prefix="cartpole-q-versus-"))
    caches = {name: work / f"cache-{name}" for name in sides}
    for cache in caches.values():
        cache.mkdir()

    rows: list[tuple[str, str, str, int]] = [
        (f"numba, {name}", "algorithm", name, int(10_000 * scale))
        for name in args.algorithms.split(",")
    ]
    rows += (
        []
        if args.only_algorithms
        else [
            ("numba, MountainCar-v0", "environment", "mountaincar", int(5_000 * scale)),
            ("numba, Acrobot-v1", "environment", "acrobot", int(2_000 * scale)),
            ("gymnasium / blog loop", "versus_blog", "", max(20, int(400 * scale))),
        ]
    )
    print(
        f"{'figure (median of ' + str(args.repeats) + ')':34s} {'this':>14s} {'baseline':>14s} {'ratio':>7s}"
    )
    for label, what, arg, episodes in rows:
        figures: dict[str, list[float]] = {name: [] for name in sides}
        for _ in range(args.repeats):
            for name, checkout in sides.items():
                figures[name].append(measure(checkout, caches[name], what, arg, episodes))
        this, base = (statistics.median(figures[name]) for name in sides)
        fmt = "{:14.2f}" if what == "versus_blog" else "{:14,.0f}"
        print(f"{label:34s} {fmt.format(this)} {fmt.format(base)} {this / base:7.2f}")

    timings = [("train, warm (s)", False)] + ([] if args.skip_cold else [("train, cold (s)", True)])
    if args.only_algorithms:
        timings = []
    for label, cold in timings:
        seconds: dict[str, list[float]] = {name: [] for name in sides}
        for repeat in range(args.repeats + (0 if cold else 1)):
            for name, checkout in sides.items():
                cache = caches[name] if not cold else Path(tempfile.mkdtemp(dir=work))
                out = work / f"run-{name}-{label[7:11]}-{repeat}"
                value = train_seconds(checkout, cache, out)
                if cold or repeat:  # the first warm run fills the cache
                    seconds[name].append(value)
        this, base = (statistics.median(seconds[name]) for name in sides)
        print(f"{label:34s} {this:14.2f} {base:14.2f} {this / base:7.2f}")


if __name__ == "__main__":
    main()
