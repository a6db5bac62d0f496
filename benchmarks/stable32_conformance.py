"""Conformance with Stable32 on public records thermocal's tests do not ship (issue 29).

For every Stable32 output file with interval bounds in the public test data of allantools
(``tests/`` of a checkout: PHASE.DAT, GPS 1PPS, Cs 5071A, Keysight 53230A, OCXO) and,
optionally, of allantoolkit (``tests/assets/Sr87``), thermocal's deviation family is run on
the same record and τ and each printed row is judged: the noise exponent α equal to
Stable32's column, the value within 1e-4 and both bounds within 2e-3 (relative; a constant
scale between the two programs, as OCXO's normalisation by its nominal frequency, is divided
out, and bounds are compared as ratios to the value).  totdev and htotdev are compared with
``bias_correct=True`` (Stable32's default) except in files named ``*nobias*``.  Outputs
Stable32 printed with the noise type set by hand run with that α (:data:`FORCED`); the
OCXO all-τ outputs (no bounds printed) are judged on α and value only.  ``--noise-id``:
the identification's rules (default ``stable32``; ``thermocal`` for the package default).

Fetch the repositories yourself (they are not a dependency); nothing here runs in CI.

Run: .venv/bin/python benchmarks/stable32_conformance.py --allantools PATH/allantools/tests
     [--allantoolkit PATH/allantoolkit/tests/assets] [--rows] [--noise-id thermocal]
"""

from __future__ import annotations

import argparse
import gzip
from pathlib import Path

import numpy as np

from thermocal.stability.family import stability

DEVS = ("adev", "oadev", "mdev", "tdev", "hdev", "ohdev", "totdev", "mtotdev", "ttotdev",
        "htotdev")  # fmt: skip


FORCED = {
    "phase_dat_mtotdev_octave_alpha0.txt": 0,
    "phase_dat_htotdev_octave_nobias.txt": 2,
    "totdev_decade.txt": 0,
    "stable32_totdev_alltau.txt": 0,
    "phase_dat_totdev_octave.txt": 0,
}
"""Outputs Stable32 printed with its noise type set by hand (``--noise-type``): one α in every
row where the same program identified others on the same record and τ (PHASE.DAT Htot
identified white FM, then flicker PM: the "nobias" run is white PM throughout, the noise
Stable32 gives no bias factor; the Cs 5071A's OADEV reads white and flicker PM up to
m = 100 and its TOTDEV white FM throughout, with no bias factor where OADEV reads flicker
FM; the OCXO all-τ TOTDEV is white FM at every τ, OADEV's α runs from +1 to −2).  PHASE.DAT's
TOTDEV is inferred: white FM at every τ, also at m = 128 where Stable32's TOTDEV rule (B1
down to 6 averages, :data:`thermocal.stability.edf.STABLE32_B1_MIN_TOTAL`) reads flicker PM
as MTOT's and Htot's output of the same record do, and as TOTDEV on GPS, 53230A, Sr87 and
OCXO shows the rule at 4–7 averages."""


def _load(path: Path) -> np.ndarray:
    """The first number of every data line (Stable32 headers and '#'/'%' lines skipped)."""
    opener = gzip.open if path.suffix == ".gz" else open
    vals = []
    with opener(path, "rt", encoding="latin-1") as f:
        for ln in f:
            s = ln.strip()
            if not s or s[0] in "#%":
                continue
            try:
                vals.append(float(s.split()[0]))
            except ValueError:
                continue
    return np.asarray(vals)


def _rows(path: Path, *, values_only: bool = False) -> np.ndarray:
    """Stable32's printed rows (AF, τ, n, α, low, value, high), commented ones included;
    ``values_only``: also rows printed without bounds (0)."""
    out = []
    for ln in path.read_text(encoding="latin-1").splitlines():
        s = ln.strip().lstrip("#").strip()
        try:
            v = [float(t) for t in s.split()]
        except ValueError:
            continue
        if len(v) == 7 and (v[4] > 0 or (values_only and v[5] > 0)):
            out.append(v)
    return np.asarray(out)


def _dev_of(name: str) -> str | None:
    low = name.lower()
    for d in sorted(DEVS, key=len, reverse=True):
        if d in low:
            return d
    return None


def _judge(
    tag: str, x: np.ndarray, dtype: str, tau0: float, f: Path, show: bool, noise_id: str
) -> list[int]:
    dev = _dev_of(f.name)
    values_only = "alltau" in f.name  # Stable32 printed no bounds there
    r = _rows(f, values_only=values_only)
    if dev is None or r.size == 0:
        return [0, 0, 0, 0]
    bias = dev in ("totdev", "htotdev") and "nobias" not in f.name
    forced = FORCED.get(f.name) if f.parent.name in ("phasedat", "Cs5071A", "ocxo") else None
    res = stability(
        x, tau0, [dev], r[:, 1], data_type=dtype, bias_correct=bias, alpha=forced,
        noise_id=noise_id,
    )  # fmt: skip
    c = res.curves[dev]
    where = {round(t / tau0): i for i, t in enumerate(c.tau_s)}
    scale = c.dev[where[round(r[0, 1] / tau0)]] / r[0, 5]
    ok = [len(r), 0, 0, 0]
    for row in r:
        j = where[round(row[1] / tau0)]
        a_ok = int(c.alpha[j]) == int(row[3])
        v_ok = abs(c.dev[j] / row[5] / scale - 1) < 1e-4
        lo = hi = 0.0
        if not values_only:
            lo = (c.low[j] / c.dev[j]) / (row[4] / row[5]) - 1
            hi = (c.high[j] / c.dev[j]) / (row[6] / row[5]) - 1
        b_ok = values_only or (abs(lo) < 2e-3 and abs(hi) < 2e-3)
        ok[1] += a_ok
        ok[2] += v_ok
        ok[3] += b_ok
        if show and not (a_ok and v_ok and b_ok):
            print(f"  {tag} {f.name} m={int(row[0])}: α {int(c.alpha[j])} vs {int(row[3])} "
                  f"({c.alpha_method[j]}), value {c.dev[j] / row[5] / scale - 1:+.1e}, "
                  f"bounds {lo:+.1e}/{hi:+.1e}")  # fmt: skip
    if values_only:
        ok[3] = -1  # not judged
    return ok


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--allantools", type=Path, required=True, help="allantools' tests/ folder")
    ap.add_argument("--allantoolkit", type=Path, help="allantoolkit's tests/assets/ folder")
    ap.add_argument("--rows", action="store_true", help="print every row that is off")
    ap.add_argument(
        "--noise-id", default="stable32", choices=("stable32", "thermocal"),
        help="the noise identification's rules (allan --noise-id)",
    )  # fmt: skip
    a = ap.parse_args()
    at = a.allantools
    sets: list[tuple[str, Path, str, float, list[Path]]] = [
        ("PHASE.DAT", at / "phasedat/PHASE.DAT", "phase", 1.0,
         sorted((at / "phasedat").glob("phase_dat_*_octave*.txt"))
         + sorted((at / "phasedat").glob("phase_dat_*_decade.txt"))),
        ("GPS", at / "gps/gps_1pps_phase_data.txt.gz", "phase", 1.0,
         sorted((at / "gps").glob("stable32_*.txt"))),
        ("Cs 5071A", at / "Cs5071A/5071A_phase.txt.gz", "phase", 1.0,
         sorted((at / "Cs5071A").glob("*_decade.txt"))),
        ("53230A", at / "Keysight53230A_ti_noise_floor/tic_phase.txt", "phase", 1.0,
         sorted((at / "Keysight53230A_ti_noise_floor").glob("tic_*dev.txt"))),
        ("OCXO", at / "ocxo/ocxo_frequency.txt", "rate", 1.0,
         sorted((at / "ocxo").glob("*_octave.txt"))),
        ("OCXO frac", at / "ocxo/ocxo_frequency.txt", "fractional", 1.0,
         sorted((at / "ocxo").glob("stable32_*_alltau.txt"))),
    ]  # fmt: skip
    if a.allantoolkit:
        sr = a.allantoolkit / "Sr87"
        files = sorted((sr / "phase0/octave").glob("*.txt"))
        files += sorted((sr / "phase0/decade").glob("*.txt"))
        sets.append(("Sr87", sr / "phase0/phase0_data.txt", "phase", 2.5, files))
    print(
        f"{'record':10s} {'deviation file':44s} {'rows':>4s} {'α':>4s} {'value':>5s} {'bounds':>6s}"
    )
    total = np.zeros(4, dtype=int)
    values = np.zeros(3, dtype=int)
    for tag, data, dtype, tau0, files in sets:
        x = _load(data)
        if dtype == "fractional":  # Hz about 10 MHz → (f − f0)/f0, as Stable32's .003 file
            x, dtype = (x - 1.0e7) / 1.0e7, "rate"
        for f in files:
            if _dev_of(f.name) is None:
                continue
            ok = _judge(tag, x, dtype, tau0, f, a.rows, a.noise_id)
            if ok[0]:
                name = f"{f.parent.name}/{f.name}"
                b = f"{ok[3]:6d}" if ok[3] >= 0 else f"{'–':>6s}"
                print(f"{tag:10s} {name:44s} {ok[0]:4d} {ok[1]:4d} {ok[2]:5d} {b}")
                if ok[3] >= 0:
                    total += ok
                else:
                    values[:3] += ok[:3]
    print(
        f"{'all':10s} {'with bounds':44s} {total[0]:4d} {total[1]:4d} {total[2]:5d} {total[3]:6d}"
    )
    if values[0]:
        print(f"{'all':10s} {'values only (no bounds printed)':44s} {values[0]:4d} {values[1]:4d} "
              f"{values[2]:5d} {'–':>6s}")  # fmt: skip
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
