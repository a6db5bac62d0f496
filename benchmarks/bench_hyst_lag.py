"""The hyst family's lag on an irregular clock: ``first_order_lag`` and the whole lag search
(``HystModel(order=2).fit``) of this tree against a tree given by ``--before`` (e.g. main
before the blocked scan: ``git archive main src | tar -x -C /tmp/before``), side by side in
one run, interleaved, each in its own process, on one simulated record: ``--rows`` samples
of a 0.1 s clock jittered by ±20 ms, a sine of ±20 °C over the record, a signal of
0.3 °/h/°C and 0.01 °/h/°C² in the lagged temperature (τ = 300 s) plus 0.5 °/h of noise.

Per tree and repeat: the lag at τ = 300 s (CPU time best of 5 in-process, then the same in
wall time), the search's CPU time (one fit), τ̂ and σ_τ.  The largest difference between the
two trees' lags relative to the record's largest |z| is printed with the ratios.

Run: ``PYTHONPATH=src .venv/bin/python benchmarks/bench_hyst_lag.py --before /tmp/before/src
[--rows 1000000] [--repeat 3]``.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

CHILD = r"""
import json, sys, time, warnings
import numpy as np
from thermocal.models import RunData
from thermocal.models.hyst import HystModel
from thermocal.models.hyst_lag import first_order_lag
warnings.simplefilter("ignore")
d = np.load(sys.argv[1])
t, x, y = d["t"], d["x"], d["y"]
cpu, wall = [], []
for _ in range(5):
    c0, w0 = time.process_time(), time.perf_counter()
    z = first_order_lag(t, x, 300.0)
    cpu.append(time.process_time() - c0)
    wall.append(time.perf_counter() - w0)
np.save(sys.argv[2], z)
run = RunData(t, x[:, None], y, ("T1",))
c0 = time.process_time()
m = HystModel(order=2).fit([run])
search = time.process_time() - c0
print(json.dumps({"lag_cpu": min(cpu), "lag_wall": min(wall), "search_cpu": search,
                  "tau": m.tau_, "sigma": m.tau_stderr_}))
"""


def _record(n: int) -> dict[str, np.ndarray]:
    """The jittered record (module docstring), its lag computed sample by sample."""
    rng = np.random.default_rng(0)
    t = np.arange(n) * 0.1 + rng.uniform(-0.02, 0.02, n)
    x = 25.0 + 20.0 * np.sin(2.0 * np.pi * t / t[-1])
    z = x.copy()  # the die: the loop, once (the truth of the signal)
    h = np.diff(t) / 300.0
    e, c = np.exp(-h).tolist(), (-np.expm1(-h) / h).tolist()
    xs, zk = x.tolist(), float(x[0])
    for k in range(1, n):
        zk = e[k - 1] * zk + (1.0 - c[k - 1]) * xs[k] + (c[k - 1] - e[k - 1]) * xs[k - 1]
        z[k] = zk
    u = z - 25.0
    y = 0.3 * u + 0.01 * u**2 + 0.5 * rng.standard_normal(n)
    return {"t": t, "x": x, "y": y}


def _child(src: str, data: Path, out: Path) -> dict[str, float]:
    env = {**os.environ, "PYTHONPATH": src}
    res = subprocess.run([sys.executable, "-c", CHILD, str(data), str(out)], env=env,
                         capture_output=True, text=True, check=True)  # fmt: skip
    return dict(json.loads(res.stdout))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--before", required=True, help="the before tree's src directory")
    ap.add_argument("--rows", type=int, default=1_000_000)
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    here = str(Path(__file__).resolve().parent.parent / "src")
    trees = {"before": args.before, "after": here}
    with tempfile.TemporaryDirectory() as tmp:
        data = Path(tmp) / "rec.npz"
        np.savez(data, **_record(args.rows))
        best: dict[str, dict[str, float]] = {}
        for _ in range(args.repeat):
            for name, src in trees.items():
                r = _child(src, data, Path(tmp) / f"{name}.npy")
                b = best.setdefault(name, r)
                for k in ("lag_cpu", "lag_wall", "search_cpu"):
                    b[k] = min(b[k], r[k])
        zb, za = np.load(Path(tmp) / "before.npy"), np.load(Path(tmp) / "after.npy")
    for name, b in best.items():
        print(f"{name:6s} lag CPU {1e3 * b['lag_cpu']:8.1f} ms  wall {1e3 * b['lag_wall']:8.1f} ms"
              f"  search CPU {b['search_cpu']:6.2f} s  tau {b['tau']:.6f} ± {b['sigma']:.4f} s"
              )  # fmt: skip
    bb, aa = best["before"], best["after"]
    print(f"lag CPU ratio {bb['lag_cpu'] / aa['lag_cpu']:.1f}, wall ratio "
          f"{bb['lag_wall'] / aa['lag_wall']:.1f}; search CPU ratio "
          f"{bb['search_cpu'] / aa['search_cpu']:.1f}; max |Δz|/max|z| "
          f"{float(np.max(np.abs(za - zb)) / np.max(np.abs(zb))):.2e}; "
          f"Δτ {aa['tau'] - bb['tau']:.3e} s")  # fmt: skip


if __name__ == "__main__":
    main()
