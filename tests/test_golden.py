"""Results never change by accident: hashes of tables and metrics recorded from earlier code.

The hashes in ``tests/data/golden_hashes.json`` were computed before the package was
restructured; a refactoring, a new engine or a faster loop must reproduce them byte for
byte on both engines.
"""

from __future__ import annotations

import hashlib
import io
import json
from pathlib import Path

import numpy as np
import pytest

from cartpole_q.config import load_config
from cartpole_q.store.rundir import metrics_csv
from cartpole_q.training import train
from tests.conftest import CONFIGS

GOLDEN = json.loads((Path(__file__).parent / "data" / "golden_hashes.json").read_text())


def _sha256(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


@pytest.mark.parametrize("engine", ["numba", "gymnasium"])
@pytest.mark.parametrize("key", sorted(GOLDEN))
def test_results_equal_the_recorded_ones(key: str, engine: str) -> None:
    name, seed = key.split("/")
    path = None if name == "default" else CONFIGS / f"{name}.yaml"
    result = train(load_config(path, {"seed": int(seed), "engine": engine}), final_eval=False)
    buffer = io.BytesIO()
    np.save(buffer, result.q_table, allow_pickle=False)
    assert _sha256(buffer.getvalue()) == GOLDEN[key]["q_table.npy"]
    assert _sha256(metrics_csv(result.metrics).encode()) == GOLDEN[key]["metrics.csv"]
