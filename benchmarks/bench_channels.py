"""Benchmark: six channels sharing one design against one channel (issue 15).

Target: fitting six channels on 10⁷ samples each, and compensating a file holding six
channels, take at most 2× the time of one channel.  Prints the figures; the numbers go into
benchmarks/RESULTS.md.

Usage::

    .venv/bin/python benchmarks/bench_channels.py [--n 10000000] [--skip-file]

Data: :func:`bench_fit.make_data` (10⁷ samples at 1 s, four lagged temperature sensors,
seed000-shaped truth) and five more channels on the same temperatures with other
coefficients and noise.  Fit: the 37-term ``poly`` (seed000) — one channel by
``PolyModel.fit``, six by :func:`thermocal.models.poly_fit.fit_shared`, and six one after the
other (what a fit per channel costs).  File: a Parquet file with the time, the four
temperatures and six signals; ``compensate_channels`` Parquet → Parquet with one channel
and with six.
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np
import pandas as pd

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_fit import make_data
from thermocal.models.poly import PolyModel
from thermocal.models.poly_fit import fit_shared
from thermocal.models.rundata import RunData
from thermocal.pipeline.compensate import compensate_channels
from thermocal.readers.options import ReadOptions

NAMES = ("g1", "g2", "g3", "g4", "g5", "g6")


def channels(run: RunData) -> list[RunData]:
    """Six channels on one run's temperatures: the first is ``run``; the others weigh the
    sensors differently, with their own noise."""
    rng = np.random.default_rng(7)
    out = [run]
    for j in range(1, len(NAMES)):
        assert run.signal is not None
        y = (0.3 + 0.2 * j) * run.signal + 0.01 * j * run.temps_c[:, j % 4]
        y += 0.01 * rng.standard_normal(run.n_samples)
        out.append(dataclasses.replace(run, signal=y))
    return out


def timed(fn: object, repeat: int = 2) -> float:
    best = float("inf")
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()  # type: ignore[operator]
        best = min(best, time.perf_counter() - t0)
    return best


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--n", type=int, default=10_000_000)
    ap.add_argument("--skip-file", action="store_true")
    args = ap.parse_args(argv)
    warnings.simplefilter("ignore")
    run = make_data(args.n)
    chans = channels(run)

    t_one = timed(lambda: PolyModel().fit([run]))
    t_six = timed(lambda: fit_shared([PolyModel() for _ in chans], [[c] for c in chans]))
    t_seq = timed(lambda: [PolyModel().fit([c]) for c in chans], repeat=1)
    print(f"samples per channel            {args.n:,}")
    print(f"load average (1 min)           {os.getloadavg()[0]:.2f} on {os.cpu_count()} CPUs")
    print(f"fit, one channel               {t_one:.2f} s")
    print(f"fit, six channels shared       {t_six:.2f} s   ratio {t_six / t_one:.2f} (target ≤ 2)")
    print(f"fit, six channels one by one   {t_seq:.2f} s   ratio {t_seq / t_one:.2f}")
    ok = t_six <= 2.0 * t_one

    if not args.skip_file:
        models = [PolyModel() for _ in chans]
        fit_shared(models, [[c] for c in chans])
        for name, mdl in zip(NAMES, models, strict=True):
            mdl.signal_name, mdl.signal_unit = name, "deg/h"
        with tempfile.TemporaryDirectory() as tmp:
            src = Path(tmp) / "in.parquet"
            cols = {"time": run.time_s}
            cols.update({f"T{k + 1}": run.temps_c[:, k] for k in range(4)})
            cols.update({n: c.signal for n, c in zip(NAMES, chans, strict=True)})
            pd.DataFrame(cols).to_parquet(src)
            del cols
            out = Path(tmp) / "out.parquet"
            one = [(NAMES[0], models[0])]
            six = list(zip(NAMES, models, strict=True))
            f_one = timed(
                lambda: compensate_channels(one, src, out, ReadOptions(signal_unit="deg/h")), 2
            )
            f_six = timed(
                lambda: compensate_channels(six, src, out, ReadOptions(signal_unit="deg/h")), 2
            )
            print(f"compensate file, one channel   {f_one:.2f} s")
            print(f"compensate file, six channels  {f_six:.2f} s   ratio {f_six / f_one:.2f} "
                  "(target ≤ 2)")  # fmt: skip
            ok = ok and f_six <= 2.0 * f_one
    print("PASS" if ok else "FAIL")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
