"""Benchmark: the total family (MTOT, TTOT, Htot) before and after the O(N log m) kernel
(issue 41 item 2), and against allantools.

At each size N (100 Hz rate records: white noise plus a random walk, octave τ up to the
largest each deviation allows):

* function level, one child process per measurement (the import and the data outside the
  timing): ``thermocal.stability.family.stability(y, 0.01, [name], "octave")`` of this tree
  ("new") and of the tree before the change ("old", ``git archive BASE src``), and
  ``allantools.<name>(y, 100, data_type="freq", taus="octave")`` when ``--allantools-python``
  names an interpreter that has it (a scratch venv: allantools is no dependency);
* end to end: ``thermocal allan FILE --deviation mtotdev,ttotdev,htotdev --json`` (wall time
  and peak RSS of the whole process, :func:`_harness.measure`), new and old.

Measurements are interleaved (new, old, allantools, new, old, …), best of ``--repeat``
(allantools once); the old kernel runs only up to ``--old-max`` samples and allantools up to
``--allantools-max`` (they grow as N^1.6–2: hours at 1e6): their time at the larger sizes is
extrapolated from the exponent fitted to the sizes they ran at, and printed as such.  The
load average is printed at the start and end.

Run: .venv/bin/python benchmarks/bench_total_family.py [--quick] [--sizes 1e4,3e4,1e5,1e6]
     [--repeat 2] [--base 2275b44] [--old-max 30000] [--allantools-python /tmp/v/bin/python]
"""

from __future__ import annotations

import argparse
import math
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

from _harness import THERMOCAL, measure

NAMES = ("mtotdev", "ttotdev", "htotdev")
ROOT = Path(__file__).resolve().parents[1]

OURS = r"""
import sys, time
import numpy as np
from thermocal.stability.family import stability
n, name = int(sys.argv[1]), sys.argv[2]
rng = np.random.default_rng(0)
y = rng.standard_normal(n) + np.cumsum(rng.standard_normal(n)) * 1e-2 + 10.0
stability(y[:1000], 0.01, [name], "octave")  # first calls (scipy) outside the timing
t0 = time.perf_counter()
res = stability(y, 0.01, [name], "octave")
print(f"{time.perf_counter() - t0:.4f} {float(res.curves[name].dev[-1])!r}")
"""

THEIRS = r"""
import sys, time
import numpy as np
import allantools
n, name = int(sys.argv[1]), sys.argv[2]
rng = np.random.default_rng(0)
y = rng.standard_normal(n) + np.cumsum(rng.standard_normal(n)) * 1e-2 + 10.0
t0 = time.perf_counter()
t, d, e, k = getattr(allantools, name)(y, 100.0, data_type="freq", taus="octave")
print(f"{time.perf_counter() - t0:.4f} {float(d[-1])!r}")
"""


def _load() -> str:
    return " ".join(f"{v:.2f}" for v in os.getloadavg())


def _child(python: str, code: str, args: list[str], src: Path | None) -> tuple[float, float]:
    env = dict(os.environ)
    if src is not None:
        env["PYTHONPATH"] = str(src)
    out = subprocess.run(
        [python, "-c", code, *args], capture_output=True, text=True, env=env, check=False
    )
    if out.returncode:
        raise SystemExit(f"{args} failed: {out.stderr[-2000:]}")
    t, last = out.stdout.split()
    return float(t), float(last)


def _csv(path: Path, n: int) -> None:
    rng = np.random.default_rng(0)
    y = rng.standard_normal(n) + np.cumsum(rng.standard_normal(n)) * 1e-2 + 10.0
    with path.open("w") as f:
        f.write("time_s,gyro_x [deg/h]\n")
        np.savetxt(f, np.c_[np.arange(n) / 100.0, y], delimiter=",", fmt="%.17g")


def _end_to_end(path: Path, src: Path) -> tuple[float, float]:
    os.environ["PYTHONPATH"] = str(src)
    return measure([*THERMOCAL, "allan", str(path), "--signal", "gyro_x [deg/h]",
                    "--deviation", ",".join(NAMES), "--max-work", "1e15", "--json"])  # fmt: skip


def _exponent(sizes: list[int], times: list[float]) -> float:
    """Slope of log t against log N (least squares)."""
    if len(sizes) < 2:
        return math.nan
    return float(np.polyfit(np.log(sizes), np.log(times), 1)[0])


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", default="1e3,2e3,1e4,3e4,1e5,1e6")
    ap.add_argument("--quick", action="store_true", help="sizes 1e3,3e3,1e4,1e5, old up to 1e4")
    ap.add_argument("--repeat", type=int, default=2)
    ap.add_argument("--base", default="2275b44", help="commit of the code before the change")
    ap.add_argument("--old-max", type=float, default=3e4)
    ap.add_argument("--allantools-python", default=None)
    ap.add_argument("--allantools-max", type=float, default=2e3, help="(run once per size)")
    args = ap.parse_args()
    sizes = [int(float(s)) for s in ("1e3,3e3,1e4,1e5" if args.quick else args.sizes).split(",")]
    old_max = 1e4 if args.quick else args.old_max
    print(f"load average at start: {_load()}  (sizes {sizes}, best of {args.repeat})")
    tmp = Path(tempfile.mkdtemp(prefix="bench-total-"))
    subprocess.run(f"git -C {ROOT} archive {args.base} src | tar -x -C {tmp}", shell=True,
                   check=True)  # fmt: skip
    old_src, new_src = tmp / "src", ROOT / "src"
    py = sys.executable
    rows: dict[tuple[str, str, int], float] = {}
    for n in sizes:
        path = tmp / f"rate_{n}.csv"
        _csv(path, n)
        for name in NAMES:
            who = ["new"] + (["old"] if n <= old_max else [])
            for r in range(args.repeat):
                if r == 0 and args.allantools_python and n <= args.allantools_max:
                    who.append("allantools")  # O(N²) in allantools: once
                elif "allantools" in who:
                    who.remove("allantools")
                for w in who:
                    if w == "allantools":
                        t, d = _child(args.allantools_python, THEIRS, [str(n), name], None)
                    else:
                        t, d = _child(py, OURS, [str(n), name], new_src if w == "new" else old_src)
                    key = (w, name, n)
                    rows[key] = min(rows.get(key, math.inf), t)
                    print(f"  N={n:>8} {name:8} {w:10} {t:9.3f} s  last dev {d:.6g}", flush=True)
        for _ in range(args.repeat):
            for w, src in (("new", new_src), ("old", old_src)):
                if w == "old" and n > old_max:
                    continue
                t, mb = _end_to_end(path, src)
                key = (w, "allan", n)
                rows[key] = min(rows.get(key, math.inf), t)
                rows[(w, "allan-MB", n)] = mb
                print(f"  N={n:>8} allan    {w:10} {t:9.3f} s  {mb:.0f} MB", flush=True)
    print(f"\nload average at end: {_load()}\n")
    print("| what | N | new [s] | old [s] | allantools [s] | old/new | allantools/new |")
    print("|---|---|---|---|---|---|---|")
    for name in (*NAMES, "allan"):
        for n in sizes:
            new = rows[("new", name, n)]
            cells = [f"{new:.3f}"]
            ratios = []
            for w in ("old", "allantools"):
                if (w, name, n) in rows:
                    v = rows[(w, name, n)]
                    cells.append(f"{v:.3f}")
                else:
                    ns = [k for k in sizes if (w, name, k) in rows]
                    if len(ns) >= 2:
                        ex = _exponent(ns, [rows[(w, name, k)] for k in ns])
                        v = rows[(w, name, ns[-1])] * (n / ns[-1]) ** ex
                        cells.append(f"~{v:.0f} (extrapolated, N^{ex:.2f})")
                    else:
                        v = math.nan
                        cells.append("–")
                ratios.append(f"{v / new:.1f}×" if math.isfinite(v) else "–")
            print(f"| {name} | {n:.0e} | " + " | ".join(cells) + " | " + " | ".join(ratios) + " |")
    for w in ("new", "old", "allantools"):
        for name in (*NAMES, "allan"):
            ns = [n for n in sizes if (w, name, n) in rows]
            if len(ns) >= 2:
                ex = _exponent(ns, [rows[(w, name, n)] for n in ns])
                print(f"growth exponent {w:10} {name:8} {ex:.2f} (N = {ns[0]:.0e}…{ns[-1]:.0e})")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
