"""Mutation check: inject small plausible bugs one at a time and see whether the suite
notices (issue 12 §5: a test that cannot fail is a defect).

Each mutant replaces one exact snippet of one source file.  The repository's ``src/``,
``tests/`` and ``pyproject.toml`` are copied to a temporary directory, the mutant is
applied there (the work tree is never touched), and pytest runs in the copy with the
copy's ``src`` first on ``PYTHONPATH``; a mutant is *killed* when the run fails.  By
default each mutant runs the test files named with it; ``--full`` runs the whole suite.

    python benchmarks/mutation_check.py            # the listed test files per mutant
    python benchmarks/mutation_check.py --full     # the whole suite per mutant (slow)
    python benchmarks/mutation_check.py allan-rrw-read-at-1s   # some mutants only
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


@dataclass(frozen=True)
class Mutant:
    name: str
    file: str
    old: str
    new: str
    tests: tuple[str, ...]
    what: str


MUTANTS: tuple[Mutant, ...] = (
    # --- the eight that survived the audit (issue 12 §5) -------------------------------
    Mutant(
        "allan-rrw-read-at-1s",
        "src/thermocal/stability/allan.py",
        'READ_TAU_S: Final = (math.sqrt(3.0), 1.0, float("nan"), 3.0, math.sqrt(2.0))',
        'READ_TAU_S: Final = (math.sqrt(3.0), 1.0, float("nan"), 1.0, math.sqrt(2.0))',
        ("tests/test_allan.py", "tests/test_allan_references.py"),
        "rate random walk slope line read at τ = 1 s instead of 3 s",
    ),
    Mutant(
        "allan-edf-overwritten",
        "src/thermocal/stability/allan.py",
        "edf[idx] += edf_simple(n_phase, m[idx], alphas[idx])",
        "edf[idx] = edf_simple(n_phase, m[idx], alphas[idx])",
        ("tests/test_allan.py", "tests/test_allan_references.py"),
        "gapped data: each segment's EDF overwrites the pooled one",
    ),
    Mutant(
        "metrics-sensitivity-no-abs",
        "src/thermocal/metrics.py",
        "mean_abs = float(np.mean(np.abs(np.diff(B) / dT)))",
        "mean_abs = float(np.mean(np.diff(B) / dT))",
        ("tests/test_metrics.py",),
        "temperature sensitivity without abs()",
    ),
    Mutant(
        "metrics-stages-keep-earth-rate",
        "src/thermocal/metrics.py",
        "            temp,\n            values - earth,\n",
        "            temp,\n            values,\n",
        ("tests/test_metrics.py",),
        "hold-stage biases without the earth rate removed",
    ),
    Mutant(
        "poly-constant-cov-without-1/m",
        "src/thermocal/models/poly.py",
        "L[0, pk:] = 1.0 / m\n",
        "L[0, pk:] = 1.0\n",
        ("tests/test_models_poly.py",),
        "multi-run fit: the constant's covariance misses its 1/m",
    ),
    Mutant(
        "kalman-innovation-without-R",
        "src/thermocal/turntable/kalman.py",
        "innov_var[j] = np.diag(p)[N_COEFFS:] + np.diag(r)",
        "innov_var[j] = np.diag(p)[N_COEFFS:]",
        ("tests/test_turntable_estimation.py", "tests/test_turntable_encoders.py"),
        "Kalman: R dropped from the innovation variance",
    ),
    Mutant(
        "c-piecewise-strict-breakpoint",
        "src/thermocal/export/c.py",
        'f"while (j < {P}_N_BREAKPOINTS && {P}_BP[j] <= temp) {{",',
        'f"while (j < {P}_N_BREAKPOINTS && {P}_BP[j] < temp) {{",',
        ("tests/test_export_c.py", "tests/test_export_c_edges.py"),
        "C export: BP < T instead of BP ≤ T",
    ),
    Mutant(
        "c-rate-gap-without-factor",
        "src/thermocal/export/c.py",
        "time_s - s->last_t > {P}_GAP_FACTOR * s->sample_interval_s",
        "time_s - s->last_t > s->sample_interval_s",
        ("tests/test_export_c.py", "tests/test_export_c_edges.py"),
        "C export: the rate buffer's gap test without GAP_FACTOR",
    ),
    # --- further plausible slips across the package ------------------------------------
    Mutant(
        "piecewise-no-width-rule-no-bic",
        "src/thermocal/models/piecewise.py",
        "    chosen = int(np.argmin(bic)) + 1\n",
        "    chosen = len(fits)\n",
        ("tests/test_models_piecewise.py", "tests/test_cli_contract.py"),
        "piecewise: every asked-for breakpoint kept, warranted or not",
    ),
    Mutant(
        "units-deg-s-to-deg-h-60",
        "src/thermocal/units.py",
        "DS_TO_DH: Final = SECONDS_PER_HOUR",
        "DS_TO_DH: Final = SECONDS_PER_MINUTE",
        ("tests/test_units.py", "tests/test_compensate.py"),
        "°/s → °/h by 60 instead of 3600",
    ),
    Mutant(
        "units-earth-rate-typo",
        "src/thermocal/units.py",
        "EARTH_RATE_RAD_S: Final = 7.292115e-5",
        "EARTH_RATE_RAD_S: Final = 7.292115e-4",
        ("tests/test_units.py", "tests/test_metrics.py"),
        "earth rate off by a factor 10",
    ),
    Mutant(
        "allan-variance-missing-2",
        "src/thermocal/stability/allan.py",
        "avar = sums / (2.0 * m.astype(np.float64) ** 2 * n_terms)",
        "avar = sums / (m.astype(np.float64) ** 2 * n_terms)",
        ("tests/test_allan.py",),
        "Allan variance without the 1/2",
    ),
    Mutant(
        "metrics-stability-ddof-0",
        "src/thermocal/metrics.py",
        "    stab = float(np.std(means, ddof=1))",
        "    stab = float(np.std(means, ddof=0))",
        ("tests/test_metrics.py",),
        "bias stability with the population σ (n instead of n − 1)",
    ),
    Mutant(
        "preprocess-rate-per-second",
        "src/thermocal/preprocess.py",
        "rate[ok] = (Ts[hi[ok]] - Ts[lo[ok]]) / span[ok] * SECONDS_PER_MINUTE",
        "rate[ok] = (Ts[hi[ok]] - Ts[lo[ok]]) / span[ok]",
        ("tests/test_preprocess.py", "tests/test_models_poly.py"),
        "Ṫ in °C/s where °C/min is stated",
    ),
    Mutant(
        "compensate-unit-factor-inverted",
        "src/thermocal/compensate/files.py",
        "y_data = y_model / factor",
        "y_data = y_model * factor",
        ("tests/test_compensate.py",),
        "model value converted to the data's unit the wrong way",
    ),
    Mutant(
        "turntable-band-ignores-noise",
        "src/thermocal/turntable/schedule.py",
        "tol = 8.0 * sigma_deg + 2.0 * q + 2.0 / 3600.0",
        "tol = 2.0 / 3600.0",
        ("tests/test_turntable_encoders.py",),
        "dwell band not scaled to the encoder noise",
    ),
    Mutant(
        "bank-picks-worst-model",
        "src/thermocal/models/bank.py",
        "choice = np.argmin(dev, axis=1)",
        "choice = np.argmax(dev, axis=1)",
        ("tests/test_models_bank.py",),
        "model bank: start-up selection takes the largest deviation",
    ),
    Mutant(
        "time-ms-as-us",
        "src/thermocal/units.py",
        '{"s": 1.0, "ms": 1e-3, "us": 1e-6}',
        '{"s": 1.0, "ms": 1e-6, "us": 1e-6}',
        ("tests/test_io.py", "tests/test_cli_inspect.py"),
        "milliseconds converted as microseconds",
    ),
    Mutant(
        "gap-factor-15",
        "src/thermocal/recording.py",
        "GAP_FACTOR = 1.5",
        "GAP_FACTOR = 15.0",
        ("tests/test_io.py", "tests/test_preprocess.py", "tests/test_cli_inspect.py"),
        "gaps only found beyond 15 median intervals",
    ),
    Mutant(
        "warmup-window-cumsum-off-by-one",
        "src/thermocal/models/warmup.py",
        "cs = np.cumsum(x[:m]) / np.arange(1, m + 1, dtype=np.float64)",
        "cs = np.cumsum(x[:m]) / np.arange(2, m + 2, dtype=np.float64)",
        ("tests/test_models_warmup.py",),
        "warm-up start window mean divided by n + 1",
    ),
    Mutant(
        "schema-accepts-short-coefficients",
        "src/thermocal/models/poly.py",
        '        same_length(state, path, "coef", len(state["terms"]), "one per term")\n',
        "",
        ("tests/attacks/test_attacks.py",),
        "model file with fewer coefficients than terms accepted",
    ),
    Mutant(
        "io-temporary-readable",
        "src/thermocal/io.py",
        "    if name.endswith(TEMP_SUFFIX):\n",
        "    if False:\n",
        ("tests/test_faults.py",),
        "an interrupted write's temporary accepted by the readers",
    ),
)


def _copy_repo(dst: Path) -> None:
    shutil.copytree(ROOT / "src", dst / "src", ignore=shutil.ignore_patterns("__pycache__"))
    shutil.copytree(ROOT / "tests", dst / "tests", ignore=shutil.ignore_patterns("__pycache__"))
    shutil.copy2(ROOT / "pyproject.toml", dst / "pyproject.toml")


def run_one(mutant: Mutant, full: bool) -> tuple[str, float, str]:
    """Apply ``mutant`` in a copy and run its tests; returns (status, seconds, detail)."""
    with tempfile.TemporaryDirectory(prefix="thermocal-mutant-") as tmp:
        d = Path(tmp)
        _copy_repo(d)
        target = d / mutant.file
        text = target.read_text(encoding="utf-8")
        if text.count(mutant.old) != 1:
            return "not-applied", 0.0, f"snippet found {text.count(mutant.old)} times"
        target.write_text(text.replace(mutant.old, mutant.new), encoding="utf-8")
        env = {**os.environ, "PYTHONPATH": str(d / "src"), "PYTHONDONTWRITEBYTECODE": "1"}
        probe = subprocess.run(
            [sys.executable, "-c", "import thermocal; print(thermocal.__file__)"],
            cwd=d, env=env, capture_output=True, text=True, check=False,
        )  # fmt: skip
        if not probe.stdout.strip().startswith(str(d)):
            return "not-applied", 0.0, f"imported {probe.stdout.strip()} instead of the copy"
        tests = ["tests"] if full else list(mutant.tests)
        t0 = time.perf_counter()
        proc = subprocess.run(
            [sys.executable, "-m", "pytest", "-q", "-x", "-n", "2", "-p", "no:cacheprovider",
             *tests],
            cwd=d, env=env, capture_output=True, text=True, check=False,
        )  # fmt: skip
        dt = time.perf_counter() - t0
        last = proc.stdout.strip().splitlines()[-1] if proc.stdout.strip() else ""
        return ("killed" if proc.returncode != 0 else "SURVIVED"), dt, last


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("names", nargs="*", help="mutants to run (default: all)")
    ap.add_argument("--full", action="store_true", help="run the whole suite per mutant")
    args = ap.parse_args(argv)
    chosen = [m for m in MUTANTS if not args.names or m.name in args.names]
    rows = []
    for m in chosen:
        status, dt, detail = run_one(m, args.full)
        rows.append((m, status, dt, detail))
        print(f"{status:11s} {dt:6.1f} s  {m.name:34s} {m.what}", flush=True)
    killed = sum(1 for _, s, _, _ in rows if s == "killed")
    applied = sum(1 for _, s, _, _ in rows if s != "not-applied")
    print(f"\nkilled {killed} of {applied} mutants ({100.0 * killed / max(applied, 1):.0f} %)")
    for m, s, _, detail in rows:
        if s != "killed":
            print(f"  {s}: {m.name}: {detail}")
    return 0 if killed == applied == len(chosen) else 1


if __name__ == "__main__":
    raise SystemExit(main())
