"""Compile cost against speed: the hooks inlined by numba (today) or called as compiled functions.

    python benchmarks/compile_designs.py [--algorithms q_learning,sarsa,...] [--repeats 3]

For each algorithm, on CartPole's twin: the seconds a cold process spends compiling (and
running two episodes of) the pair's training loop after a first pair has warmed numba up,
and the trained env steps per second (median of ``--repeats`` runs of 3,000 episodes),
once with today's design (every hook and helper inlined into the loop by numba,
``inline="always"``) and once with the hooks and helpers compiled on their own and called
(numba links them; nothing is inlined). Each side runs in a fresh interpreter with its own
empty numba cache, the two sides interleaved; results are byte-identical (a digest of the
table is printed).

The question it answers (issue 30): whether the compilations could add (each algorithm's
hooks compiled once, for every world) instead of multiply (each pair compiled whole). The
linked design compiles a pair in about half the time but trains at about half the speed,
because numba inlines nothing it links: the per-step calls stay calls.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent

MEASURE = r"""
import hashlib, json, sys, time
import numpy as np
if sys.argv[1] == "linked":  # the hooks and helpers compiled on their own, not inlined
    import cartpole_q.engines.compile as compile_module
    from numba import njit

    def linked(*args, **kwargs):
        kwargs.pop("inline", None)
        return njit(*args, **kwargs)

    compile_module.njit = linked
sys.path.insert(0, {benchmarks!r})
from throughput import engine_rate
from cartpole_q.config import load_config
from cartpole_q.training import train

warm, algorithm, repeats = sys.argv[2], sys.argv[3], int(sys.argv[4])
def two_episodes(name):
    config = load_config(overrides={{"agent.algorithm": name, "train.episodes": 2,
                                     "eval.episodes": 1, "agent.epsilon": 0.1}})
    started = time.perf_counter()
    train(config, final_eval=False)
    return time.perf_counter() - started
two_episodes(warm)  # numba's own first-use costs, paid once per process
compile_seconds = two_episodes(algorithm)
rates = []
for seed in range(repeats):
    steps, seconds = engine_rate(None, "numba", 3000, seed, algorithm=algorithm)
    rates.append(steps / seconds)
table = train(load_config(overrides={{"agent.algorithm": algorithm, "train.episodes": 300}}),
              final_eval=False).q_table
digest = hashlib.sha1(np.ascontiguousarray(table).tobytes()).hexdigest()[:12]
print(json.dumps({{"compile": compile_seconds, "rate": sorted(rates)[len(rates) // 2],
                  "digest": digest}}))
"""


def measure(design: str, warm: str, algorithm: str, repeats: int) -> dict[str, float | str]:
    """One fresh interpreter's figures for one design and algorithm, with an empty cache."""
    with tempfile.TemporaryDirectory() as cache:
        done = subprocess.run(
            [sys.executable, "-c", MEASURE.format(benchmarks=str(HERE)), design, warm,
             algorithm, str(repeats)],
            capture_output=True, text=True, check=True, env={"XDG_CACHE_HOME": cache,
            "PATH": "/usr/bin:/bin", "PYTHONDONTWRITEBYTECODE": "1"},
        )  # fmt: skip
    figures: dict[str, float | str] = json.loads(done.stdout.strip().splitlines()[-1])
    return figures


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--algorithms", default="sarsa,expected_sarsa,n_step_tree_backup,sarsa_lambda"
    )
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    print(f"{'algorithm':<22}{'design':<9}{'compile s':>10}{'Msteps/s':>10}  table digest")
    for algorithm in args.algorithms.split(","):
        warm = "q_learning" if algorithm != "q_learning" else "sarsa"
        rows = {design: measure(design, warm, algorithm, args.repeats)
                for design in ("inlined", "linked")}  # fmt: skip
        for design, row in rows.items():
            print(f"{algorithm:<22}{design:<9}{float(row['compile']):>10.2f}"
                  f"{float(row['rate']) / 1e6:>10.2f}  {row['digest']}")  # fmt: skip
        inlined, linked = rows["inlined"], rows["linked"]
        print(f"{'':<22}{'ratio':<9}{float(linked['compile']) / float(inlined['compile']):>10.2f}"
              f"{float(linked['rate']) / float(inlined['rate']):>10.2f}  "
              f"{'identical' if linked['digest'] == inlined['digest'] else 'DIFFERENT'}")  # fmt: skip
    print("(ratio: linked / inlined; compile: the second pair of a cold process)")


if __name__ == "__main__":
    main()
