"""Benchmark: the warm-up (SPEC §4c) and bank (SPEC §4d) model families.

Prints, on the simulator's truth (fixed seeds):

* ``warmup`` — fit time and drift removed at a start temperature left out of the
  fit (scenario ``mems-warmup``), against the number of repeats per start
  temperature (the mems-gyro's flicker noise limits one repeat); predict and
  stream throughput [samples/s];
* ``bank`` — fit time on the ``accel-full-range`` runs (18 h at 1 Hz each),
  right-curve rate and worst RMS error on held-out power-ons, predict and stream
  throughput.

    .venv/bin/python benchmarks/bench_models_warmup_bank.py [--fit-runs 6] [--held-out 15]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from thermocal.models.bank import BankModel
from thermocal.models.rundata import RunData
from thermocal.models.warmup import WarmupModel
from thermocal.simulate import SCENARIOS


def mems_runs(seed: int) -> list[tuple[RunData, str, np.ndarray]]:
    out = []
    for rec, truth in SCENARIOS["mems-warmup"](seed):
        run = RunData.from_recording(rec, "gyro", ["T1"], known_input=truth["input"])
        out.append((run, str(truth["label"]), rec.column("truth_bias")))
    return out


def bench_warmup(held_out: str = "T+20") -> None:
    test_run, _, drift = next(x for x in mems_runs(100) if x[1] == held_out)
    print(f"warmup (mems-warmup, start temperature {held_out} left out, order 2, t0_order 2)")
    print("  repeats  fit runs  fit [s]  drift removed [%]")
    for repeats in (1, 2, 4, 8, 16):
        runs = [r for s in range(repeats) for r, lab, _ in mems_runs(s) if lab != held_out]
        t0 = time.perf_counter()
        model = WarmupModel(order=2, t0_order=2, start_window_s=0.5).fit(runs)
        fit_s = time.perf_counter() - t0
        left = drift - model.predict(test_run)
        removed = 100.0 * (1.0 - np.std(left) / np.std(drift))
        print(f"  {repeats:7d}  {len(runs):8d}  {fit_s:7.3f}  {removed:17.1f}")
    n = test_run.n_samples
    t0 = time.perf_counter()
    for _ in range(20):
        model.predict(test_run)
    pred_rate = 20 * n / (time.perf_counter() - t0)
    st = model.stream(0.1)
    t0 = time.perf_counter()
    for t, row in zip(test_run.time_s, test_run.temps_c, strict=True):
        st.update(float(t), row)
    stream_rate = n / (time.perf_counter() - t0)
    print(f"  predict {pred_rate:.3g} samples/s, stream {stream_rate:.3g} samples/s")


def bench_bank(fit_runs: int, held_out: int) -> None:
    fit = SCENARIOS["accel-full-range"](0, runs=fit_runs)
    runs = [RunData.from_recording(r, "accel", ["T1"], known_input=t["input_mg"]) for r, t in fit]
    t0 = time.perf_counter()
    model = BankModel().fit(runs)
    fit_s = time.perf_counter() - t0
    n_samples = sum(r.n_samples for r in runs)
    curve_of = [fit[g[0]][1]["curve"] for g in model.groups_]
    held = SCENARIOS["accel-full-range"](1, runs=held_out)
    stages = {s["label"]: s["start_s"] for s in held[0][1]["stages"]}
    right, total, worst, margins = 0, 0, 0.0, []
    pred_s, pred_n = 0.0, 0
    for rec, truth in held:
        run = RunData.from_recording(rec, "accel", ["T1"], known_input=truth["input_mg"])
        noise_free = rec.column("truth_rate") - truth["input_mg"]
        for start in (0.0, stages["soak-low"], stages["soak-high"]):
            keep = run.time_s >= start
            r = RunData(
                run.time_s[keep],
                run.temps_c[keep],
                None if run.signal is None else run.signal[keep],
                run.temp_names,
                known_input=run.known_input,
            )
            t0 = time.perf_counter()
            pred = model.predict(r)
            pred_s += time.perf_counter() - t0
            pred_n += r.n_samples
            total += 1
            right += curve_of[model.selection_.index] == truth["curve"]
            margins.append(model.selection_.margin)
            worst = max(worst, float(np.sqrt(np.mean((noise_free[keep] - pred) ** 2))))
    st = model.stream(1.0)
    r = runs[0]
    assert r.signal is not None
    m = 20000
    t0 = time.perf_counter()
    for t, row, y in zip(r.time_s[:m], r.temps_c[:m], r.target()[:m], strict=True):
        st.update(float(t), row, float(y))
    stream_rate = m / (time.perf_counter() - t0)
    print(
        f"bank (accel-full-range): fit {fit_runs} runs × {runs[0].n_samples} samples "
        f"({n_samples} samples) in {fit_s:.2f} s → {model.n_models} models, groups {model.groups_}"
    )
    print(
        f"  held-out power-ons: {right}/{total} right curve ({100 * right / total:.1f} %), "
        f"worst RMS error {worst:.4f} mg, smallest margin {min(margins):.3f} mg"
    )
    print(f"  predict {pred_n / pred_s:.3g} samples/s, stream {stream_rate:.3g} samples/s")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--fit-runs", type=int, default=6)
    ap.add_argument("--held-out", type=int, default=15)
    args = ap.parse_args(argv)
    bench_warmup()
    bench_bank(args.fit_runs, args.held_out)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
