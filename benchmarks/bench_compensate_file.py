"""Speed of ``compensate_file`` alone (Parquet → Parquet, chunks of 500 k rows), for A/B runs of
two trees side by side.

The file part of ``bench_compensate.py``: the 37-term polynomial model of the ``rlg-modelling``
scenario, its run tiled ten times (2.05 M samples, four temperatures), best of 3.  The module
that holds ``compensate_file`` is the first argument, so that a tree from before a move can be
timed by the same script (``thermocal.compensate.files`` before issue 40's restructuring,
``thermocal.pipeline.compensate`` after).

Run: ``PYTHONPATH=TREE/src .venv/bin/python benchmarks/bench_compensate_file.py MODULE``;
prints M samples/s.
"""

from __future__ import annotations

import importlib
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np
import pandas as pd

from thermocal.models.registry import make_model
from thermocal.simulate import SCENARIOS

TEMPS = ["T1", "T2", "T3", "T4"]


def main() -> None:
    warnings.simplefilter("ignore")
    try:  # the tree before issue 40 kept RunData in models.base
        rundata = importlib.import_module("thermocal.models.rundata")
    except ImportError:
        rundata = importlib.import_module("thermocal.models.base")
    module = importlib.import_module(sys.argv[1])
    rec, _ = SCENARIOS["rlg-modelling"](1)[0]
    fit_run = rundata.RunData.from_recording(rec, "gyro", TEMPS)
    model = make_model("poly").fit([fit_run])
    reps = 10
    n = fit_run.n_samples * reps
    t = np.arange(n, dtype=np.float64)
    temps = np.tile(fit_run.temps_c, (reps, 1))
    signal = np.tile(fit_run.signal, reps)
    with tempfile.TemporaryDirectory() as tmp:
        src = Path(tmp) / "in.parquet"
        columns = {"time": t, "gyro": signal, **{c: temps[:, i] for i, c in enumerate(TEMPS)}}
        pd.DataFrame(columns).to_parquet(src)
        model.signal_name = "gyro"
        best = float("inf")
        for _ in range(3):
            t0 = time.perf_counter()
            module.compensate_file(model, src, Path(tmp) / "out.parquet", chunk_rows=500_000)
            best = min(best, time.perf_counter() - t0)
    print(f"{n / best / 1e6:.3f}")


if __name__ == "__main__":
    main()
