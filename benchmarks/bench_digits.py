"""Benchmark: the deviation family keeps its digits at 10⁸ samples (issue 42).

A rate record of ``--n`` samples (default 10⁸) y_i = 1e6 °/h + a random walk (steps of
0.05 °/h rms) + white noise (0.5 °/h rms), rounded to the grid of 2⁻¹⁰ °/h so that every
sample is an integer I_i / 1024 held exactly in float64.  At a few octave factors m
(``--m``) each deviation of ``thermocal.stability.family.stability(y, τ0, [name], m τ0)``
is compared with an exact evaluation of its NIST SP 1065 definition:

* the integer phase X_k = Σ_{i<k} I_i (int64, exact: |X| < 1.1e17 at 10⁸ samples) and, for
  MDEV/TDEV, its running sum P_k = Σ_{i<k} X_i (int64, wrapping: every inner sum
  v_j = P_{j+3m} − 3P_{j+2m} + 3P_{j+m} − P_j fits in 63 bits, so the wrapped arithmetic
  gives it exactly);
* every difference of the definition (eqs. 7, 11, 14, 15, 17, 18, 25, 33) exactly in int64,
  in chunks of 2²² terms (no more than three arrays of N at a time);
* each square rounded once to float64 and summed pairwise by numpy, the chunks' sums by
  ``math.fsum``: relative error ≤ ε log₂(2²²) ≈ 5e-15, far below the 1e-9 asked;
* TIE rms (eq. 33) of the phase less its mean rate, the mean's phase step m Σ I / n
  subtracted from each integer difference (one rounding each).

Nothing of thermocal's is used for the reference.  Prints per deviation and m the value,
the relative difference and thermocal's time; exit 1 if any exceeds 1e-9.

Run: .venv/bin/python -u benchmarks/bench_digits.py [--n 100000000] [--m 1,16,1024,65536,4194304]
Memory: ≈ 4 arrays of N float64/int64 at the peak (3.2 GB at 10⁸).
"""

from __future__ import annotations

import argparse
import gc
import math
import time
from collections.abc import Callable

import numpy as np
import numpy.typing as npt

I64 = npt.NDArray[np.int64]
SCALE = 1024
TAU0 = 0.01
CHUNK = 1 << 22
NAMES = ("adev", "oadev", "mdev", "tdev", "hdev", "ohdev", "totdev", "tierms")
REL = 1e-9


def record(n: int, seed: int = 0) -> I64:
    """Integer samples I_i (y_i = I_i / SCALE °/h), generated in chunks of 10⁷."""
    rng = np.random.default_rng(seed)
    out = np.empty(n, dtype=np.int64)
    walk = 0.0
    for a in range(0, n, 10_000_000):
        b = min(a + 10_000_000, n)
        w = walk + np.cumsum(rng.normal(0.0, 0.05, b - a))
        walk = float(w[-1])
        out[a:b] = np.round((1e6 + w + rng.normal(0.0, 0.5, b - a)) * SCALE).astype(np.int64)
    return out


def chunked_sq(n_terms: int, term: Callable[[int, int], npt.NDArray[np.generic]]) -> float:
    """Σ_{k<n_terms} term(k)² with ``term(a, b)`` the integer (or once-rounded) terms k in
    [a, b): squares in float64, pairwise within a chunk, ``math.fsum`` across chunks."""
    parts = []
    for a in range(0, n_terms, CHUNK):
        f = term(a, min(a + CHUNK, n_terms)).astype(np.float64)
        parts.append(float(f @ f) if f.size < 16 else float(np.sum(f * f)))
    return math.fsum(parts)


def diff_terms(x: I64, m: int, taps: tuple[int, ...], step: int = 1) -> Callable[[int, int], I64]:
    """Terms Σ_j taps[j] x_{k·step + j m} for k in [a, b) (int64, exact)."""

    def term(a: int, b: int) -> I64:
        k = np.arange(a, b, dtype=np.int64) * step if step > 1 else None
        out = np.zeros(b - a, dtype=np.int64)
        for j, c in enumerate(taps):
            if c:
                out += c * (x[k + j * m] if k is not None else x[a + j * m : b + j * m])
        return out

    return term


def reference(name: str, ints: I64, x: I64, p: I64 | None, m: int) -> float:
    """SP 1065 deviation ``name`` at factor m of y = ints / SCALE [°/h] every TAU0."""
    n = x.size
    tau, unit = m * TAU0, TAU0 / SCALE
    if name in ("adev", "oadev", "hdev", "ohdev"):
        d = 2 if name in ("adev", "oadev") else 3
        taps = (1, -2, 1) if d == 2 else (-1, 3, -3, 1)
        if name in ("adev", "hdev"):
            n_terms = (n - 1) // m + 1 - d
            s = chunked_sq(n_terms, diff_terms(x, m, taps, step=m))
        else:
            n_terms = n - d * m
            s = chunked_sq(n_terms, diff_terms(x, m, taps))
        return math.sqrt(s / ((2.0 if d == 2 else 6.0) * n_terms)) * unit / tau
    if name in ("mdev", "tdev"):
        assert p is not None
        n_terms = n - 3 * m + 1
        with np.errstate(over="ignore"):
            s = chunked_sq(n_terms, diff_terms(p, m, (-1, 3, -3, 1)))
        mod = math.sqrt(s / (2.0 * n_terms)) * unit / (m * tau)
        return mod * tau / math.sqrt(3.0) if name == "tdev" else mod
    if name == "totdev":  # odd reflection at both ends; terms centred on x_1 … x_{N−2}
        x0, xl = int(x[0]), int(x[-1])

        def ext(k: I64) -> I64:
            lo, hi = k < 0, k > n - 1
            v = x[np.clip(k, 0, n - 1)]
            v[lo] = 2 * x0 - x[-k[lo]]
            v[hi] = 2 * xl - x[2 * (n - 1) - k[hi]]
            return v

        def tot(a: int, b: int) -> I64:
            i = np.arange(a + 1, b + 1, dtype=np.int64)
            return ext(i - m) - 2 * ext(i) + ext(i + m)

        s = chunked_sq(n - 2, tot)
        return math.sqrt(s / (2.0 * (n - 2))) * unit / tau
    if name == "tierms":
        step = m * int(ints.sum()) / ints.size  # the mean's phase step, rounded once

        def tie(a: int, b: int) -> npt.NDArray[np.float64]:
            return (x[a + m : b + m] - x[a:b]).astype(np.float64) - step

        return math.sqrt(chunked_sq(n - m, tie) / (n - m)) * unit
    raise ValueError(name)


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, default=100_000_000)
    ap.add_argument("--m", default="1,16,1024,65536,4194304")
    ap.add_argument("--only", default=None, help="comma-separated deviations")
    args = ap.parse_args()
    from thermocal.stability.family import stability

    names = args.only.split(",") if args.only else list(NAMES)
    ms = [int(v) for v in args.m.split(",")]
    t0 = time.perf_counter()
    ints = record(args.n)
    x = np.zeros(args.n + 1, dtype=np.int64)
    np.cumsum(ints, out=x[1:])
    refs: dict[tuple[str, int], float] = {}
    t1 = time.perf_counter()
    for name in names:
        p = None
        if name in ("mdev", "tdev"):
            p = np.zeros(x.size + 1, dtype=np.int64)
            with np.errstate(over="ignore"):
                np.cumsum(x, out=p[1:])  # wraps; the inner sums come out exact
        for m in ms:
            refs[name, m] = reference(name, ints, x, p, m)
        del p
    t_ref = time.perf_counter() - t1
    del x
    gc.collect()
    y = ints.astype(np.float64) / SCALE
    del ints
    print(f"N = {args.n:.3g} rate samples, 1e6 °/h + random walk + white, m = {ms}")
    print(f"record {t1 - t0:.1f} s, exact references {t_ref:.1f} s")
    ok = True
    for name in names:
        t = time.perf_counter()
        res = stability(y, TAU0, [name], np.array(ms, dtype=np.float64) * TAU0)
        dt = time.perf_counter() - t
        curve = res.curves[name]
        worst = 0.0
        for m, dev in zip(curve.m.tolist(), curve.dev.tolist(), strict=True):
            ref = refs[name, int(m)]
            rel = abs(dev / ref - 1.0)
            worst = max(worst, rel)
            print(f"  {name:7s} m = {int(m):8d}  {dev:.15e}  exact {ref:.15e}  rel {rel:.1e}")
        ok &= worst <= REL
        print(f"{name:7s} thermocal {dt:6.1f} s  max rel. {worst:.1e}  (≤ 1e-9: {worst <= REL})")
    return 0 if ok else 1


if __name__ == "__main__":
    raise SystemExit(main())
