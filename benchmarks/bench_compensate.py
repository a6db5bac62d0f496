"""Speed of compensation with the 37-term polynomial model (issue 6), and with the
piecewise-linear model (SPEC §4b) for comparison.

* batch: ``compensate_run`` (``model.predict`` + subtraction) in memory;
* file: ``compensate_file`` Parquet → Parquet in chunks;
* Python streaming: ``StreamingCompensator.update`` sample by sample, and
  ``update_block`` on blocks of 100 and 1000 samples;
* generated C (double and float): ``<p>_update`` in a loop over in-memory samples
  (cc -O2 -std=c99), timed with ``clock()``;
* piecewise (``fog-slow``, 3 segments): batch predict, per-sample streaming, C double.

Targets: batch ≥ 20 M samples/s, Python streaming ≥ 100 k samples/s, C ≥ 10 M samples/s.

Run: ``.venv/bin/python benchmarks/bench_compensate.py``
"""

from __future__ import annotations

import subprocess
import tempfile
import time
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from thermocal.compensate.kernels import StreamingCompensator, compensate_run
from thermocal.export.c import exercise_inputs, find_compiler, generate_c
from thermocal.models.registry import make_model
from thermocal.models.rundata import RunData
from thermocal.pipeline.compensate import compensate_file
from thermocal.pipeline.model_file import load_model_dict, save_model
from thermocal.simulate import SCENARIOS

TEMPS = ["T1", "T2", "T3", "T4"]

BENCH_MAIN = r"""
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
#include "%(p)s.h"
int main(int argc, char **argv)
{
    FILE *in = fopen(argv[1], "rb");
    long n, i, rep, reps = atol(argv[2]);
    double *rec, sink = 0.0, secs;
    %(p)s_real temps[%(P)s_N_TEMPS];
    %(p)s_state st;
    clock_t c0;
    int j;
    if (fread(&n, sizeof n, 1, in) != 1) return 2;
    rec = malloc(sizeof(double) * (size_t)n * (%(P)s_N_TEMPS + 2));
    if (fread(rec, sizeof(double), (size_t)n * (%(P)s_N_TEMPS + 2), in)
        != (size_t)n * (%(P)s_N_TEMPS + 2)) return 3;
    c0 = clock();
    for (rep = 0; rep < reps; ++rep) {
        %(p)s_init(&st, 1.0);
        for (i = 0; i < n; ++i) {
            const double *r = rec + i * (%(P)s_N_TEMPS + 2);
            for (j = 0; j < %(P)s_N_TEMPS; ++j) temps[j] = (%(p)s_real)r[1 + j];
            sink += (double)%(p)s_update(&st, r[0] + (double)rep * 1e7, temps,
                                        (%(p)s_real)r[%(P)s_N_TEMPS + 1]);
        }
    }
    secs = (double)(clock() - c0) / CLOCKS_PER_SEC;
    printf("%%.6g %%.17g\n", (double)n * (double)reps / secs, sink);
    return 0;
}
"""


def best_rate(fn, n: int, repeat: int = 3) -> float:  # type: ignore[no-untyped-def]
    best = float("inf")
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return n / best


def main() -> None:
    warnings.simplefilter("ignore")
    rec, _ = SCENARIOS["rlg-modelling"](1)[0]
    fit_run = RunData.from_recording(rec, "gyro", TEMPS)
    t0 = time.perf_counter()
    model = make_model("poly").fit([fit_run])
    print(f"poly fit: {len(model.coefficients())} coefficients, {time.perf_counter() - t0:.2f} s")

    # batch: tile the modelling run to 2.05 M samples (1 Hz, contiguous)
    reps = 10
    n = fit_run.n_samples * reps
    t = np.arange(n, dtype=np.float64)
    T = np.tile(fit_run.temps_c, (reps, 1))
    assert fit_run.signal is not None
    f = np.tile(fit_run.signal, reps)
    big = RunData(time_s=t, temps_c=T, signal=f, temp_names=tuple(TEMPS))
    rate = best_rate(lambda: compensate_run(model, big), n)
    print(f"batch compensate_run (37 terms, {n} samples): {rate / 1e6:.2f} M samples/s")
    rate_p = best_rate(lambda: model.predict(big), n)
    print(f"  of which model.predict: {rate_p / 1e6:.2f} M samples/s")

    with tempfile.TemporaryDirectory() as tmp:
        src = Path(tmp) / "in.parquet"
        pd.DataFrame(
            {"time": t, "gyro": f, **{c: T[:, i] for i, c in enumerate(TEMPS)}}
        ).to_parquet(src)
        model.signal_name = "gyro"
        rate_f = best_rate(
            lambda: compensate_file(model, src, Path(tmp) / "out.parquet", chunk_rows=500_000),
            n,
            repeat=1,
        )
        print(
            f"file compensate_file Parquet→Parquet (chunks of 500k): {rate_f / 1e6:.2f} M samples/s"
        )

        # Python streaming
        m_s = 20_000
        sc = StreamingCompensator(model, 1.0)

        def per_sample() -> None:
            sc.reset()
            for i in range(m_s):
                sc.update(t[i], T[i], f[i])

        rate_s = best_rate(per_sample, m_s, repeat=1)
        print(f"Python StreamingCompensator.update (per sample): {rate_s / 1e3:.1f} k samples/s")
        m_b = 200_000
        for block in (100, 1000):

            def per_block(block: int = block) -> None:
                sc.reset()
                for a in range(0, m_b, block):
                    sc.update_block(t[a : a + block], T[a : a + block], f[a : a + block])

            rate_b = best_rate(per_block, m_b, repeat=1)
            print(
                f"Python StreamingCompensator.update_block (blocks of {block}): "
                f"{rate_b / 1e3:.1f} k samples/s"
            )

        # generated C
        cc = find_compiler()
        if cc is None:
            print("no C compiler: C benchmark skipped")
            return
        path = Path(tmp) / "rlg_poly.json"
        save_model(model, path)
        d = load_model_dict(path)
        for real in ("double", "float"):
            rate_c = c_rate(d, "rlg_poly", real, Path(tmp) / real, cc)
            print(f"generated C ({real}, cc -O2): {rate_c / 1e6:.1f} M samples/s")

        # piecewise-linear model (memoryless): for comparison
        pw_rec, _ = SCENARIOS["fog-slow"](1)[0]
        pw_run = RunData.from_recording(pw_rec, "gyro", ["T1"])
        pw = make_model("piecewise").fit([pw_run])
        pw.signal_name = "gyro"
        n_pw = 2_000_000
        pw_t = np.arange(n_pw, dtype=np.float64)
        pw_T = np.resize(pw_run.temps_c[:, 0], n_pw)[:, None]
        pw_f = np.resize(pw_run.target(), n_pw)
        pw_big = RunData(time_s=pw_t, temps_c=pw_T, signal=pw_f, temp_names=("T1",))
        rate = best_rate(lambda: compensate_run(pw, pw_big), n_pw)
        print(f"piecewise batch compensate_run ({n_pw} samples): {rate / 1e6:.1f} M samples/s")
        sc_pw = StreamingCompensator(pw, 1.0)

        def pw_per_sample() -> None:
            sc_pw.reset()
            for i in range(m_s):
                sc_pw.update(pw_t[i], pw_T[i], pw_f[i])

        rate_s = best_rate(pw_per_sample, m_s, repeat=1)
        print(f"piecewise StreamingCompensator.update (per sample): {rate_s / 1e3:.1f} k samples/s")
        pw_path = Path(tmp) / "fog_pw.json"
        save_model(pw, pw_path)
        rate_c = c_rate(load_model_dict(pw_path), "fog_pw", "double", Path(tmp) / "pw", cc)
        print(f"piecewise generated C (double, cc -O2): {rate_c / 1e6:.1f} M samples/s")


def c_rate(d: dict[str, Any], prefix: str, real: str, cdir: Path, cc: str) -> float:
    """Samples/s of the generated ``<p>_update`` on 10⁶ samples of :func:`exercise_inputs`
    (with a gap), 10 repetitions."""
    tx, Tx, fx = exercise_inputs(d, 1_000_000, 1.0, gap_at=0.5)
    cdir.mkdir(parents=True, exist_ok=True)
    fin = cdir / "x.bin"
    with open(fin, "wb") as fh:
        fh.write(np.int64(tx.size).tobytes())
        fh.write(np.ascontiguousarray(np.column_stack([tx, Tx, fx])).tobytes())
    ex = generate_c(d, prefix=prefix, real=real)
    ex.write(cdir)
    (cdir / "bench.c").write_text(BENCH_MAIN % {"p": ex.prefix, "P": ex.prefix.upper()})
    exe = cdir / "bench"
    subprocess.run(
        [cc, "-O2", "-std=c99", "-o", str(exe), str(cdir / ex.source_name),
         str(cdir / "bench.c")],
        check=True,
    )  # fmt: skip
    out = subprocess.run([str(exe), str(fin), "10"], capture_output=True, text=True, check=True)
    return float(out.stdout.split()[0])


if __name__ == "__main__":
    main()
