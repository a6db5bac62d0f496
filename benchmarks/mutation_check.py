"""Mutation check: inject small plausible bugs one at a time and see whether the tests
notice (issue 12 §5, issue 27 item 6: a test that cannot fail is a defect).

Each mutant names ONE file, a short code expression that must occur there exactly once,
its replacement, and the test files that should catch it.  The whole tracked tree (``git
ls-files``: src/, tests/, README.md, pyproject.toml, everything the tests read), plus new
files not yet committed, is copied once per job to a temporary directory; each mutant is
applied there (the work tree is never touched), its test files run with the copy's ``src``
first on ``PYTHONPATH`` (``pytest -x -q -p no:randomly``), and the file is restored.

Outcomes: ``killed`` (the tests failed), ``SURVIVED`` (they passed), ``timeout`` (counted
as killed, listed), ``ERROR`` (the expression is not found, or found more than once, in the
file, or the file is missing: the mutant did not apply; never counted as killed, always
listed, and the exit status is 1).  After code moves, ``--check`` lists in a second which
mutants no longer apply, without running any test.

    python benchmarks/mutation_check.py                      # every mutant, one job
    python benchmarks/mutation_check.py --jobs 2 fleet- px4  # names containing these words
    python benchmarks/mutation_check.py --check              # only: does each one apply?
    python benchmarks/mutation_check.py --full name          # the whole suite per mutant
"""

from __future__ import annotations

import argparse
import os
import queue
import shutil
import subprocess
import sys
import tempfile
import threading
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


_TEST_FILES = {p.name: p.relative_to(ROOT).as_posix() for p in (ROOT / "tests").rglob("test_*.py")}
"""Every test file by its basename (basenames are unique across the tests tree)."""


def _t(*names: str) -> tuple[str, ...]:
    """Test files by module name, wherever they sit in the tests tree (``units`` gives
    ``tests/core/test_units.py``); a name with a ``/`` is a path and is kept as it is."""
    return tuple(
        n if "/" in n else _TEST_FILES.get(f"test_{n}.py", f"tests/test_{n}.py") for n in names
    )


P = "src/thermocal/"
# Files split by the module they guard (each group: the files one earlier file became).
MATHS = _t("adequacy_by_hand", "stability_by_hand", "kernels_by_hand", "preprocess_by_hand",
           "gravity_by_hand", "identifiers_by_hand")  # fmt: skip
FIRMWARE = _t("ardupilot_by_hand", "px4_accel_by_hand", "params_by_hand", "ulog_subscriptions")
MULTIPOS_BY_HAND = _t("calibration_checks", "multipos_by_hand", "gravity_placements",
                      "validation_by_hand")  # fmt: skip
H38_AUDIT = _t("multipos_messages", "validate_messages", "compensate_rate", "inspection_setpoints",
               "noise_messages", "export_c_messages", "demo_validations")  # fmt: skip
LEFTOVER39 = _t("allan_option_attacks", "station_fifo_attacks", "fleet_worker_attacks",
                "compensate_column_attacks")  # fmt: skip
TT_THERMAL = _t("turntable_by_hand", "turntable_thermal", "turntable_thermal_cli")
TT_ACCEL = _t("turntable_by_hand", "turntable_accel", "turntable_thermal")
TT_ENC = _t("turntable_by_hand", "turntable_encoders", "turntable_kinematics", "turntable_cli")
TT_CAL = _t("turntable_by_hand", "turntable_estimation", "turntable_encoders", "turntable_cli")
FLEET = _t("fleet_units", "fleet", "fleet_reruns")
WORK_BOUNDS = ("tests/cli/test_work_bounds_attacks.py",)
UNITS = _t(
    "units_by_hand",
    "text_by_hand",
    "ulog_vehicle_imu",
    "units",
    "units_resolver",
    "units_property",
    "units_travel",
)
H38R = _t("reader_options")
TEXT = _t(
    "units_by_hand",
    "text_by_hand",
    "ulog_vehicle_imu",
    "text_logs",
    "tests/readers/test_text_attacks.py",
)
PARAMS = _t(
    "params_ranges",
    "tempcal_by_hand",
    "export_params",
    "tests/export/test_export_params_attacks.py",
)
PX4 = _t("params_ranges", "tempcal_by_hand", "px4_tempcal", "px4_baro_mag", "ardupilot_tempcal")
ADEQ = _t(*MATHS, "adequacy", "fc_gates")
STAB = _t(*MATHS, "stability_reference", "allan", "allan_references")
NOISE = _t(*MATHS, "stability_noise_terms", "noise_cmd")
H38 = _t("noise_terms_real_sensors")
MULTI = _t(*MATHS, "multipos")
STATION = _t("station", "readers_station")
ST_ATT = _t("tests/station/test_station_attacks.py")
FC = _t("units_by_hand", "text_by_hand", "ulog_vehicle_imu", "fc_log_readers", "fc_gates")
EXPC = _t("export_c", "export_c_edges", "export_c_triads", "export_c_units")
COMP = _t(*MATHS, "compensate", "outside_range", "judge_absolute")
GRAV = _t(*MATHS, "gravity_tilt", "gravity_tref")
IDS = _t(*MATHS, "c_identifiers", "tests/export/test_generated_code_attacks.py")
OUTS = _t("faults", "tests/core/test_output_attacks.py")
METRICS = _t(*MATHS, "metrics", "drift_angle", "metrics_runs")
NAMES = _t("tests/core/test_names_attacks.py")
FW_AP = _t(*FIRMWARE, "ardupilot_hygiene", "ardupilot_tclr_range",
           "ardupilot_param_changes", "fc_reports")  # fmt: skip
FW_EXPORT = _t(*FIRMWARE, "export_params", "tests/export/test_export_params_attacks.py",
               "px4_tempcal")  # fmt: skip
FW_PX4 = _t(*FIRMWARE, "px4_tempcal", "px4_baro_mag", "ardupilot_tempcal")
FW_ADEQ = _t(*FIRMWARE, "adequacy", "export_params", "outside_range")
FW_ULOG = _t(*FIRMWARE, "ulog_fast", "tempcal_pipeline_reads")
FW_ATT = _t("tests/tempcal/test_firmware_attacks.py", *FIRMWARE)
H39A = _t(
    "stability_reference",
    "allan",
    "allan_references",
    "allan_dynamic",
    "noise_cmd",
    "noise_terms_quantization",
    "noise_terms_theo1_edf",
    "total_edf_stable32",
    "noise_type",
    "stability_noise_terms",
    "stability_tables",
)
H39A_ATT = _t("tests/stability/test_allan_attacks.py")
H39A_EDF = _t("stability_tables", "total_edf_stable32", "noise_terms_theo1_edf")
H39MP = _t(*MULTIPOS_BY_HAND, "tests/multipos/test_multipos_attacks.py")
ADEQ_H39 = (*_t("adequacy_overrides"), *ADEQ)
ST_ATT2 = ("tests/station/test_station_run_attacks.py",)
AUDIT = _t("tests/cli/test_cli_surface_attacks.py", "tests/simulate/test_simulate_rate_attacks.py")
H39L = _t(*LEFTOVER39)
DIGITS = _t("deviation_digits")


MUTANTS: tuple[Mutant, ...] = (
    # --- the project's own 22 (issue 12 §5; the first eight: the audit's survivors) ------
    Mutant(
        "allan-rrw-read-at-1s",
        P + "stability/allan.py",
        'float("nan"), 3.0, math.sqrt(2.0))',
        'float("nan"), 1.0, math.sqrt(2.0))',
        _t("allan", "allan_references"),
        "rate random walk line read at τ = 1 s, not 3 s",
    ),
    Mutant(
        "allan-edf-overwritten",
        P + "stability/family.py",
        "edf[i] += e if",
        "edf[i] = e if",
        _t("allan", "allan_references"),
        "gapped data: each segment's EDF overwrites the pooled one",
    ),
    Mutant(
        "metrics-sensitivity-no-abs",
        P + "metrics.py",
        "np.mean(np.abs(np.diff(B) / dT))",
        "np.mean(np.diff(B) / dT)",
        METRICS,
        "temperature sensitivity without abs()",
    ),
    Mutant(
        "metrics-stages-keep-earth-rate",
        P + "metrics.py",
        "bias=s.bias - earth)",
        "bias=s.bias)",
        METRICS,
        "hold-stage biases without the earth rate removed",
    ),
    Mutant(
        "poly-constant-cov-without-1/m",
        P + "models/poly_fit.py",
        "L[0, pk:] = 1.0 / m\n",
        "L[0, pk:] = 1.0\n",
        _t("models_poly"),
        "multi-run fit: the constant's covariance misses its 1/m",
    ),
    Mutant(
        "kalman-innovation-without-R",
        P + "turntable/kalman.py",
        "np.diag(p)[N_COEFFS:] + np.diag(r)",
        "np.diag(p)[N_COEFFS:]",
        _t("turntable_estimation", "turntable_encoders"),
        "Kalman: R dropped from the innovation variance",
    ),
    Mutant(
        "c-piecewise-strict-breakpoint",
        P + "export/c/piecewise.py",
        "{P}_BP[j] <= temp)",
        "{P}_BP[j] < temp)",
        EXPC,
        "C export: BP < T instead of BP ≤ T",
    ),
    Mutant(
        "c-rate-gap-without-factor",
        P + "export/c/core.py",
        "time_s - s->last_t > {P}_GAP_FACTOR * s->sample_interval_s",
        "time_s - s->last_t > s->sample_interval_s",
        EXPC,
        "C export: the rate buffer's gap test without GAP_FACTOR",
    ),
    Mutant(
        "piecewise-no-width-rule-no-bic",
        P + "models/piecewise.py",
        "chosen = int(np.argmin(bic)) + 1\n",
        "chosen = len(fits)\n",
        _t("models_piecewise", "cli_contract"),
        "piecewise: every asked-for breakpoint kept",
    ),
    Mutant(
        "units-deg-s-to-deg-h-60",
        P + "units.py",
        "DS_TO_DH: Final = SECONDS_PER_HOUR",
        "DS_TO_DH: Final = SECONDS_PER_MINUTE",
        _t("units", "compensate"),
        "°/s → °/h by 60 instead of 3600",
    ),
    Mutant(
        "units-earth-rate-typo",
        P + "units.py",
        "EARTH_RATE_RAD_S: Final = 7.292115e-5",
        "EARTH_RATE_RAD_S: Final = 7.292115e-4",
        _t("units", "metrics"),
        "earth rate off by a factor 10",
    ),
    Mutant(
        "allan-variance-missing-2",
        P + "stability/allan.py",
        "avar = sums / (2.0 * m.astype(np.float64) ** 2 * n_terms)",
        "avar = sums / (m.astype(np.float64) ** 2 * n_terms)",
        _t("allan"),
        "Allan variance without the 1/2",
    ),
    Mutant(
        "metrics-stability-ddof-0",
        P + "metrics.py",
        "    stab = float(np.std(means, ddof=1))",
        "    stab = float(np.std(means, ddof=0))",
        METRICS,
        "bias stability with n instead of n − 1",
    ),
    Mutant(
        "preprocess-rate-per-second",
        P + "preprocess.py",
        "            out *= SECONDS_PER_MINUTE\n",
        "",
        _t("preprocess", "models_poly"),
        "Ṫ in °C/s where °C/min is stated",
    ),
    Mutant(
        "compensate-unit-factor-inverted",
        P + "compensate/files.py",
        "y_data = y_model / plan.factor",
        "y_data = y_model * plan.factor",
        _t("compensate"),
        "model value converted to the data's unit the wrong way",
    ),
    Mutant(
        "turntable-band-ignores-noise",
        P + "turntable/schedule.py",
        "tol = 8.0 * sigma_deg + 2.0 * q + 2.0 * units.ARCSEC_TO_DEG",
        "tol = 2.0 * units.ARCSEC_TO_DEG",
        _t("turntable_encoders"),
        "dwell band not scaled to the encoder noise",
    ),
    Mutant(
        "bank-picks-worst-model",
        P + "models/bank.py",
        "choice = np.argmin(dev, axis=1)",
        "choice = np.argmax(dev, axis=1)",
        _t("models_bank"),
        "bank start-up selection takes the largest deviation",
    ),
    Mutant(
        "time-ms-as-us",
        P + "units.py",
        '{"s": 1.0, "ms": 1e-3, "us": 1e-6}',
        '{"s": 1.0, "ms": 1e-6, "us": 1e-6}',
        _t("io", "cli_inspect"),
        "milliseconds converted as microseconds",
    ),
    Mutant(
        "gap-factor-15",
        P + "recording.py",
        "GAP_FACTOR = 1.5",
        "GAP_FACTOR = 15.0",
        _t("io", "preprocess", "cli_inspect"),
        "gaps only found beyond 15 median intervals",
    ),
    Mutant(
        "warmup-window-cumsum-off-by-one",
        P + "models/warmup.py",
        "np.cumsum(x[:m]) / np.arange(1, m + 1, dtype=np.float64)",
        "np.cumsum(x[:m]) / np.arange(2, m + 2, dtype=np.float64)",
        _t("models_warmup"),
        "warm-up start window mean divided by n + 1",
    ),
    Mutant(
        "schema-accepts-short-coefficients",
        P + "models/poly.py",
        '        same_length(state, path, "coef", len(state["terms"]), "one per term")\n',
        "",
        _t("tests/cli/test_cli_attacks.py"),
        "model file with fewer coefficients than terms accepted",
    ),
    Mutant(
        "io-temporary-readable",
        P + "readers/common.py",
        "    if name.endswith(TEMP_SUFFIX):\n",
        "    if False:\n",
        _t("faults"),
        "an interrupted write's temporary accepted by the readers",
    ),
    # --- issue 27's named survivors -------------------------------------------------------
    Mutant(
        "turntable-thermal-order-margin",
        P + "turntable/thermal.py",
        "if score < best * 0.95:",
        "if score < best:",
        TT_THERMAL,
        "thermal order: a higher order taken for any gain, not 5 %",
    ),
    Mutant(
        "turntable-accel-dof",
        P + "turntable/accel.py",
        "dof = max(m - 4, 1)",
        "dof = max(m, 1)",
        TT_ACCEL,
        "accelerometer dwell fit: residual dof without the 4 unknowns",
    ),
    Mutant(
        "turntable-accel-weights",
        P + "turntable/accel.py",
        "sw = np.sqrt(w)\n",
        "sw = np.ones_like(w)\n",
        TT_ACCEL,
        "accelerometer dwell fit unweighted (samples per dwell ignored)",
    ),
    Mutant(
        "turntable-arw-units",
        P + "turntable/calibrate.py",
        "out: FloatArray = arw * units.DEG_TO_RAD / np.sqrt(units.SECONDS_PER_HOUR)",
        "out: FloatArray = arw * units.DEG_TO_RAD / units.SECONDS_PER_HOUR",
        TT_CAL,
        "given ARW [°/√h] converted with /3600 instead of /√3600",
    ),
    Mutant(
        "turntable-azimuth-quantum-sign",
        P + "turntable/calibrate.py",
        'v[6 + model.MISALIGNMENT_NAMES.index("xy")] = -1.0',
        'v[6 + model.MISALIGNMENT_NAMES.index("xy")] = 1.0',
        TT_CAL,
        "encoder quantum: azimuth variance added to yx, xy with the same sign",
    ),
    Mutant(
        "turntable-half-turn-sign",
        P + "turntable/schedule.py",
        "return 180.0 if d == -180.0 else d",
        "return -180.0 if d == -180.0 else d",
        TT_ENC,
        "schedule: a half turn goes negative",
    ),
    Mutant(
        "turntable-angle-wrap",
        P + "turntable/schedule.py",
        "return abs((a - b + 180.0) % 360.0 - 180.0) <= tol",
        "return abs(a - b) <= tol",
        TT_ENC,
        "dwell positions compared without wrapping 359.9° to 0°",
    ),
    Mutant(
        "fleet-resume-skips-failed",
        P + "fleet/batch.py",
        'if rec.get("status") != "ok":',
        'if rec.get("status") == "never":',
        FLEET,
        "a failed unit is not redone on the next run",
    ),
    Mutant(
        "fleet-limit-max-strict",
        P + "fleet/config.py",
        'value <= self.value if self.bound == "max"',
        'value < self.value if self.bound == "max"',
        FLEET,
        "a figure equal to its _max limit fails",
    ),
    Mutant(
        "fleet-limit-min-strict",
        P + "fleet/config.py",
        "else value >= self.value",
        "else value > self.value",
        FLEET,
        "a figure equal to its _min limit fails",
    ),
    Mutant(
        "fleet-nan-limit-passes",
        P + "fleet/config.py",
        "if value is None or not math.isfinite(value):\n            return False",
        "if value is None or not math.isfinite(value):\n            return True",
        FLEET,
        "a NaN figure passes its limit",
    ),
    Mutant(
        "fleet-channel-limit-everywhere",
        P + "fleet/batch.py",
        "names = [lim.channel] if lim.channel else list(figures)",
        "names = list(figures)",
        FLEET,
        "a [limits.<channel>] limit judged on every channel",
    ),
    Mutant(
        "units-counts-per-degree",
        P + "units.py",
        '"counts/deg": (True, SECONDS_PER_HOUR, "deg/h")',
        '"counts/deg": (True, SECONDS_PER_MINUTE, "deg/h")',
        UNITS,
        "pulses per degree: °/s → °/h by 60",
    ),
    Mutant(
        "text-empty-field-not-number",
        P + "readers/text.py",
        "if empty and not f:\n        return True",
        "if empty and not f:\n        return False",
        TEXT,
        "text log: a row with an empty field (missing value) is not a data row",
    ),
    Mutant(
        "params-accel-midrange-reference",
        P + "export/params.py",
        "mid = 0.5 * (lo + hi) - tref_c",
        "mid = 0.5 * (lo + hi)",
        PARAMS,
        "accelerometer offsets relative to the model at T − TREF = mid, not T = mid",
    ),
    Mutant(
        "params-ardupilot-tmin",
        P + "export/params.py",
        'out.params[p + "TMIN"] = max(out.params.get(p + "TMIN", lo), lo)',
        'out.params[p + "TMIN"] = min(out.params.get(p + "TMIN", lo), lo)',
        PARAMS,
        "ArduPilot TMIN: the lowest of the triads' ranges, not the common one",
    ),
    Mutant(
        "px4-holdout-on-training-bins",
        P + "tempcal/pipeline.py",
        "held = _cubic(t_med[even], v_med[even], unit, name)",
        "held = _cubic(t_med, v_med, unit, name)",
        PX4,
        "hold-out cubic fitted on every bin, the judged ones too",
    ),
    Mutant(
        "px4-motion-threshold",
        P + "tempcal/pipeline.py",
        "adequacy.MOTION_FLOOR_DEG_S * adequacy.DEG_H_PER_DEG_S\n",
        "adequacy.MOTION_FLOOR_DEG_S\n",
        PX4,
        "multi-IMU step check: gyro floor 0.3 °/h instead of 0.3 °/s",
    ),
    # --- turntable --------------------------------------------------------------------
    Mutant(
        "turntable-thermal-dof-off-by-one",
        P + "turntable/thermal.py",
        "dof = len(v) - (order + 1)",
        "dof = len(v) - order",
        TT_THERMAL,
        "thermal WLS: reduced χ² with one dof too many",
    ),
    Mutant(
        "turntable-thermal-chi2-floor",
        P + "turntable/thermal.py",
        "(max(chi2, 1.0) if dof > 0 else 1.0)",
        "(chi2 if dof > 0 else 1.0)",
        TT_THERMAL,
        "thermal WLS: covariance shrunk when the scatter is below the σ",
    ),
    Mutant(
        "turntable-thermal-weights-sigma",
        P + "turntable/thermal.py",
        "w = 1.0 / np.maximum(sg_k, 1e-12 * float(np.max(sg_k))) ** 2",
        "w = 1.0 / np.maximum(sg_k, 1e-12 * float(np.max(sg_k)))",
        TT_THERMAL,
        "thermal WLS weights 1/σ instead of 1/σ²",
    ),
    Mutant(
        "turntable-thermal-loto-keeps-run",
        P + "turntable/thermal.py",
        "keep = np.arange(len(v)) != i",
        "keep = np.arange(len(v)) >= 0",
        TT_THERMAL,
        "leave-one-temperature-out keeps the run it predicts",
    ),
    Mutant(
        "turntable-thermal-tref-low-end",
        P + "turntable/thermal.py",
        "tref = float(0.5 * (t.min() + t.max())) if tref_c is None",
        "tref = float(t.min()) if tref_c is None",
        TT_THERMAL,
        "thermal TREF at the coldest run, not mid-range",
    ),
    Mutant(
        "turntable-arw-tau",
        P + "turntable/calibrate.py",
        "out: FloatArray = np.sqrt(ss / dof * tau_med)",
        "out: FloatArray = np.sqrt(ss / dof / tau_med)",
        TT_CAL,
        "ARW from the rest scatter divided by τ instead of multiplied",
    ),
    Mutant(
        "turntable-arw-dof",
        P + "turntable/calibrate.py",
        "dof += g.shape[0] - 1",
        "dof += g.shape[0]",
        TT_CAL,
        "ARW: dwell scatter with n instead of n − 1",
    ),
    Mutant(
        "turntable-quantum-sigma-sqrt12",
        P + "turntable/schedule.py",
        "self.quantum_deg * units.DEG_TO_ARCSEC / np.sqrt(12.0)",
        "self.quantum_deg * units.DEG_TO_ARCSEC / 12.0",
        TT_ENC,
        "quantisation σ q/12 instead of q/√12",
    ),
    Mutant(
        "turntable-mad-scale",
        P + "turntable/schedule.py",
        "sig.append(1.4826 * float(np.median(np.abs(d2 - np.median(d2)))) / np.sqrt(6.0))",
        "sig.append(1.4826 * float(np.median(np.abs(d2 - np.median(d2)))) / np.sqrt(2.0))",
        TT_ENC,
        "encoder jitter from second differences with √2 instead of √6",
    ),
    Mutant(
        "turntable-dwell-pause-strict",
        P + "turntable/schedule.py",
        "if dur >= pause_s",
        "if dur > pause_s + 5.0",
        TT_ENC,
        "dwells shorter than pause + 5 s dropped",
    ),
    Mutant(
        "turntable-accel-bias-mg",
        P + "turntable/accel.py",
        "scale = np.array([1.0 / g, 1.0 / g, 1.0 / g, 1.0 / units.MG_TO_MS2])",
        "scale = np.array([1.0 / g, 1.0 / g, 1.0 / g, 1.0])",
        TT_ACCEL,
        "accelerometer bias left in m/s² where mg is stated",
    ),
    Mutant(
        "turntable-accel-min-dwells",
        P + "turntable/accel.py",
        "if m < 6:",
        "if m < 4:",
        TT_ACCEL,
        "accelerometer triad fitted from 4 or 5 attitudes",
    ),
    Mutant(
        "turntable-chi2-warning-threshold",
        P + "turntable/calibrate.py",
        "chi2 > 1.0 + 5.0 * np.sqrt(2.0 / est.dof)",
        "chi2 > 1.0 + 5000.0 * np.sqrt(2.0 / est.dof)",
        TT_CAL,
        "residuals far above the white-noise level not reported",
    ),
    # --- fleet -----------------------------------------------------------------------------
    Mutant(
        "fleet-missing-channel-passes",
        P + "fleet/batch.py",
        'failed.append(f"{lim.label}: no channel {ch!r}")',
        "pass",
        FLEET,
        "a limit on a channel the unit lacks passes",
    ),
    Mutant(
        "fleet-limit-options-not-compared",
        P + "fleet/batch.py",
        '("validate", "[validate]"), ("limits", "[limits]")',
        '("validate", "[validate]")',
        FLEET,
        "changed [limits] do not redo a unit",
    ),
    Mutant(
        "fleet-missing-figure-passes",
        P + "fleet/batch.py",
        'failed.append(f"{ch}.{lim.figure} {why} ({lim.label})")',
        "pass",
        FLEET,
        "a limit on a figure not computed passes",
    ),
    Mutant(
        "fleet-changed-input-ignored",
        P + "fleet/batch.py",
        "elif before[f] != digest:",
        "elif False:",
        FLEET,
        "a changed input file does not redo the unit",
    ),
    # --- units -------------------------------------------------------------------------
    Mutant(
        "units-counts-per-rad",
        P + "units.py",
        '"counts/rad": (True, RS_TO_DH, "deg/h")',
        '"counts/rad": (True, RAD_TO_DEG, "deg/h")',
        UNITS,
        "pulses per radian converted to °/s, called °/h",
    ),
    Mutant(
        "units-counts-per-g",
        P + "units.py",
        '"counts/g": (False, G_TO_MG, "mg")',
        '"counts/g": (False, 1.0, "mg")',
        UNITS,
        "LSB per g read as LSB per mg",
    ),
    Mutant(
        "units-pulse-without-tau",
        P + "units.py",
        "gain = factor / (interval_s * scale_factor)",
        "gain = factor / scale_factor * interval_s",
        UNITS,
        "pulse counts: N·τ/K instead of N/(τK)",
    ),
    Mutant(
        "units-int16-sign",
        P + "units.py",
        "v = np.where(v >= INT16_SIGN_BIT, v - UINT16_MODULUS, v)",
        "v = np.where(v > INT16_SIGN_BIT, v - UINT16_MODULUS, v)",
        UNITS,
        "int16 temperature: 32768 read as +32768, not −32768",
    ),
    Mutant(
        "units-somigliana-sign",
        P + "units.py",
        "* (1.0 + WGS84_SOMIGLIANA_K * s2)",
        "* (1.0 - WGS84_SOMIGLIANA_K * s2)",
        UNITS + GRAV,
        "normal gravity decreasing towards the poles",
    ),
    Mutant(
        "units-mg-factor",
        P + "units.py",
        "MG_TO_MS2: Final = STANDARD_GRAVITY_M_S2 * 1e-3",
        "MG_TO_MS2: Final = STANDARD_GRAVITY_M_S2 * 1e-2",
        UNITS,
        "1 mg = 0.098 m/s²",
    ),
    Mutant(
        "units-arw-per-60",
        P + "units.py",
        "ARW_DEG_SQRT_H_PER_DEG_H_SQRT_HZ: Final = 1.0 / 60.0",
        "ARW_DEG_SQRT_H_PER_DEG_H_SQRT_HZ: Final = 1.0 / 3600.0",
        UNITS + NOISE,
        "ARW °/√h from a density in °/h/√Hz divided by 3600, not 60",
    ),
    Mutant(
        "units-latitude-bound-strict",
        P + "units.py",
        "if not -90.0 <= latitude_deg <= 90.0:",
        "if not -90.0 < latitude_deg < 90.0:",
        UNITS + GRAV,
        "normal gravity refused at the poles",
    ),
    # --- text logs ---------------------------------------------------------------------
    Mutant(
        "text-header-empty-name",
        P + "readers/text.py",
        "is_names = all(f and not _is_number(f, dec) for f in names)",
        "is_names = all(not _is_number(f, dec) for f in names)",
        TEXT,
        "a header line with an empty name taken as the header",
    ),
    Mutant(
        "text-decimal-tie-comma",
        P + "readers/text.py",
        '-len(texts[c]), c == ".")',
        '-len(texts[c]), c == ",")',
        TEXT,
        "decimal mark: a tie goes to the comma",
    ),
    Mutant(
        "text-underscore-number",
        P + "readers/text.py",
        'if "_" in field or not field.isascii():',
        "if not field.isascii():",
        TEXT,
        "digit-group underscores (0_5) read as numbers",
    ),
    Mutant(
        "text-wrong-field-count-kept",
        P + "readers/text.py",
        "if len(fields) != n:",
        "if len(fields) < n:",
        TEXT,
        "a row with too many fields is not a bad line",
    ),
    # --- parameter export ------------------------------------------------------------
    Mutant(
        "params-ardupilot-tmax",
        P + "export/params.py",
        'out.params[p + "TMAX"] = min(out.params.get(p + "TMAX", hi), hi)',
        'out.params[p + "TMAX"] = max(out.params.get(p + "TMAX", hi), hi)',
        PARAMS,
        "ArduPilot TMAX: the highest of the triads' ranges",
    ),
    Mutant(
        "params-ardupilot-scale",
        P + "export/params.py",
        "poly.coef[k] / ARDUPILOT_SCALE",
        "poly.coef[k] * ARDUPILOT_SCALE",
        PARAMS,
        "ArduPilot coefficients multiplied by 1e-6 instead of divided",
    ),
    Mutant(
        "params-ardupilot-tref",
        P + "export/params.py",
        "ARDUPILOT_TREF_C = 35.0",
        "ARDUPILOT_TREF_C = 25.0",
        PARAMS,
        "ArduPilot's polynomial about 25 °C (the firmware's is 35 °C)",
    ),
    Mutant(
        "params-px4-tref-low-end",
        P + "export/params.py",
        "tref = 0.5 * (lo + hi) if tref_c is None else float(tref_c)",
        "tref = lo if tref_c is None else float(tref_c)",
        PARAMS,
        "PX4 TREF at the low end of the range, not mid-range",
    ),
    Mutant(
        "params-range-union",
        P + "export/params.py",
        "lo = max(float(m.temp_range_[0, 0]) for m in models.values())",
        "lo = min(float(m.temp_range_[0, 0]) for m in models.values())",
        PARAMS,
        "a triad's TMIN below one channel's fitted range",
    ),
    Mutant(
        "params-gyro-unit-per-minute",
        P + "export/params.py",
        'float(units.convert(1.0, model_unit, "deg/h")) * units.DH_TO_RS',
        'float(units.convert(1.0, model_unit, "deg/h")) * units.DEG_TO_RAD / 60.0',
        PARAMS,
        "°/h → rad/s by /60",
    ),
    Mutant(
        "params-accel-offset-sign",
        P + "export/params.py",
        "b[0] = 0.0 - (b[1] * mid",
        "b[0] = 0.0 + (b[1] * mid",
        PARAMS,
        "accelerometer X0 of the wrong sign",
    ),
    Mutant(
        "params-accel-x0-constant-error",
        P + "export/params.py",
        "b[0] = 0.0 - (b[1] * mid",
        "b[0] = 1.0 - (b[1] * mid",
        _t("px4_tempcal") + PARAMS,
        "accelerometer X0 off by one model unit (1 mg or 1 m/s²: the weak _removed)",
    ),
    Mutant(
        "params-px4-tmax-low",
        P + "export/params.py",
        'out.params[p + "TMAX"] = hi\n',
        'out.params[p + "TMAX"] = lo\n',
        PARAMS,
        "PX4 TMAX written as the range's low end",
    ),
    # --- px4 / ardupilot tempcal --------------------------------------------------------
    Mutant(
        "px4-baro-holdout-on-training",
        P + "tempcal/px4.py",
        "held = np.polynomial.polynomial.polyfit(x[even], v_med[even, j], order)",
        "held = np.polynomial.polynomial.polyfit(x, v_med[:, j], order)",
        PX4,
        "baro/mag hold-out fitted on every bin",
    ),
    Mutant(
        "px4-min-bins",
        P + "tempcal/pipeline.py",
        "if t_med.size < MIN_BINS:",
        "if t_med.size < 4:",
        PX4,
        "a cubic judged and fitted on 4 bins",
    ),
    Mutant(
        "px4-bin-median-to-mean",
        P + "tempcal/binning.py",
        "[np.median(values[order[a:b]], axis=0)",
        "[np.mean(values[order[a:b]], axis=0)",
        PX4,
        "bin statistic the mean: spikes move the fit",
    ),
    Mutant(
        "px4-baro-tref-low-end",
        P + "tempcal/px4.py",
        "tref = 0.5 * (lo + hi) if tref_c is None else float(tref_c)\n    x = t_med - tref",
        "tref = lo if tref_c is None else float(tref_c)\n    x = t_med - tref",
        PX4,
        "baro/mag TREF at the low end",
    ),
    Mutant(
        "px4-step-window",
        P + "tempcal/pipeline.py",
        "if not any(abs(s[0] - o[0]) <= adequacy.STILL_WINDOW_S for o in others)",
        "if not any(abs(s[0] - o[0]) <= 0.0 for o in others)",
        PX4,
        "a board move seen by every IMU reported as one IMU's bias step",
    ),
    # --- adequacy ------------------------------------------------------------------------
    Mutant(
        "adequacy-samples-strict",
        P + "adequacy.py",
        "ok = ratio >= MIN_SAMPLES_PER_COEFFICIENT",
        "ok = ratio > MIN_SAMPLES_PER_COEFFICIENT",
        ADEQ,
        "exactly 10 samples per coefficient refused",
    ),
    Mutant(
        "adequacy-span-per-order",
        P + "adequacy.py",
        "need = MIN_SPAN_PER_ORDER_C * max(order, 1)",
        "need = MIN_SPAN_PER_ORDER_C",
        ADEQ,
        "the span needed does not grow with the order",
    ),
    Mutant(
        "adequacy-distinct-order",
        P + "adequacy.py",
        "if distinct < order + 1:",
        "if distinct < order:",
        ADEQ,
        "order p fitted through p distinct temperatures",
    ),
    Mutant(
        "adequacy-rate-per-second",
        P + "adequacy.py",
        "return (temps[keep] - back) / interval_s * 60.0",
        "return (temps[keep] - back) / interval_s",
        ADEQ,
        "Ṫ for the rate test in °C/s",
    ),
    Mutant(
        "adequacy-firmware-strict",
        P + "adequacy.py",
        "ok = span_c >= minimum_c",
        "ok = span_c > minimum_c",
        ADEQ,
        "a sweep exactly at the firmware minimum refused",
    ),
    Mutant(
        "adequacy-moving-share-strict",
        P + "adequacy.py",
        "if mot.share > MAX_MOVING_SHARE:",
        "if mot.share > 10.0 * MAX_MOVING_SHARE:",
        ADEQ,
        "a record moving 2…20 % of the time accepted",
    ),
    Mutant(
        "adequacy-ends-share",
        P + "adequacy.py",
        "share = min(low, high)",
        "share = max(low, high)",
        ADEQ,
        "range ends: the better end judged",
    ),
    Mutant(
        "adequacy-robust-range-small",
        P + "adequacy.py",
        "if t.size < 1000:",
        "if t.size < 10:",
        ADEQ,
        "small records' range cut at the 0.1/99.9 percentiles",
    ),
    # --- stability -------------------------------------------------------------------------
    Mutant(
        "stability-mdev-max-factor",
        P + "stability/deviations.py",
        "return (n_phase + 1) // 3 if name",
        "return (n_phase + 4) // 3 if name",
        STAB,
        "mdev evaluated one m beyond the data",
    ),
    Mutant(
        "stability-mdev-third-difference-taps",
        P + "stability/deviations.py",
        "    u *= 3.0\n",
        "    u *= 2.0\n",
        _t("deviation_digits"),
        "MDEV's slide x_{j+3m} − 3x_{j+2m} + 3x_{j+m} − x_j with 2 for 3 (m above 4096)",
    ),
    Mutant(
        "stability-mdev-first-inner-sum",
        P + "stability/deviations.py",
        "    v = float(np.sum(first))\n",
        "    v = float(np.sum(first[1:]))\n",
        _t("deviation_digits"),
        "MDEV's first inner sum v_0 one second difference short",
    ),
    Mutant(
        "stability-totdev-reflection-sign",
        P + "stability/deviations.py",
        "v = (s[:, : 6 * m] - 2.0 * s[:, m : 7 * m] + s[:, 2 * m : 8 * m]) / m",
        "v = (s[:, : 6 * m] - 2.0 * s[:, m : 7 * m] - s[:, 2 * m : 8 * m]) / m",
        STAB,
        "total-deviation second difference S1 − 2S2 − S3",
    ),
    Mutant(
        "stability-theo1-tau",
        P + "stability/deviations.py",
        "return np.asarray(0.75 * np.asarray(m, dtype=np.float64) * tau0_s)",
        "return np.asarray(np.asarray(m, dtype=np.float64) * tau0_s)",
        STAB,
        "Theo1's τ = m τ0 instead of 0.75 m τ0",
    ),
    Mutant(
        "stability-phase-tau0",
        P + "stability/deviations.py",
        "    x *= tau0_s\n",
        "",
        STAB,
        "rate integrated to phase without τ0",
    ),
    Mutant(
        "stability-mtie-sum",
        P + "stability/deviations.py",
        "num = np.maximum(num, np.where(b > 0, a, 0.0))",
        "num = num + np.where(b > 0, a, 0.0)",
        STAB,
        "MTIE of gapped data summed over stretches instead of the maximum",
    ),
    Mutant(
        "stability-edf-white-fm",
        P + "stability/edf.py",
        "return n * (n + 1.0) / 6.0",
        "return n * (n - 1.0) / 6.0",
        STAB + NOISE,
        "B1 of random-walk FM (μ = 2, Hadamard ladder): N(N−1)/6 instead of N(N+1)/6",
    ),
    Mutant(
        "stability-mtot-sp1065",
        P + "stability/edf.py",
        "    if alpha in _MTOT_STABLE32:\n        b, c = _MTOT_STABLE32[alpha]",
        "    if alpha in _MTOT:\n        b, c = _MTOT[alpha]",
        STAB + _t("total_edf_stable32"),
        "MTOT/TTOT EDF at m ≥ 10 from SP 1065 Table 8 instead of Stable32's line",
    ),
    Mutant(
        "stability-mtot-no-greenhall",
        P + "stability/edf.py",
        "    if m < MTOT_GREENHALL_BELOW:",
        "    if m < 1:",
        STAB + _t("total_edf_stable32"),
        "MTOT/TTOT EDF below m = 10 from the line instead of Greenhall's modified-Allan EDF",
    ),
    Mutant(
        "stability-lag1-phase-detrend",
        P + "stability/edf.py",
        "        zc = z - z.mean()\n"
        "        return _lag1_differenced(lag1_autocorrelation(zc), zc, dmax, 2, rules.r1_sample)",
        "        zc = _detrend(z, 1)\n"
        "        return _lag1_differenced(lag1_autocorrelation(zc), zc, dmax, 2, rules.r1_sample)",
        STAB + _t("noise_id_stable32"),
        "lag-1 identification of phase data removes a line (Stable32 removes nothing)",
    ),
    Mutant(
        "stability-b1-no-rn",
        P + "stability/edf.py",
        '    if nid.method != "b1" or nid.alpha != 2:',
        "    if True:",
        STAB + _t("noise_id_stable32"),
        "B1's phase-noise reading not split into white and flicker PM by R(n)",
    ),
    Mutant(
        "stability-b1-rn-kept-previous",
        P + "stability/family.py",
        '        if not stable32 and nid.method == "b1" and i > 0',
        '        if not stable32 and nid.method.startswith("b1") and i > 0',
        STAB + _t("noise_id_stable32"),
        "an R(n) flicker-PM reading overridden by the shorter τ's α",
    ),
    Mutant(
        "stability-totvar-bias-ffm",
        P + "stability/family.py",
        "_TOTVAR_BIAS: Final = {-1: 1.0 / (3.0 * math.log(2.0)), -2: 0.75}",
        "_TOTVAR_BIAS: Final = {-1: 1.0 / (2.0 * math.log(2.0)), -2: 0.75}",
        STAB + _t("bias_stable32"),
        "totdev's flicker-FM bias with 1/(2 ln 2) instead of Howe's 1/(3 ln 2)",
    ),
    Mutant(
        "stability-htot-short-sp1065",
        P + "stability/edf.py",
        "    if alpha > 0 or (m < HTOT_FORMULA_FROM and alpha >= -2):",
        "    if alpha > 0 or (m < HTOT_FORMULA_FROM and alpha >= 0):",
        STAB + _t("total_edf_stable32", "bias_stable32"),
        "Htot's flicker/random-walk FM EDF below m = 16 from SP 1065's formula",
    ),
    Mutant(
        "stability-simple-wfm",
        P + "stability/edf.py",
        "4.0 * m * m / (4.0 * m * m + 5.0)",
        "4.0 * m * m / (4.0 * m * m + 2.5)",
        STAB + _t("total_edf_stable32", "bias_stable32"),
        "the simple white-FM EDF with 4m²/(4m² + 2.5)",
    ),
    Mutant(
        "stability-total-pm-no-offset",
        P + "stability/edf.py",
        "STABLE32_SIMPLE_OFFSET: Final = 2.0",
        "STABLE32_SIMPLE_OFFSET: Final = 0.0",
        STAB + _t("total_edf_stable32", "noise_type"),
        "totdev/Htot where Stable32 takes the simple EDF: without its + 2",
    ),
    Mutant(
        "stability-htot-pm-greenhall",
        P + "stability/edf.py",
        "    if alpha > 0 or (m < HTOT_FORMULA_FROM and alpha >= -2):",
        "    if m < HTOT_FORMULA_FROM and alpha >= -2:",
        STAB + _t("total_edf_stable32", "noise_type"),
        "Htot at phase noise from m = 16 by SP 1065's FM formula / Greenhall",
    ),
    Mutant(
        "stability-noise-type-ignored",
        P + "stability/analysis.py",
        "            alpha=alpha, noise_id=noise_id,\n",
        "            alpha=None, noise_id=noise_id,\n",
        STAB + _t("noise_type"),
        "allan --noise-type accepted and ignored",
    ),
    Mutant(
        "stability-s32-b1-barnes-n",
        P + "stability/edf.py",
        "    n_th = nb if n_theory is None else max(int(n_theory), 2)",
        "    n_th = nb",
        STAB + _t("noise_id_rules_stable32"),
        "--noise-id stable32: B1 judged at the number of averages, not the deviation's terms",
    ),
    Mutant(
        "stability-s32-total-min-8",
        P + "stability/edf.py",
        "STABLE32_B1_MIN_TOTAL: Final = 6",
        "STABLE32_B1_MIN_TOTAL: Final = 8",
        STAB + _t("noise_id_rules_stable32"),
        "--noise-id stable32: the total family's B1 stops at 8 averages as the Allan family's",
    ),
    Mutant(
        "stability-s32-guarded",
        P + "stability/family.py",
        '        if not stable32 and nid.method == "b1" and i > 0',
        '        if nid.method == "b1" and i > 0',
        STAB + _t("noise_id_rules_stable32"),
        "--noise-id stable32 with thermocal's bound by the shorter τ's α",
    ),
    Mutant(
        "stability-s32-record-n",
        P + "stability/family.py",
        "            b1_n = int(cnt) if math.isfinite(cnt) and cnt > 0 else sum(record.sizes) - 1",
        "            b1_n = sum(record.sizes) - 1",
        STAB + _t("noise_id_rules_stable32"),
        "--noise-id stable32: B1 at the record length for every deviation (ADEV's terms)",
    ),
    Mutant(
        "stability-s32-rate-detrended",
        P + "stability/family.py",
        "ed.IdRules(b1_n, b1_min, rate_detrend=False, r1_sample=True)",
        "ed.IdRules(b1_n, b1_min, rate_detrend=True, r1_sample=True)",
        STAB + _t("noise_id_rules_stable32"),
        "--noise-id stable32: rate averages detrended before the lag-1 method",
    ),
    Mutant(
        "text-single-column-refused",
        P + "readers/text.py",
        '            best = (0, 0, " ")',
        "            best = None",
        _t("text_single_column"),
        "a one-value-a-line text file (Stable32's) refused",
    ),
    Mutant(
        "text-comments-as-banner",
        P + "readers/text.py",
        'return tuple(x for x in lines if x.strip() and not x.lstrip().startswith("#"))',
        "return tuple(x for x in lines if x.strip())",
        _t("text_single_column"),
        "'#' comment lines before the data reported as a banner",
    ),
    Mutant(
        "reading-signal-message-lists-nothing",
        P + "pipeline/reading.py",
        "        if not names and not keep_other:",
        "        if False:",
        _t("text_single_column"),
        "the --signal message lists no columns when only the named ones were read",
    ),
    Mutant(
        "stability-s32-nonoverlapping-min-8",
        P + "stability/edf.py",
        "STABLE32_B1_MIN_NONOVERLAPPING: Final = 10",
        "STABLE32_B1_MIN_NONOVERLAPPING: Final = 8",
        STAB + _t("noise_id_rules_stable32"),
        "--noise-id stable32: ADEV/HDEV read by B1 down to 8 averages",
    ),
    Mutant(
        "stability-s32-r1-population",
        P + "stability/family.py",
        "ed.IdRules(b1_n, b1_min, rate_detrend=False, r1_sample=True)",
        "ed.IdRules(b1_n, b1_min, rate_detrend=False, r1_sample=False)",
        STAB + _t("noise_id_rules_stable32"),
        "--noise-id stable32: r1 as Riley & Greenhall print it, not Stable32's (n − 1)/n",
    ),
    Mutant(
        "stability-b1-ddof",
        P + "stability/edf.py",
        "b1 = float(np.var(ym, ddof=1)) / avar",
        "b1 = float(np.var(ym, ddof=0)) / avar",
        STAB + NOISE,
        "noise identification: B1 from the population variance",
    ),
    Mutant(
        "noise-model-walk-sqrt3",
        P + "stability/noise_model.py",
        '(1.0 if kind == "density" else math.sqrt(3.0))',
        '(1.0 if kind == "density" else 3.0)',
        NOISE,
        "random-walk read from the slope line with 3 instead of √3",
    ),
    Mutant(
        "noise-model-discrete-sqrt-dt",
        P + "stability/noise_model.py",
        'f"{_yaml_float(v / math.sqrt(dt))}"',
        'f"{_yaml_float(v * math.sqrt(dt))}"',
        NOISE,
        "discrete noise σ = density·√dt instead of /√dt",
    ),
    # --- issue 38: noise terms read where the curve follows them ----------------------------
    Mutant(
        "noise-white-stretch-slack",
        P + "stability/allan.py",
        "_STRETCH_SLACK: Final = math.log(1.01)",
        "_STRETCH_SLACK: Final = math.log(1.08)",
        H38,
        "−½ stretch admits points 8 % off its line (the filtered short τ)",
    ),
    Mutant(
        "noise-bias-minimum-factor",
        P + "stability/allan.py",
        "val = float(dev[k]) / BIAS_INSTABILITY_FACTOR",
        "val = float(dev[k]) * BIAS_INSTABILITY_FACTOR",
        H38,
        "bias instability at the minimum σ_min·0.664 instead of /0.664",
    ),
    Mutant(
        "noise-bias-minimum-edf",
        P + "stability/allan.py",
        "keep = np.asarray(edf >= BIAS_MIN_EDF)",
        "keep = np.asarray(edf >= 0.0)",
        H38,
        "minimum sought among the last points of one or two degrees of freedom",
    ),
    Mutant(
        "multipos-faces-unchecked",
        P + "multipos/accel.py",
        "        if ang > FACE_MAX_DEG:\n",
        "        if ang > 180.0:\n",
        _t(*H38_AUDIT),
        "a POSES file of another session turned into a six-face calibration",
    ),
    Mutant(
        "noise-periodic-stretch-unmasked",
        P + "stability/allan.py",
        "        free &= ~(share >= PERIODIC_CLEAN_SHARE)\n",
        "        pass\n",
        _t(*H38_AUDIT),
        "the -1/2 stretch read where a sinusoid holds a third of the Allan variance",
    ),
    Mutant(
        "noise-periodic-amplitude",
        P + "stability/periodic.py",
        "amp = math.sqrt(2.0 * power)",
        "amp = math.sqrt(power)",
        H38,
        "sinusoid amplitude from its power without the factor 2",
    ),
    Mutant(
        "noise-lattice-no-glitch",
        P + "stability/noise_model.py",
        "if off > QUANT_MAX_OFF * n or not math.isfinite(lo_k):",
        "if off > 0 or not math.isfinite(lo_k):",
        H38,
        "one glitch off the lattice hides the sensor's quantisation",
    ),
    # --- multipos ------------------------------------------------------------------------
    # the triads' calibration from arrays, and errors that name parameters
    Mutant(
        "i40c-tt-arrays-gyro-unit-ignored",
        P + "turntable/calibrate.py",
        'alpha_column="alpha", beta_column="beta", gyro_unit=gyro_unit,',
        'alpha_column="alpha", beta_column="beta", gyro_unit="deg/s",',
        ("tests/turntable/test_turntable_calibrate_arrays.py",),
        "calibrate_arrays with rad/s arrays read them as °/s",
    ),
    Mutant(
        "i40c-tt-arrays-encoders-swapped",
        P + "turntable/calibrate.py",
        'other={"alpha": alpha, "beta": beta},',
        'other={"alpha": beta, "beta": alpha},',
        ("tests/turntable/test_turntable_calibrate_arrays.py",),
        "calibrate_arrays takes the outer encoder for the inner one",
    ),
    Mutant(
        "i40c-coefficient-rows-units",
        P + "turntable/model.py",
        'unit = (bias_unit,) * 3 + ("ppm",) * 3 + ("arcsec",) * 6',
        'unit = (bias_unit,) * 3 + ("arcsec",) * 3 + ("ppm",) * 6',
        ("tests/docs/test_tutorial_notebook_multipos.py",),
        "a triad's table shows scale factors in ″ and misalignments in ppm",
    ),
    Mutant(
        "i40c-parameter-error-others-unnamed",
        P + "errors.py",
        'text = text.replace("{" + p + "}", other(p) if other is not None else p)',
        'text = text.replace("{" + p + "}", p)',
        ("tests/core/test_gravity_parameters.py", "tests/core/test_gravity_tref.py"),
        "--gravity without --gravity-axis: the command line names gravity_axis, no option",
    ),
    Mutant(
        "multipos-gap-factor",
        P + "multipos/gyro.py",
        "GAP_FACTOR: float = 1.5",
        "GAP_FACTOR: float = 15.0",
        MULTI,
        "multi-position: a turn across a gap of 10 samples integrated",
    ),
    Mutant(
        "multipos-turn-sense",
        P + "multipos/gyro.py",
        "sense = 1.0 if float(tot[tn.axis]) >= 0 else -1.0",
        "sense = 1.0",
        MULTI,
        "multi-position: a turn the other way taken positive",
    ),
    Mutant(
        "multipos-turn-named-axis",
        P + "multipos/calibrate.py",
        'j = "xyz".index(tr.name[0])',
        "j = 2",
        (*MULTI, "tests/multipos/test_multipos_imucal.py"),
        "multi-position: every named turn taken about z (issue 38's bug: the last face's axis)",
    ),
    Mutant(
        "multipos-turn-axis-check",
        P + "multipos/gyro.py",
        "if off > TURN_AXIS_TOLERANCE_DEG:",
        "if off > 180.0:",
        (*MULTI, "tests/multipos/test_multipos_imucal.py"),
        "multi-position: a turn about another axis than its name accepted",
    ),
    Mutant(
        "multipos-turn-angle-check",
        P + "multipos/gyro.py",
        "if abs(ang / (2.0 * math.pi) - 1.0) > TURN_ANGLE_TOLERANCE:",
        "if abs(ang / (2.0 * math.pi) - 1.0) > 0.6:",
        (*MULTI, "tests/multipos/test_multipos_imucal.py"),
        "multi-position: half a turn taken for a full one",
    ),
    Mutant(
        "multipos-turn-lean-ignored",
        P + "multipos/gyro.py",
        "rot, e = _turn_axis_scatter(rot, e, bias_rad_s, up, max_iter)",
        "rot, e = rot, e",
        (*MULTI, "tests/multipos/test_multipos_sigma.py", "tests/multipos/test_multipos_imucal.py"),
        "multi-position: a hand's turn taken exactly about its axis (misalignment σ 5× small)",
    ),
    Mutant(
        "multipos-gyro-plausible",
        P + "multipos/calibrate.py",
        "if abs(th[3 + i] * units.PPM) > GYRO_E_PLAUSIBLE]",
        "if abs(th[3 + i] * units.PPM) > 1.0]",
        (*MULTI, "tests/multipos/test_multipos_imucal.py"),
        "multi-position: a gyro scale factor of +25 % not warned of",
    ),
    Mutant(
        "multipos-rotation-angle",
        P + "multipos/geometry.py",
        "(np.trace(m, axis1=-2, axis2=-1) - 1.0) / 2.0",
        "(np.trace(m, axis1=-2, axis2=-1) - 1.0) / 3.0",
        MULTI,
        "rotation angle from the trace with /3",
    ),
    Mutant(
        "multipos-bias-cov-dropped",
        P + "multipos/gyro.py",
        "c_sys = jb @ bias_cov @ jb.T + ga @ accel_free_cov @ ga.T",
        "c_sys = ga @ accel_free_cov @ ga.T",
        (*MULTI, "tests/multipos/test_multipos_sigma.py"),
        "gyro scale σ without the bias uncertainty",
    ),
    Mutant(
        "multipos-poses-noise-only",
        P + "multipos/poses.py",
        "by_motion = motion_fraction * motion",
        "by_motion = 0.0 * motion",
        ("tests/multipos/test_multipos_real_sessions.py",),
        "pose detector: the still limit from the noise alone (hand-held poses lost: 4 of 10)",
    ),
    Mutant(
        "multipos-misfit-weights-off",
        P + "multipos/accel.py",
        "for _ in range(MISFIT_ITERATIONS):",
        "for _ in range(0):",
        ("tests/multipos/test_multipos_real_sessions.py",),
        "misfit sensor fitted with its white-noise weights (imu_tk's Xsens: 1.09× the residual)",
    ),
    Mutant(
        "multipos-six-face-bias-noise-only",
        P + "multipos/accel.py",
        "np.var(pairs, axis=0, ddof=1) / 3.0",
        "0.0 * np.var(pairs, axis=0, ddof=1)",
        ("tests/multipos/test_multipos_six_face_sigma.py",),
        "six-face bias σ from the white noise alone (faces set a degree off: z-rms ≈ 140)",
    ),
    Mutant(
        "multipos-offset-ignored",
        P + "pipeline/multipos.py",
        "        return float(given)\n",
        "        return 0.0\n",
        ("tests/multipos/test_multipos_real_sessions.py",),
        "--accel-offset/--gyro-offset ignored (unsigned counts: 1 distinct pose)",
    ),
    Mutant(
        "multipos-saturated-motions-kept",
        P + "multipos/gyro.py",
        "motions = unsaturated(motions, saturated)",
        "motions = unsaturated(motions, None)",
        ("tests/multipos/test_multipos_real_sessions.py",),
        "motions across clipped gyro samples integrated into the gyro fit",
    ),
    Mutant(
        "inspect-saturation-unreported",
        P + "inspection.py",
        "            problems.extend(_saturation_problems(name, arr))",
        "            pass",
        ("tests/multipos/test_multipos_real_sessions.py",),
        "inspect says nothing of samples on the int16 rails",
    ),
    Mutant(
        "multipos-poses-drift-off",
        P + "multipos/poses.py",
        "        if turn > drift_deg:",
        "        if turn > 1e9 * drift_deg:",
        ("tests/multipos/test_multipos_real_sessions.py",),
        "pose detector: a slow 10° turn taken as a pose",
    ),
    Mutant(
        "multipos-poses-tremor-unexplained",
        P + "multipos/poses.py",
        "    rejected += _tremor(ratio, poses, rejected, min_n)",
        "    rejected += _tremor(ratio, poses, rejected, min_n)[:0]",
        ("tests/multipos/test_multipos_real_sessions.py",),
        "pose detector: stretches lost to tremor not reported",
    ),
    Mutant(
        "multipos-offset-not-in-bias",
        P + "pipeline/multipos.py",
        "    if acc_off_mg == 0.0 and gyr_off_deg_h == 0.0:",
        "    if True:",
        ("tests/multipos/test_multipos_real_sessions.py",),
        "--accel-offset removed before the fit but not put back into the biases",
    ),
    Mutant(
        "multipos-gyro-scale-model-all-nine",
        P + "multipos/gyro.py",
        '"scale": (0, 4, 8)}',
        '"scale": tuple(range(9))}',
        ("tests/multipos/test_multipos_real_sessions.py",),
        "--gyro-model scale fits the misalignments too (MPU held-out turn 6.96°)",
    ),
    Mutant(
        "multipos-too-few-motions-redundancy",
        P + "multipos/gyro.py",
        "return nu < len(GYRO_MODELS[fit.model]) and significant",
        "return nu < 3 and significant",
        ("tests/multipos/test_multipos_real_sessions.py",),
        "6 motions for 9 gyro elements (3 dof, χ² 704) not warned of",
    ),
    # --- station -----------------------------------------------------------------------------
    Mutant(
        "station-part-rotation-strict",
        P + "station/recorder.py",
        "if now_unix - self.part_started >= self.cfg.part_s:",
        "if now_unix - self.part_started > 2.0 * self.cfg.part_s:",
        STATION,
        "recorder parts closed after twice their length",
    ),
    Mutant(
        "station-unit-id-range",
        P + "station/config.py",
        "if not 0 <= c.unit <= 247:",
        "if not 0 <= c.unit <= 255:",
        STATION,
        "Modbus slave id 248…255 accepted",
    ),
    Mutant(
        "station-register-range",
        P + "station/config.py",
        "if not 0 <= getattr(c, key) <= 0xFFFF:",
        "if not 0 <= getattr(c, key) <= 0x1FFFF:",
        STATION,
        "register address beyond 65535 accepted",
    ),
    Mutant(
        "station-positive-interval",
        P + "station/config.py",
        "    if not v > 0:\n",
        "    if not v >= 0:\n",
        STATION,
        "a zero interval/period accepted",
    ),
    Mutant(
        "station-newer-version",
        P + "readers/station.py",
        "if version > STATION_VERSION:",
        "if False:",
        STATION,
        "a station folder of a newer format read",
    ),
    Mutant(
        "station-sighup-not-caught",
        P + "cli/station_cmd.py",
        'STOP_SIGNALS = ("SIGINT", "SIGTERM", "SIGHUP")',
        'STOP_SIGNALS = ("SIGINT", "SIGTERM")',
        ST_ATT,
        "a hang-up kills the run: chamber left at the program's set-point, open part lost",
    ),
    Mutant(
        "station-log-on-closed-stderr-raises",
        P + "station/run.py",
        "            self.broken = say(message)",
        "            print(message, file=sys.stderr, flush=True)",
        ST_ATT,
        "a closed stderr raises BrokenPipeError in the safe stop; the open part never closed",
    ),
    Mutant(
        "station-resume-first-setpoint",
        P + "station/run.py",
        'last_sp = float(ev["setpoint_c"])',
        'last_sp = float(ev["setpoint_c"]) if last_sp is None else last_sp',
        ST_ATT,
        "--resume reports the first set-point written, not where a killed run left the chamber",
    ),
    Mutant(
        "station-reading-range-unchecked",
        P + "station/chamber.py",
        "why = self.cfg.out_of_range(value, self.cfg.tolerance_c)",
        'why = ""',
        ST_ATT,
        "a register reading 0x8000 (-3276.8 °C) taken as the chamber's temperature",
    ),
    Mutant(
        "station-program-range-first-only",
        P + "station/run.py",
        "for t, c in zip(t_prog, c_prog, strict=True):  # before anything is written",
        "for t, c in zip(t_prog[:1], c_prog[:1], strict=True):",
        ST_ATT,
        "only the program's first set-point checked against the chamber's range",
    ),
    Mutant(
        "station-safe-range-wide",
        P + "station/config.py",
        "SAFE_RANGE_C = (0.0, 50.0)",
        "SAFE_RANGE_C = (0.0, 100.0)",
        ST_ATT,
        "a 90 °C safe set-point accepted",
    ),
    Mutant(
        "station-hold-reached-sign",
        P + "station/run.py",
        "if not reached and abs(self.chamber_c - sp) <= self.ch_cfg.tolerance_c:",
        "if not reached and abs(self.chamber_c - sp) >= self.ch_cfg.tolerance_c:",
        ST_ATT,
        "a hold counted as reached when the chamber is far from it",
    ),
    Mutant(
        "station-reply-function-code-unchecked",
        P + "station/chamber.py",
        "if got != code:",
        "if got is None:",
        ST_ATT,
        "a reply to another function code read as the temperature",
    ),
    Mutant(
        "station-lock-shared",
        P + "station/recorder.py",
        "fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)",
        "fcntl.flock(fd, fcntl.LOCK_SH | fcntl.LOCK_NB)",
        ST_ATT,
        "two runs write one folder (a shared lock)",
    ),
    Mutant(
        "station-failed-start-kept",
        P + "station/run.py",
        "        loop.abandon()\n        raise\n",
        "        raise\n",
        ST_ATT,
        "a failed start leaves station.json: the corrected command is refused",
    ),
    Mutant(
        "station-resume-units-unchecked",
        P + "station/recorder.py",
        'RESUME_SENSOR_KEYS = ("names", "units", "delimiter", "decimal", "rate_hz")',
        'RESUME_SENSOR_KEYS = ("names", "delimiter", "decimal", "rate_hz")',
        ST_ATT,
        "--resume with other units accepted: the folder read in the new unit",
    ),
    Mutant(
        "station-clock-ratio-wide",
        P + "station/run.py",
        "CLOCK_RATIO = (0.8, 1.25)",
        "CLOCK_RATIO = (0.01, 100.0)",
        ST_ATT,
        "rate_hz 20× off the sensor's line rate passes the host-clock check",
    ),
    Mutant(
        "station-inf-accepted",
        P + "station/sensors.py",
        "if not math.isfinite(value):",
        "if math.isnan(value):",
        ST_ATT,
        "inf and 1e999 lines recorded as good samples",
    ),
    Mutant(
        "station-overlong-line-not-skipped",
        P + "station/sensors.py",
        'buf, skipping = b"", True',
        'buf, skipping = b"", False',
        ST_ATT,
        "a 10 MB line kept in bad.txt as 4 KB pieces (every byte)",
    ),
    Mutant(
        "station-part-write-error-raw",
        P + "station/recorder.py",
        "                self._failed(tmp, exc)\n",
        "                raise\n",
        ST_ATT,
        "a full disk while closing a part: exit 1 without the file's name",
    ),
    Mutant(
        "station-live-display-hangup-raises",
        P + "station/display.py",
        "highlight=False)\n        except (OSError, ValueError) as exc:",
        "highlight=False)\n        except ValueError as exc:",
        ST_ATT,
        "the live display raises on a terminal gone: the safe stop aborted, exit 1",
    ),
    Mutant(
        "station-beyond-any-sensor-signed",
        P + "station/run.py",
        "if abs(values[i]) > lim:",
        "if values[i] > lim:",
        ST_ATT,
        "-3e4 deg/s recorded as a sample (only positive values checked)",
    ),
    Mutant(
        "station-resume-overwrites-last-part",
        P + "station/recorder.py",
        "nxt[s] = max(nxt.get(s, 0), i + 1)",
        "nxt[s] = max(nxt.get(s, 0), i)",
        ST_ATT,
        "--resume writes its first part over the recording's last",
    ),
    Mutant(
        "station-resume-rate-time-from-zero",
        P + "station/run.py",
        "anchor = anchors.setdefault(cfg.id, host - index / cfg.rate_hz)",
        "anchor = anchors.setdefault(cfg.id, -index / cfg.rate_hz)",
        ST_ATT,
        "the rate time re-anchored at 0 by each run: time restarts on --resume",
    ),
    Mutant(
        "station-resume-setpoints-unchecked",
        P + "station/recorder.py",
        "] != [float(x) for x in program[1]]:",
        "] != [float(x) for x in program[1]] and False:",
        ST_ATT,
        "--resume with other set-points at the same times accepted",
    ),
    Mutant(
        "station-no-stderr-prints-on-stdout",
        P + "station/run.py",
        '    if sys.stderr is None:\n        return ""\n',
        "",
        ST_ATT,
        "started with 2>&-, the run's messages land in the --json output on stdout",
    ),
    Mutant(
        "station-parts-signal-units-uncompared",
        P + "readers/station.py",
        'for role in ("signals", "temperatures", "units"):',
        'for role in ("temperatures", "units"):',
        ST_ATT,
        "parts with deg/s and rad/s concatenated and read in the last part's unit",
    ),
    # --- readers: ULog / DataFlash --------------------------------------------------------
    Mutant(
        "ulog-delta-dt-us",
        P + "readers/ulog.py",
        "dt_s = cols[dt_col] * 1e-6",
        "dt_s = cols[dt_col] * 1e-3",
        FC,
        "ULog vehicle_imu: Δt in ms, rates 1000× too small",
    ),
    Mutant(
        "ulog-time-unit",
        P + "readers/ulog.py",
        '"time": "timestamp", "time_unit": "us"',
        '"time": "timestamp", "time_unit": "ms"',
        FC,
        "ULog timestamps read as milliseconds",
    ),
    # --- triad validation and report on raw counts (issue 38) ------------------------------
    Mutant(
        "triad-count-scale-divided",
        P + "models/calibration.py",
        "return x * self.count_scale",
        "return x / self.count_scale",
        _t("triad_validate_counts"),
        "validate: raw counts divided by the count scale",
    ),
    Mutant(
        "triad-one-pose-after-raw",
        P + "multipos/validate.py",
        'ma = units.convert(xg_c[pose.start : pose.end].mean(axis=0), "rad/s", unit)',
        'ma = units.convert(xg[pose.start : pose.end].mean(axis=0), "rad/s", unit)',
        _t("triad_validate_counts"),
        "one still pose: the gyro's rate at rest after = before",
    ),
    Mutant(
        "triad-report-bias-as-stored",
        P + "report/triads.py",
        'if f.name.startswith("bias") and f.unit != tri.unit:',
        'if f.name.startswith("bias") and f.unit == tri.unit:',
        _t("report_triads"),
        "triad report: a deg/s gyro's bias shown in deg/h",
    ),
    Mutant(
        "triad-report-one-temperature-plotted",
        P + "report/triads.py",
        "over_t = len(temps) >= 2",
        "over_t = len(temps) >= 1",
        _t("report_triads"),
        "triad report: one temperature plotted against temperature",
    ),
    # --- C export -----------------------------------------------------------------------
    Mutant(
        "c-triad-clamp-swapped",
        P + "export/c/triad.py",
        "temp_c < {P}_T_LO ? {P}_T_LO : (temp_c > {P}_T_HI ? {P}_T_HI : temp_c)",
        "temp_c < {P}_T_LO ? {P}_T_HI : (temp_c > {P}_T_HI ? {P}_T_LO : temp_c)",
        EXPC,
        "C triad: below the range clamped to the top and vice versa",
    ),
    Mutant(
        "c-triad-bias-sign",
        P + "export/c/triad.py",
        '"    r[1] = (double)x[1] - th[1] * {P}_BIAS_TO_DATA;"',
        '"    r[1] = (double)x[1] + th[1] * {P}_BIAS_TO_DATA;"',
        EXPC,
        "C triad: y bias added instead of subtracted",
    ),
    Mutant(
        "c-triad-scale-ppm",
        P + "export/c/triad.py",
        '"    m[1][1] = 1.0 + th[4] * 1e-6;"',
        '"    m[1][1] = 1.0 + th[4] * 1e-3;"',
        EXPC,
        "C triad: y scale factor read in ppt, not ppm",
    ),
    Mutant(
        "c-triad-horner-order",
        P + "export/c/triad.py",
        "for (j = {order - 2}; j >= 0; --j)",
        "for (j = {order - 2}; j > 0; --j)",
        EXPC,
        "C triad: the constant coefficient left out of Horner's scheme",
    ),
    # --- compensate kernels --------------------------------------------------------------
    Mutant(
        "compensate-worse-strict",
        P + "compensate/kernels.py",
        "if finite and a > (1.0 + tolerance) * b:",
        "if finite and a > (1.0 + 10.0 * tolerance) * b:",
        COMP,
        "a worse absolute rms not reported within 10× the tolerance",
    ),
    Mutant(
        "compensate-abs-rms-about-mean",
        P + "compensate/kernels.py",
        "float(np.sqrt(np.mean(e * e)))",
        "float(np.std(e))",
        COMP,
        "rms about zero computed about the mean",
    ),
    Mutant(
        "compensate-counts-tau-default",
        P + "compensate/kernels.py",
        "return float(phys_per_count) * unit_factor(phys_unit, mu, where=where)",
        "return float(phys_per_count) / unit_factor(phys_unit, mu, where=where)",
        COMP + _t("export_c_units"),
        "counts → model unit: second factor inverted",
    ),
    Mutant(
        "compensate-stream-known-input-sign",
        P + "compensate/kernels.py",
        "float(signal) - self.known_input))",
        "float(signal) + self.known_input))",
        COMP + _t("models_bank", "calibration_stream"),
        "streaming: the known input added instead of removed",
    ),
    # --- gravity, identifiers, outputs ------------------------------------------------------
    Mutant(
        "gravity-placement-tolerance",
        P + "gravity.py",
        "if float(np.dot(d, s / np.linalg.norm(s))) >= cos_tol:",
        "if float(np.dot(d, s / np.linalg.norm(s))) >= -1.0:",
        GRAV,
        "every run joins the first placement whatever its direction",
    ),
    Mutant(
        "gravity-tilt-clamp",
        P + "gravity.py",
        "return math.degrees(math.acos(max(-1.0, min(1.0, c))))",
        "return math.degrees(math.asin(max(-1.0, min(1.0, c))))",
        GRAV,
        "tilt from asin instead of acos",
    ),
    Mutant(
        "identifiers-length-hash",
        P + "identifiers.py",
        "if len(s) > max_len:",
        "if len(s) > max_len + 8:",
        IDS,
        "C identifiers up to 8 characters too long",
    ),
    Mutant(
        "identifiers-printable-range",
        P + "identifiers.py",
        "elif 0x20 <= b < 0x7F:",
        "elif 0x20 <= b <= 0x7F:",
        IDS,
        "DEL written raw inside a C string",
    ),
    Mutant(
        "outputs-fifo-accepted",
        P + "outputs.py",
        '(stat.S_ISFIFO, "a FIFO"),',
        '(stat.S_ISREG, "a FIFO"),',
        OUTS,
        "output gate: a FIFO taken for a file (and every plain file refused)",
    ),
    Mutant(
        "outputs-file-over-directory",
        P + "outputs.py",
        'raise ThermocalInputError(f"{f}: is a directory, expected a file name")',
        "pass",
        OUTS,
        "output gate: a directory accepted as an output file name",
    ),
    # --- models, metrics, preprocess --------------------------------------------------------
    Mutant(
        "metrics-drift-trapezoid",
        P + "metrics.py",
        "inc = 0.5 * (e[1:] + e[:-1]) * np.diff(t) / float(time_unit_s)",
        "inc = e[1:] * np.diff(t) / float(time_unit_s)",
        METRICS,
        "drift angle by the right-hand rectangle rule",
    ),
    Mutant(
        "metrics-drift-reference-earth",
        P + "metrics.py",
        "b0 = float(np.mean(selected)) - float(earth_rate)",
        "b0 = float(np.mean(selected))",
        METRICS,
        "drift reference bias keeps the earth rate",
    ),
    Mutant(
        "metrics-drift-ref-window-end",
        P + "metrics.py",
        "key=lambda i: bool(t[i] - t0 > end))",
        "key=lambda i: bool(t[i] - t0 >= 2.0 * end))",
        METRICS,
        "drift reference window twice as long as asked",
    ),
    Mutant(
        "preprocess-centred-half",
        P + "preprocess.py",
        'lo = np.searchsorted(ts, ti - interval_s / 2.0, side="left")',
        'lo = np.searchsorted(ts, ti - interval_s, side="left")',
        _t(*MATHS, "preprocess"),
        "centred Ṫ over 1.5 Δ",
    ),
    # issue 38, reports and messages (h38-reports)
    Mutant(
        "report-average-fallback-two",
        P + "report/analysis.py",
        ">= MIN_FALLBACK_AVERAGES]",
        ">= 2]",
        _t("tempcal_averages", "metrics_averages"),
        "a short record's fallback averaging time gives only two averages",
    ),
    Mutant(
        "metrics-average-advice-whole-record",
        P + "metrics.py",
        "{option} {longest_s / 2.0:.3g} or less",
        "{option} {longest_s:.3g} or less",
        _t("tempcal_averages", "metrics_averages"),
        "the advised --average is the whole record (one average), not half",
    ),
    Mutant(
        "export-c-known-input-wrong-way",
        P + "export/c/core.py",
        "units.convert([value], unit, su)",
        "units.convert([value], su, unit)",
        _t("export_c_readable"),
        "the header's known input converted the wrong way (deg/h shown as deg/s)",
    ),
    Mutant(
        "report-drift-after-raw",
        P + "report/build.py",
        "(main.after_raw, None)",
        "(main.after_raw, 0.0)",
        _t("report"),
        "the after drift angle with nothing removed against a bias-removed before",
    ),
    Mutant(
        "report-no-change-never",
        P + "report/build.py",
        "abs(a - b) <= NO_CHANGE_REL",
        "abs(a - b) < 0.0 * NO_CHANGE_REL",
        _t("report"),
        "equal figures shown as a percentage of rounding",
    ),
    Mutant(
        "piecewise-segments-judged-on-the-first",
        P + "models/piecewise.py",
        "parts[k].append(x[idx == k])",
        "parts[k].append(x[idx == 0])",
        _t("piecewise_segments"),
        "every segment judged on the first segment's samples",
    ),
    Mutant(
        "piecewise-segment-advice-ignores-breakpoints",
        P + "models/piecewise.py",
        "given=self.breakpoints is not None,",
        "given=False,",
        _t("piecewise_segments"),
        "breakpoints given, the refusal advises --segments instead of moving them",
    ),
    Mutant(
        "report-coverage-gap-whole-step",
        P + "report/analysis.py",
        "sum(g.length_s - tau0_s for g in gaps)",
        "sum(g.length_s for g in gaps)",
        _t("report_calibration"),
        "a gap counted as the whole step, its last sample interval included",
    ),
    Mutant(
        "readers-counter-rate",
        P + "readers/text.py",
        "out: FloatArray = counts / float(rate_hz)",
        "out: FloatArray = counts * (1.0 / float(rate_hz) + 1e-6)",
        H38R,
        "a sample counter's time off by 1e-6 s a sample",
    ),
    Mutant(
        "readers-lost-sample-jump",
        P + "recording.py",
        "n_lost = round(rise)",
        "n_lost = rise",
        H38R,
        "lost samples not rounded to whole periods",
    ),
    Mutant(
        "readers-lost-window-earlier",
        P + "recording.py",
        "rise = float(jump[j]) - earlier",
        "rise = float(jump[j])",
        H38R,
        "a lost sample counted again at every step of the latency window",
    ),
    Mutant(
        "readers-jitter-half-range",
        P + "recording.py",
        "float(p95 - p5) / (2.0 * med)",
        "float(p95 - p5) / med",
        H38R,
        "jitter as the whole 5–95 % range, not its half",
    ),
    Mutant(
        "readers-text-column-share",
        P + "readers/text.py",
        ">= TEXT_COLUMN_SHARE * len(mixed)",
        ">= 0.0 * len(mixed)",
        H38R,
        "every field taken for a text column",
    ),
    Mutant(
        "readers-lost-late-sample",
        P + "recording.py",
        "and o[j + 1] - q[j] - earlier > n_lost - LOST_SAMPLE_JUMP / 2:",
        ":",
        H38R,
        "a late sample before a loss (or at the end) taken for the loss",
    ),
    Mutant(
        "readers-stamps-kept",
        P + "readers/dispatch.py",
        "out, lost = nominal_time(t, rate_hz)",
        "out, lost = t, 0",
        H38R,
        "--rate on host timestamps keeps the jittery stamps",
    ),
    Mutant(
        "readers-t-is-time",
        P + "readers/common.py",
        'return name.strip() == "T" or TEMPERATURE_NAME',
        "return TEMPERATURE_NAME",
        H38R,
        "a capital T taken for time",
    ),
    # issue 39 slice h39-bounds
    Mutant(
        "bounds-work-never-checked",
        P + "stability/family.py",
        "if total > max_work:",
        "if False:",
        WORK_BOUNDS,
        "the family's work estimate computed and never compared with the budget",
    ),
    Mutant(
        "bounds-work-total-points",
        P + "stability/deviations.py",
        '{"mtotdev": 90.0,',
        '{"mtotdev": 10.0,',
        WORK_BOUNDS,
        "the total family's 9m extended points counted as m",
    ),
    Mutant(
        "bounds-work-subsequences",
        P + "stability/deviations.py",
        "subs = np.maximum(pts - 3.0 * big + 1.0, 0.0)",
        "subs = np.maximum(pts - 3.0 * big, 0.0)",
        WORK_BOUNDS,
        "one subsequence per factor left out of the estimate (N − 3m, not N − 3m + 1)",
    ),
    Mutant(
        "bounds-work-theo1-lags",
        P + "stability/deviations.py",
        "(even / 2.0) * (n - even)",
        "even * (n - even)",
        WORK_BOUNDS,
        "Theo1's m/2 lags counted as m",
    ),
    Mutant(
        "bounds-work-budget-inclusive",
        P + "stability/family.py",
        "if total > max_work:",
        "if total >= max_work * 0.99:",
        WORK_BOUNDS,
        "a request within the budget refused",
    ),
    Mutant(
        "bounds-fleet-unit-files-unchecked",
        P + "fleet/config.py",
        'refuse_special_input(base / f, f"data file of unit {uid}")',
        "None",
        WORK_BOUNDS,
        "a FIFO as a unit's modelling file reaches the hash and the reader (a hang)",
    ),
    Mutant(
        "bounds-special-input-no-fifo",
        P + "outputs.py",
        '(stat.S_ISFIFO, "a FIFO"),',
        '(stat.S_ISDIR, "a FIFO"),',
        WORK_BOUNDS,
        "FIFOs not recognised as special files",
    ),
    Mutant(
        "bounds-compensate-special-unchecked",
        P + "compensate/files.py",
        "    refuse_special_input(path)\n    if path.stat().st_size == 0:",
        "    if path.stat().st_size == 0:",
        WORK_BOUNDS,
        "compensate opens a FIFO given as its recording",
    ),
    Mutant(
        "bounds-model-file-special-unchecked",
        P + "models/filecheck.py",
        "refuse_special_input(p, what)",
        "None",
        WORK_BOUNDS,
        "a FIFO given as a model file is opened",
    ),
    Mutant(
        "bounds-line-exact-refused",
        P + "readers/text.py",
        'and not (len(line) == limit + 1 and line.endswith("\\n"))',
        "",
        WORK_BOUNDS,
        "a line of exactly the bound (plus its line end) refused",
    ),
    Mutant(
        "bounds-line-data-rows-unbounded",
        P + "readers/text.py",
        "while line := bounded_line(fh, path, lineno + 1, limit):",
        "while line := fh.readline():",
        WORK_BOUNDS,
        "the data rows read without the line bound (only the layout lines bounded)",
    ),
    Mutant(
        "bounds-line-head-unbounded",
        P + "readers/text.py",
        'return [bounded_line(fh, path, k, limit).rstrip("\\r\\n") for k in',
        'return [fh.readline().rstrip("\\r\\n") for k in',
        WORK_BOUNDS,
        "the layout lines read without the bound (a 10 MB line split field by field)",
    ),
    Mutant(
        "bounds-scheduler-port-range",
        P + "fleet/batch.py",
        "not 1 <= port <= 65535",
        "not 0 <= port",
        WORK_BOUNDS,
        "a scheduler port beyond 65535 handed to Dask (its ValueError: exit 1)",
    ),
    Mutant(
        "bounds-worker-memory-share",
        P + "fleet/batch.py",
        "WORKER_MEMORY_SHARE: Final = 0.5",
        "WORKER_MEMORY_SHARE: Final = 5.0",
        WORK_BOUNDS,
        "a unit allowed more memory than its Dask worker has",
    ),
    Mutant(
        "bounds-killed-worker-stops-batch",
        P + "fleet/batch.py",
        "yield lost_unit(task_of[fut.key], exc)",
        "raise",
        WORK_BOUNDS,
        "a worker's death stops the batch, its unit lost and its file never named",
    ),
    Mutant(
        "bounds-memory-budget-ignored",
        P + "readers/common.py",
        "return budget if base is None else min(base, budget)",
        "return base",
        WORK_BOUNDS,
        "the worker's memory budget set and never applied",
    ),
    Mutant(
        "bounds-dask-logs-parent-only",
        P + "fleet/batch.py",
        'for n in ("distributed", "tornado", *logging.root.manager.loggerDict)',
        'for n in ("distributed", "tornado")',
        WORK_BOUNDS,
        "Dask's child loggers with their own level (distributed.client) left talking",
    ),
    Mutant(
        "bounds-dynamic-unchecked",
        P + "stability/allan.py",
        "if work > max_work:",
        "if False:",
        WORK_BOUNDS,
        "the dynamic ADEV's windows counted and never compared with the budget",
    ),
    Mutant(
        "bounds-dynamic-window-cost",
        P + "stability/allan.py",
        "DYNAMIC_WINDOW_WORK: Final = 1.5e7",
        "DYNAMIC_WINDOW_WORK: Final = 1.5e6",
        WORK_BOUNDS,
        "a dynamic-ADEV window's fixed cost taken ten times too small",
    ),
    Mutant(
        "bounds-dynamic-step",
        P + "stability/allan.py",
        "step = max(1, round(window_s / 2.0 / tau0_s))",
        "step = max(1, round(window_s / tau0_s))",
        WORK_BOUNDS,
        "the windows counted a whole window apart (they are half a window apart)",
    ),
    Mutant(
        "bounds-memory-share",
        P + "readers/common.py",
        "MEMORY_SHARE = 0.5",
        "MEMORY_SHARE = 0.9",
        WORK_BOUNDS,
        "a read allowed 90 % of the available memory (a 3e8-row Parquet passed)",
    ),
    Mutant(
        "bounds-memory-limit-zero",
        P + "readers/common.py",
        "if value <= 0:",
        "if value < 0:",
        WORK_BOUNDS,
        "THERMOCAL_MEMORY_LIMIT=0 (or nan, inf) taken as a limit of 0 bytes",
    ),
    Mutant(
        "bounds-dataflash-special-unchecked",
        P + "readers/dataflash.py",
        'refuse_special_input(p, "DataFlash log")',
        "None",
        WORK_BOUNDS,
        "a FIFO given as a DataFlash log handed to pymavlink (a hang)",
    ),
    Mutant(
        "bounds-columns-unbounded",
        P + "readers/text.py",
        "MAX_COLUMNS = 10_000",
        "MAX_COLUMNS = 10_000_000",
        WORK_BOUNDS,
        "a table of 300 000 columns handed to pandas (minutes)",
    ),
    Mutant(
        "bounds-columns-swallowed-read",
        P + "readers/dispatch.py",
        "except TooManyColumnsError as exc:",
        "except ZeroDivisionError as exc:",
        WORK_BOUNDS,
        "the column bound's refusal swallowed by the reader (pandas reads it as one column)",
    ),
    Mutant(
        "bounds-columns-swallowed-compensate",
        P + "readers/text.py",
        "except TooManyColumnsError as exc:",
        "except ZeroDivisionError as exc:",
        WORK_BOUNDS,
        "the column bound's refusal swallowed by compensate's chunk options",
    ),
    Mutant(
        "bounds-theo1-noise-at-m",
        P + "stability/family.py",
        "mm = max(1, round(0.75 * mm))",
        "mm = max(1, mm)",
        (*STAB, *_t("noise_terms_theo1_edf", "noise_id_stable32"), *WORK_BOUNDS),
        "Theo1's noise identified at m, not at the averaging factor of τ = 0.75 m τ0",
    ),
    Mutant(
        "bounds-hadamard-clipped",
        P + "stability/family.py",
        "-2 if dmax == 2 else -4)",
        "-2)",
        (*STAB, *_t("total_edf_stable32", "noise_id_stable32"), *WORK_BOUNDS),
        "the Hadamard family's α clipped at −2 (flicker-walk and random-run FM lost)",
    ),
    # issue 39 slice h39-names
    Mutant(
        "names-trigraph-one-pass",
        P + "identifiers.py",
        'while "??" in s:',
        'if "??" in s:',
        IDS + NAMES,
        "C comments escaped in one pass: '???' keeps a '??' (a trigraph with the next '/')",
    ),
    Mutant(
        "names-splice-hidden-by-blanks",
        P + "identifiers.py",
        'r"\\\\(?=[ ]*$)"',
        'r"\\\\(?=$)"',
        IDS + NAMES,
        "a backslash followed by blanks at a comment's end left: still a line splice for gcc",
    ),
    Mutant(
        "names-backstop-splice-blanks",
        P + "identifiers.py",
        'if re.search(r"\\\\[ \\t]*(\\n|$)", text):',
        'if re.search(r"\\\\(\\n|$)", text):',
        IDS + NAMES,
        "the generated-C backstop misses a backslash + blanks + newline (a splice for gcc)",
    ),
    Mutant(
        "names-backstop-trigraph",
        P + "identifiers.py",
        "if _TRIGRAPH.search(text):",
        "if False:",
        IDS + NAMES,
        "the generated-C backstop lets a trigraph through",
    ),
    Mutant(
        "names-metrics-twice-adjacent",
        P + "metrics.py",
        "if lab in labels[:i]:",
        "if lab in labels[: max(i - 1, 0)]:",
        METRICS + _t("tests/core/test_metrics_attacks.py"),
        "a path given twice in a row counted twice",
    ),
    Mutant(
        "names-metrics-third-sensor-only",
        P + "metrics.py",
        "if named and value not in named:",
        "if len(named) > 1 and value not in named:",
        METRICS + _t("tests/core/test_metrics_attacks.py"),
        "a second sensor pooled; only a third one noticed",
    ),
    Mutant(
        "names-metrics-unnamed-run-silent",
        P + "metrics.py",
        'if "" in sensors and len(sensors) > 1:',
        'if "" in sensors and len(sensors) > 2:',
        METRICS + _t("tests/core/test_metrics_attacks.py"),
        "a run naming no sensor pooled with a named sensor's without a warning",
    ),
    Mutant(
        "names-metrics-copy-by-time",
        P + "metrics.py",
        "values = np.ascontiguousarray(rec.columns[n], dtype=np.float64)",
        "values = np.ascontiguousarray(rec.time_s, dtype=np.float64)",
        METRICS + _t("tests/core/test_metrics_attacks.py"),
        "copies found by their time axis (a re-stamped copy passes, real runs at 1 Hz refused)",
    ),
    Mutant(
        "names-kalibr-axis-name-raw",
        P + "stability/noise_model.py",
        "name = one_line(ax.name)",
        "name = ax.name",
        NOISE + NAMES,
        "Kalibr YAML: an axis name written raw in its comments (a newline starts a key)",
    ),
    Mutant(
        "names-kalibr-source-raw",
        P + "stability/noise_model.py",
        "written by thermocal noise from {one_line(source)}",
        "written by thermocal noise from {source}",
        NOISE + NAMES,
        "Kalibr YAML: the input file's name written raw in the header comment",
    ),
    Mutant(
        "names-kalibr-key-twice-accepted",
        P + "stability/noise_model.py",
        "        if key in seen:\n",
        "        if key in seen and False:\n",
        NOISE + NAMES,
        "Kalibr backstop: a key written twice accepted (PyYAML keeps the last)",
    ),
    Mutant(
        "names-kalibr-float-loose",
        P + "stability/noise_model.py",
        'elif not re.fullmatch(r"[0-9]+\\.[0-9]*(e[+-][0-9]+)?", value):',
        'elif not re.fullmatch(r"[0-9.e+-]+", value):',
        NOISE + NAMES,
        "Kalibr backstop: '1e+16' (text to YAML 1.1) taken for a float",
    ),
    Mutant(
        "names-one-line-keeps-line-separator",
        P + "identifiers.py",
        '_LINE_UNSAFE_CATEGORIES = frozenset(("Cc", "Cf", "Zl", "Zp", "Cs", "Co", "Cn"))',
        '_LINE_UNSAFE_CATEGORIES = frozenset(("Cc", "Cf", "Zp", "Cs", "Co", "Cn"))',
        IDS + NAMES,
        "U+2028 (a YAML line break) kept in a one-line name",
    ),
    Mutant(
        "names-noise-rate-floor",
        P + "stability/noise_model.py",
        "IMU_RATE_HZ: Final = (10.0, 1.0e5)",
        "IMU_RATE_HZ: Final = (0.01, 1.0e5)",
        NOISE + NAMES,
        "time x1000 (0.1 Hz) not warned: densities 31.6x silently",
    ),
    Mutant(
        "names-noise-gyro-density-ceiling",
        P + "stability/noise_model.py",
        'IMU_DENSITY: Final = {"gyro": (1.0e-9, 1.0e-2), "accel": (1.0e-8, 1.0e-1)}',
        'IMU_DENSITY: Final = {"gyro": (1.0e-9, 1.0), "accel": (1.0e-8, 1.0e-1)}',
        NOISE + NAMES,
        "a gyro density no IMU has (0.012 rad/s/sqrt(Hz)) not warned",
    ),
    Mutant(
        "names-noise-accel-overlap-cli",
        P + "cli/noise_cmd.py",
        "if n in names[:i] or n in (taken or []):",
        "if n in names[:i]:",
        NOISE + NAMES,
        "--accel naming the gyro's columns not refused by the command",
    ),
    Mutant(
        "names-noise-rostopic-any",
        P + "stability/noise_model.py",
        'ROS_NAME: Final = re.compile(r"[A-Za-z~/][A-Za-z0-9_/]*")',
        'ROS_NAME: Final = re.compile(r"[^\\n]*")',
        NOISE + NAMES,
        "any one-line --rostopic accepted (a quote, a space, '#', nothing)",
    ),
    Mutant(
        "names-poses-deep-json",
        P + "pipeline/multipos.py",
        "except RecursionError:  # thousands of nested brackets",
        "except MemoryError:  # thousands of nested brackets",
        NAMES,
        "a POSES file nested 100 000 deep: RecursionError, exit 1",
    ),
    Mutant(
        "names-report-mathtext",
        P + "report/figures.py",
        'PLAIN_TEXT: Any = {"text.parse_math": False}',
        'PLAIN_TEXT: Any = {"text.parse_math": True}',
        NAMES,
        "report figures parse a column name as TeX ('$\\\\frac$': ValueError, exit 1)",
    ),
    Mutant(
        "names-report-glyph-warning",
        P + "report/figures.py",
        'r"Glyph \\d+ .*missing from"',
        'r"Glyph never"',
        NAMES,
        "matplotlib's missing-glyph warning on a name with NEL: a foreign line (exit 1 -W error)",
    ),
    Mutant(
        "names-allan-plot-mathtext",
        P + "report/allan_plots.py",
        "ax.set_title(title, parse_math=False)",
        "ax.set_title(title)",
        NAMES,
        "allan --plot parses the column name in its title as TeX",
    ),
    Mutant(
        "names-fleet-id-dollar",
        P + "fleet/config.py",
        "not _ID.fullmatch(uid):",
        "not _ID.match(uid):",
        NAMES,
        "a fleet unit id 'u1\\n' accepted ('$' matches before a final newline): a folder name",
    ),
    Mutant(
        "names-station-id-dollar",
        P + "station/config.py",
        "if not _ID.fullmatch(sid) or sid == CHAMBER_STREAM:",
        "if not _ID.match(sid) or sid == CHAMBER_STREAM:",
        NAMES,
        "a station sensor id 'imu\\n' accepted ('$' matches before a final newline)",
    ),
    Mutant(
        "names-oserror-name-raw",
        P + "pipeline/messages.py",
        'return one_line(f"{where}: {exc.strerror or exc}"), True',
        'return f"{where}: {exc.strerror or exc}", True',
        NAMES,
        "a file name with a newline in an OS error: the error spread over two lines",
    ),
    # issue 39 slice h39-firmware
    Mutant(
        "fw-ap-rotation-not-inverted",
        P + "tempcal/ardupilot.py",
        "out = out @ ardupilot_rotation(code)  #",
        "out = out @ ardupilot_rotation(code).T  #",
        FW_AP,
        "ArduPilot's AHRS rotation applied again instead of undone",
    ),
    Mutant(
        "fw-ap-pitch-sign",
        P + "tempcal/ardupilot.py",
        "ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])",
        "ry = np.array([[cp, 0, -sp], [0, 1, 0], [sp, 0, cp]])",
        FW_AP,
        "ArduPilot's pitch matrix with its sign flipped",
    ),
    Mutant(
        "fw-tclr-powers-off-by-one",
        P + "tempcal/ardupilot.py",
        "return [[float(x) * 1e6 for x in p[k]] for k in (1, 2, 3)]",
        "return [[float(x) * 1e6 for x in p[k]] for k in (0, 1, 2)]",
        FW_AP,
        "TCLR learned coefficients taken one power too low",
    ),
    Mutant(
        "fw-tclr-no-tref",
        P + "tempcal/ardupilot.py",
        "np.vander(np.asarray(temp_c, dtype=np.float64) - AP_TREF_C, 4",
        "np.vander(np.asarray(temp_c, dtype=np.float64), 4",
        FW_AP,
        "TCLR cubic fitted in T, not T - 35",
    ),
    Mutant(
        "fw-ap-caltemp-not-clamped",
        P + "tempcal/ardupilot.py",
        "tcal = float(np.clip(self.caltemp_c[kind], self.tmin_c, self.tmax_c))",
        "tcal = float(self.caltemp_c[kind])",
        FW_AP,
        "INS_ACC/GYR CALTEMP not constrained to TMIN..TMAX as correct_sensor does",
    ),
    Mutant(
        "fw-px4-accel-sign",
        P + "export/params.py",
        'out.params[f"{p}X{k}_{i}"] = poly.coef[k]',
        'out.params[f"{p}X{k}_{i}"] = -poly.coef[k] if kind == "accel" else poly.coef[k]',
        FW_PX4,
        "PX4 accelerometer cubic written with the wrong sign",
    ),
    Mutant(
        "fw-px4-quartic-accepted",
        P + "export/params.py",
        "if power > 3:",
        "if power > 4:",
        FW_EXPORT,
        "a quartic accepted for PX4 (X0..X3 only)",
    ),
    Mutant(
        "fw-any-override-passes",
        P + "adequacy.py",
        'if t.get("override") not in overrides or not t.get("override")]',
        "if not overrides]",
        FW_ADEQ,
        "firmware export accepts any override for every failed adequacy test",
    ),
    Mutant(
        "fw-ulog-fast-first-for-last",
        P + "readers/ulog_fast.py",
        "first[ids[::-1]] = data_at[::-1]",
        "first[ids] = data_at",
        FW_ULOG,
        "fast ULog reader takes each msg_id's last data message for its first",
    ),
    Mutant(
        "fw-baro-no-upper-bound",
        P + "tempcal/offset_gates.py",
        "ok = finite & (p >= lo) & (p <= hi)",
        "ok = finite & (p >= lo)",
        FW_ATT,
        "barometer samples of 3e38 Pa kept",
    ),
    Mutant(
        "fw-baro-altitude-threshold",
        P + "tempcal/offset_gates.py",
        "if abs(resid[k]) > BARO_STEP_PA:",
        "if abs(resid[k]) > 10.0 * BARO_STEP_PA:",
        FW_ATT,
        "a climb of 50 m taken for thermal drift",
    ),
    Mutant(
        "fw-mag-turn-threshold",
        P + "tempcal/offset_gates.py",
        "off = np.flatnonzero(angle > MAG_TURN_DEG)",
        "off = np.flatnonzero(angle > 10.0 * MAG_TURN_DEG)",
        FW_ATT,
        "a turning vehicle's magnetometer fitted",
    ),
    Mutant(
        "fw-mag-unit-band",
        P + "tempcal/offset_gates.py",
        "ok = finite & (mag >= lo) & (mag <= hi)",
        "ok = finite & (mag >= lo) & (mag <= 100.0 * hi)",
        FW_ATT,
        "a magnetometer in µT declared as gauss fitted",
    ),
    Mutant(
        "fw-gyro-noise-sqrt2",
        P + "tempcal/pipeline.py",
        "noise = np.std(np.diff(v, axis=0), axis=0) / np.sqrt(2.0)",
        "noise = np.std(np.diff(v, axis=0), axis=0) * np.sqrt(2.0)",
        FW_ATT,
        "gyro white noise from first differences multiplied by sqrt 2",
    ),
    Mutant(
        "fw-ap-baro-enabled-at-limit",
        P + "tempcal/ardupilot_baro.py",
        '"TCAL_ENABLED": 0 if self.at_limit else 1,',
        '"TCAL_ENABLED": 1,',
        FW_ATT,
        "TCAL_ENABLED 1 when the exponent is at a limit",
    ),
    Mutant(
        "fw-ap-baro-int8-silent",
        P + "tempcal/ardupilot_baro.py",
        "and round(hi) <= INT8_RANGE[1]:",
        "and round(hi) <= 2 * INT8_RANGE[1]:",
        FW_ATT,
        "TCAL_TEMP_MAX clamped to 127 without a word",
    ),
    Mutant(
        "fw-triad-px4-scale-metadata-only",
        P + "export/triad_params.py",
        "rng = ARDUPILOT_ACCSCAL_RANGE if scale else ARDUPILOT_ACCOFFS_RANGE_M_S2",
        "rng = PX4_ACCSCALE_RANGE if scale else ARDUPILOT_ACCOFFS_RANGE_M_S2",
        FW_ATT,
        "CAL_ACC scale 2.0 written for PX4 (only its metadata range checked)",
    ),
    Mutant(
        "fw-gyro-bias-threshold",
        P + "tempcal/pipeline.py",
        "if bias[j] <= GYRO_BIAS_MAX_RAD_S and",
        "if bias[j] <= 10.0 * GYRO_BIAS_MAX_RAD_S and",
        FW_ATT,
        "a still gyro reading 0.117 rad/s (deg/s in the rad/s topic) not warned",
    ),
    Mutant(
        "fw-baro-span-located",
        P + "tempcal/offset_gates.py",
        'j = np.searchsorted(tb, tb + CHANGE_WINDOW_S, side="right") - 1',
        'j = np.searchsorted(tb, tb + 10.0 * CHANGE_WINDOW_S, side="right") - 1',
        FW_ATT,
        "the climb's time span said over ten minutes, not where it happened",
    ),
    Mutant(
        "fw-documented-range-open",
        P + "export/params.py",
        "if doc.lo <= v <= doc.hi:",
        "if doc.lo <= v:",
        FW_ATT,
        "INS_TCAL TMAX 95 written without the warning of its documented @Range -70…80",
    ),
    # issue 39 slice h39-allan
    Mutant(
        "h39a-hadamard-clipped-at-rwfm",
        P + "stability/family.py",
        "-2 if dmax == 2 else -4",
        "-2",
        H39A,
        "Hadamard family's α clipped to −2 (random-run FM read as random-walk FM)",
    ),
    Mutant(
        "h39a-theo1-noise-at-m",
        P + "stability/family.py",
        "mm = max(1, round(0.75 * mm))",
        "mm = int(mm)",
        H39A,
        "Theo1's noise identified at m, not at its τ = 0.75 m τ0",
    ),
    Mutant(
        "h39a-edf-table1-ffm-typo",
        P + "stability/edf.py",
        "-1: (None, (1.048, 0.534), (1.180, 0.816)),",
        "-1: (None, (1.048, 0.543), (1.180, 0.816)),",
        H39A,
        "Greenhall Table 1 (modified, flicker FM, d = 2): a1 0.534 typed 0.543",
    ),
    Mutant(
        "h39a-edf-table2-rwfm-typo",
        P + "stability/edf.py",
        "-2: (None, (1.079, 0.368), (1.033, 0.607)),",
        "-2: (None, (1.097, 0.368), (1.033, 0.607)),",
        H39A,
        "Greenhall Table 2 (unmodified, random-walk FM, d = 2): a0 1.079 typed 1.097",
    ),
    Mutant(
        "h39a-edf-table3-typo",
        P + "stability/edf.py",
        "(15.23, 12.0)",
        "(15.32, 12.0)",
        H39A,
        "Greenhall Table 3 (flicker PM normalisation, d = 2): b0 15.23 typed 15.32",
    ),
    Mutant(
        "h39a-edf-totvar-typo",
        P + "stability/edf.py",
        "-1: (1.17, 0.22)",
        "-1: (1.17, 0.32)",
        H39A,
        "SP 1065 Table 7 (totdev, flicker FM): c 0.22 typed 0.32",
    ),
    Mutant(
        "h39a-edf-htot-typo",
        P + "stability/edf.py",
        "-1: (0.868, 1.140)",
        "-1: (0.868, 1.410)",
        H39A,
        "SP 1065 Htot EDF (flicker FM): b1 1.140 typed 1.410",
    ),
    Mutant(
        "h39a-edf-theo1-fpm-typo",
        P + "stability/edf.py",
        "12.387 * t",
        "12.837 * t",
        H39A,
        "Theo1 EDF (flicker PM): 12.387 typed 12.837",
    ),
    Mutant(
        "h39a-edf-mtot-wpm-typo",
        P + "stability/edf.py",
        "2: (1.90, 2.10),",
        "2: (1.09, 2.10),",
        H39A,
        "SP 1065 Table 8 (mtotdev, white PM): b 1.90 typed 1.09",
    ),
    Mutant(
        "h39a-rn-theory-2pi",
        P + "stability/edf.py",
        "math.log(math.pi * m)",
        "math.log(2.0 * math.pi * m)",
        H39A,
        "R(n)'s flicker-PM theory with 2π n (f_h = 1/τ0), not π n (f_h = 1/(2 τ0))",
    ),
    Mutant(
        "h39a-dynamic-increases-only",
        P + "stability/allan.py",
        "apart = (d_lo > w_hi) | (d_hi < w_lo)",
        "apart = d_lo > w_hi",
        H39A,
        "dynamic ADEV flags windows noisier than the record, never quieter ones",
    ),
    Mutant(
        "h39a-quantization-mrad",
        P + "stability/allan.py",
        '(1e6, "urad", "quantization")',
        '(1e3, "urad", "quantization")',
        H39A,
        "rad/s data: Q converted to mrad but labelled µrad",
    ),
    Mutant(
        "h39a-walk-chosen-by-density",
        P + "stability/noise_model.py",
        "key=lambda a: a.walk.value",
        "key=lambda a: a.density.value",
        H39A,
        "noise model: the random walk of the axis with the largest density, not the largest walk",
    ),
    Mutant(
        "h39a-constant-column-accepted",
        P + "stability/analysis.py",
        "    if lo == hi:",
        "    if lo == hi and False:",
        H39A_ATT,
        "a constant (stuck) column analysed: ADEV 0 with a zero-width interval and a noise type",
    ),
    Mutant(
        "h39a-few-levels-unseen",
        P + "stability/analysis.py",
        "FEW_LEVELS: Final = 3",
        "FEW_LEVELS: Final = 1",
        H39A_ATT,
        "a flat-lined column of two values analysed without a word",
    ),
    Mutant(
        "h39a-taus-last-m-dropped",
        P + "stability/analysis.py",
        "& (m <= m_max)",
        "& (m < m_max)",
        H39A_ATT,
        "--taus at the record's last τ taken for outside it",
    ),
    Mutant(
        "h39a-idle-bias-correct-any",
        P + "stability/analysis.py",
        "bool(np.all(r.curves[d].bias == 1.0))",
        "bool(np.any(r.curves[d].bias == 1.0))",
        H39A_ATT,
        "--bias-correct called idle when one τ's factor is 1",
    ),
    Mutant(
        "h39a-idle-noise-type-any",
        P + "stability/analysis.py",
        "all(d in NO_INTERVAL for d in devs)",
        "any(d in NO_INTERVAL for d in devs)",
        H39A_ATT,
        "--noise-type called idle when one deviation (MTIE) has no interval",
    ),
    Mutant(
        "h39a-rate-floor-gone",
        P + "readers/text.py",
        "RATE_HZ_RANGE = (1e-6, 1e7)",
        "RATE_HZ_RANGE = (1e-320, 1e7)",
        H39A_ATT,
        "--rate 1e-300 accepted (time = n / rate overflows: exit 1)",
    ),
    Mutant(
        "h39a-ramp-rate-floor-gone",
        P + "profiles.py",
        "RAMP_RATE_RANGE = (1e-4, 1e3)",
        "RAMP_RATE_RANGE = (0.0, 1e3)",
        H39A_ATT,
        "profile --rate 1e-300 °C/min accepted (a program of 1e302 s: exit 1)",
    ),
    Mutant(
        "h39a-chamber-rate-2000",
        P + "pipeline/fit.py",
        "MAX_CHAMBER_RATE_C_PER_MIN = 20.0",
        "MAX_CHAMBER_RATE_C_PER_MIN = 2000.0",
        H39A_ATT,
        "fit: Ṫ of 1000 °C/min (s read as ms) taken as a chamber's ramp",
    ),
    Mutant(
        "h39a-ms-scale-100",
        P + "pipeline/fit.py",
        '(1000.0, "ms read as s")',
        '(100.0, "ms read as s")',
        H39A_ATT,
        "fit: the ms-read-as-s hint scaled by 100, not 1000",
    ),
    Mutant(
        "h39a-edf-table1-rrfm-typo",
        P + "stability/edf.py",
        "(1.489, 0.702)",
        "(1.498, 0.702)",
        H39A_EDF,
        "Greenhall Table 1 (modified, random-run FM, d = 3): a0 1.489 typed 1.498",
    ),
    Mutant(
        "h39a-edf-table2-fpm-typo",
        P + "stability/edf.py",
        "(9950.0, 6520.0)",
        "(9950.0, 6250.0)",
        H39A_EDF,
        "Greenhall Table 2 (unmodified, flicker PM, d = 3): a1 6520 typed 6250",
    ),
    Mutant(
        "h39a-edf-table2-fwfm-typo",
        P + "stability/edf.py",
        "-3: (None, None, (1.053, 0.553)),",
        "-3: (None, None, (1.053, 0.535)),",
        H39A_EDF,
        "Greenhall Table 2 (unmodified, flicker-walk FM, d = 3): a1 0.553 typed 0.535",
    ),
    Mutant(
        "h39a-edf-theo1-rwfm-typo",
        P + "stability/edf.py",
        "8.6 * t * (a - 1.0)",
        "6.8 * t * (a - 1.0)",
        H39A_EDF,
        "Theo1 EDF (random-walk FM): 8.6 typed 6.8",
    ),
    Mutant(
        "h39a-edf-totvar-rwfm-typo",
        P + "stability/edf.py",
        "-2: (0.93, 0.36)",
        "-2: (0.93, 0.63)",
        H39A_EDF,
        "SP 1065 Table 7 (totdev, random-walk FM): c 0.36 typed 0.63",
    ),
    Mutant(
        "h39a-rn-theory-white-pm",
        P + "stability/edf.py",
        "return 1.0 / m",
        "return 1.0 / (m + 1)",
        H39A_EDF,
        "R(n) of white PM 1/(n + 1), not 1/n",
    ),
    # issue 39 slice h39-multipos
    Mutant(
        "h39mp-gyro-no-chi2-inflation",
        P + "multipos/gyro.py",
        "cov_p = cov0 * chi2",
        "cov_p = cov0",
        H39MP,
        "multipos: the gyro's σ not scaled by a significant reduced χ² (misfit motions)",
    ),
    Mutant(
        "h39mp-gyro-three-dof-per-motion",
        P + "multipos/gyro.py",
        "dof = (2 * len(rot.motions) + 3 * len(rot.turns)) - len(free)",
        "dof = (3 * len(rot.motions) + 3 * len(rot.turns)) - len(free)",
        H39MP,
        "multipos: 3 degrees of freedom per motion (its residual lies across gravity: 2)",
    ),
    Mutant(
        "h39mp-planarity-threshold",
        P + "multipos/accel.py",
        "if w[0] < 0.02:",
        "if w[0] < 0.002:",
        H39MP,
        "multipos: poses within ±5° of one plane accepted (normal's scale factor unseen)",
    ),
    Mutant(
        "h39mp-six-face-misalignment-axis",
        P + "multipos/accel.py",
        "sig[6 + k] = math.sqrt(var_e[model.MISALIGNMENT_INDEX[n][1]])",
        "sig[6 + k] = math.sqrt(var_e[model.MISALIGNMENT_INDEX[n][0]])",
        H39MP,
        "six-face misalignment σ from the faces of its row's axis, not its column's",
    ),
    Mutant(
        "h39mp-gravity-first-run-of-placement",
        P + "gravity.py",
        "        s = np.mean([vecs[k] for k in group], axis=0)\n        u = s",
        "        s = vecs[group[0]]\n        u = s",
        (*H39MP, *GRAV),
        "a placement's gravity direction from its first run only",
    ),
    Mutant(
        "h39mp-validate-ambient-last-column",
        P + "validation.py",
        "run.temps_c[:, 0]",
        "run.temps_c[:, -1]",
        (*H39MP, "tests/core/test_validation.py"),
        "validate: the ambient taken from the last temperature column",
    ),
    Mutant(
        "h39mp-validate-zero-reference-unconverted",
        P + "validation.py",
        "zero_reference=self.zero_reference / factor,",
        "zero_reference=self.zero_reference,",
        (*H39MP, "tests/core/test_validation.py", "tests/pipeline/test_triad_validate_counts.py"),
        "validate: the zero reference left in the model's unit when shown in the data's",
    ),
    Mutant(
        "h39mp-validate-stage-stability-unconverted",
        P + "validation.py",
        '"bias_stability_before", "bias_stability_after")',
        '"bias_stability_before", "bias_stability_after")[:2]',
        (*H39MP, "tests/core/test_validation.py", "tests/pipeline/test_triad_validate_counts.py"),
        "validate: each stage's bias stability left in the model's unit",
    ),
    Mutant(
        "h39mp-validate-weak-verdict-ignored",
        P + "validation.py",
        "if self.r is not None and not self.weakly_correlated:",
        "if False:",
        (*H39MP, "tests/core/test_validation.py"),
        "validate: a run that repeats the modelling run judged improved",
    ),
    Mutant(
        "h39mp-scale-factor-refused",
        P + "turntable/model.py",
        "SCALE_FACTOR_REFUSED: Final = 0.5",
        "SCALE_FACTOR_REFUSED: Final = 50.0",
        H39MP,
        "multipos: --accel-unit mg on m/s² data written (scale factors −99 %)",
    ),
    Mutant(
        "h39mp-gyro-direction-refused",
        P + "multipos/calibrate.py",
        "if not (after <= GYRO_DIRECTION_REFUSED_DEG and after < before):",
        "if not (after <= 90.0):",
        H39MP,
        "multipos: a gyro fit leaving 40° of direction residual written",
    ),
    Mutant(
        "h39mp-accel-residual-not-below-before",
        P + "multipos/calibrate.py",
        "(after < before or after == 0.0)",
        "(after < 1e9 * before or after == 0.0)",
        H39MP,
        "multipos: an accelerometer fit that made the residual worse written",
    ),
    Mutant(
        "h39mp-tref-margin",
        P + "turntable/thermal.py",
        "lo - margin <= tref_c <= hi + margin",
        "lo - 1e9 * margin <= tref_c <= hi + 1e9 * margin",
        H39MP,
        "--tref 200 fitted and written (the reader refuses the file)",
    ),
    Mutant(
        "h39mp-check-as-read-skipped",
        P + "pipeline/turntable.py",
        "        calibration_from_dict(json.loads(json.dumps(cal.to_dict())), str(output))",
        "        pass",
        H39MP,
        "a calibration its own reader refuses (condition > 10) written",
    ),
    Mutant(
        "h39mp-azimuth-refused",
        P + "turntable/calibrate.py",
        "AZIMUTH_REFUSED_DEG = 5.0",
        "AZIMUTH_REFUSED_DEG = 500.0",
        H39MP,
        "turntable: α encoder off by 90° written as −1e6 ppm scale factors",
    ),
    Mutant(
        "h39mp-azimuth-sign",
        P + "turntable/calibrate.py",
        "np.arctan2(e[1, 0] - e[0, 1], 2.0 + e[0, 0] + e[1, 1])",
        "np.arctan2(e[0, 1] - e[1, 0], 2.0 + e[0, 0] + e[1, 1])",
        H39MP,
        "turntable: the α offset found with the wrong sign (the hint doubles it)",
    ),
    Mutant(
        "h39mp-azimuth-warned",
        P + "turntable/calibrate.py",
        "AZIMUTH_WARNED_DEG = 1.0",
        "AZIMUTH_WARNED_DEG = 4.0",
        H39MP,
        "turntable: a 3° inner-axis rotation (−1371 ppm on x, y) not warned of",
    ),
    Mutant(
        "h39mp-tt-scale-refused",
        P + "turntable/calibrate.py",
        "bad = model.scale_factors_beyond(theta)",
        "bad = []",
        H39MP,
        "turntable: a °/s gyro declared °/h written (scale factors −99.97 %)",
    ),
    Mutant(
        "h39mp-tt-residual-refused",
        P + "turntable/calibrate.py",
        "RESIDUAL_REFUSED = 20.0",
        "RESIDUAL_REFUSED = 200.0",
        H39MP,
        "turntable: a run with the latitude's sign wrong (residuals 138×) written",
    ),
    Mutant(
        "h39mp-tt-azimuth-before-unit",
        P + "turntable/calibrate.py",
        "if not abs(k - 1.0) <= SCALE_FACTOR_REFUSED:",
        "if False:",
        H39MP,
        "turntable: a wrong gyro unit blamed on the α encoder's zero",
    ),
    Mutant(
        "h39mp-save-calibration-unchecked",
        P + "models/files.py",
        "        calibration_from_dict(json.loads(json.dumps(d)), str(path))",
        "        pass",
        H39MP,
        "a calibration its own reader refuses written by any writer",
    ),
    Mutant(
        "h39mp-validate-triads-unjudged",
        P + "multipos/validate.py",
        "        if not v.rms_after <= lim:",
        "        if not v.rms_after <= 10.0 * lim:",
        H39MP,
        "validate: a held-out session read in rad/s for °/s (47° after) shown without a word",
    ),
    Mutant(
        "h39mp-short-named-pose",
        P + "multipos/calibrate.py",
        "or t[s.end - 1] - t[s.start] < static_s]",
        "or t[s.end - 1] - t[s.start] < 0.0]",
        H39MP,
        "multipos: a named pose of three samples used without a word",
    ),
    # issue 39 slice h39-station
    Mutant(
        "adequacy-h39-any-override-passes",
        P + "adequacy.py",
        "t.override is None or t.override not in self.overrides",
        "t.override is None or not self.overrides",
        ADEQ_H39,
        "any override (--allow-motion) passes every adequacy test (a narrow sweep too)",
    ),
    Mutant(
        "adequacy-h39-n-equals-p-overridable",
        P + "adequacy.py",
        "if n_samples <= n_coefficients:",
        "if n_samples < n_coefficients:",
        ADEQ_H39,
        "n = p samples (the fit passes through them) refused only unless --allow-narrow",
    ),
    Mutant(
        "adequacy-h39-too-few-bins-overridable",
        P + "adequacy.py",
        'verdict, override = "fail", None\n        msg = (\n            f"{name} holds {distinct}',
        'verdict, override = "fail", ALLOW_NARROW\n'
        '        msg = (\n            f"{name} holds {distinct}',
        ADEQ_H39,
        "fewer distinct temperatures than coefficients fitted with --allow-narrow",
    ),
    Mutant(
        "adequacy-h39-best-stillness",
        P + "adequacy.py",
        "return max(tests, key=lambda t: (rank[t.verdict], t.figure or 0.0))",
        "return min(tests, key=lambda t: (rank[t.verdict], t.figure or 0.0))",
        ADEQ_H39,
        "of several runs, the stillest run's verdict recorded (a moving run passes)",
    ),
    Mutant(
        "adequacy-h39-first-run-stillness",
        P + "adequacy.py",
        "tests.append(_worst_stillness(per_run))",
        "tests.append(per_run[0])",
        ADEQ_H39,
        "of several runs, only the first run's stillness judged",
    ),
    Mutant(
        "adequacy-h39-stillness-figure-ignored",
        P + "adequacy.py",
        "key=lambda t: (rank[t.verdict], t.figure or 0.0))",
        "key=lambda t: rank[t.verdict])",
        ADEQ_H39,
        "of runs with one verdict, the first one's figure kept, not the worst",
    ),
    Mutant(
        "station-h39-setpoint-event-every-write",
        P + "station/run.py",
        "SETPOINT_EVENT_C = 1.0",
        "SETPOINT_EVENT_C = 0.0",
        ST_ATT2,
        "every set-point of a fine ramp an event: station.json rewritten 10⁵ times a day",
    ),
    Mutant(
        "station-h39-setpoint-event-step-ignored",
        P + "station/run.py",
        "if (last is not None and last[2] == self.step and abs(",
        "if (last is not None and abs(",
        ST_ATT2,
        "a hold's set-point within 1 °C of the ramp's last not recorded: a kill reports 64.x °C",
    ),
    Mutant(
        "station-h39-program-points-unbounded",
        P + "station/run.py",
        "if t_prog.size > MAX_PROGRAM_POINTS:",
        "if t_prog.size > 100 * MAX_PROGRAM_POINTS:",
        ST_ATT2,
        "a program of 10⁶ points run: a 20 MB station.json rewritten at every event",
    ),
    Mutant(
        "station-h39-output-folder-oserror-raw",
        P + "station/recorder.py",
        "            except OSError as exc:  # a read-only place, a file in the way, no such mount",
        "            except ValueError as exc:  # a read-only place",
        ST_ATT2,
        "-o on a read-only place: the OS error's text without the option to change",
    ),
    Mutant(
        "station-h39-wall-clock",
        P + "station/clock.py",
        "return _WALL0 + (time.monotonic() - _MONO0)",
        "return time.time()",
        ST_ATT2,
        "the loop timed by the wall clock: a step back of an hour stalls the run an hour",
    ),
    Mutant(
        "station-h39-clock-step-silent",
        P + "station/run.py",
        "if abs(jump) <= CLOCK_STEP_S:",
        "if abs(jump) <= 1e9:",
        ST_ATT2,
        "a step of the host's clock not reported",
    ),
    Mutant(
        "station-h39-shared-register-accepted",
        P + "station/config.py",
        'if c.register_kind == "holding" and c.setpoint_register == c.temperature_register:',
        "if False:",
        ST_ATT2,
        "one holding register for set-point and temperature: the set-point read back as T",
    ),
    # issue 39 slice h39-audit
    Mutant(
        "audit-fit-latitude-open",
        P + "pipeline/fit.py",
        "if o.latitude is not None and not -90.0 <= o.latitude <= 90.0:",
        "if o.latitude is not None and not -90.0 <= o.latitude:",
        AUDIT,
        "fit --latitude 200 accepted: the earth rate of another latitude removed silently",
    ),
    Mutant(
        "audit-fit-rcond-negative",
        P + "pipeline/fit.py",
        "if value is not None and not (np.isfinite(value) and value >= 0.0):",
        "if value is not None and not (np.isfinite(value) and value >= -1.0):",
        AUDIT,
        "fit --rcond -1 accepted: the SVD truncation silently switched off",
    ),
    Mutant(
        "audit-fit-breakpoints-empty",
        P + "pipeline/fit.py",
        'if o.breakpoints is not None and not split_floats(o.breakpoints, "--breakpoints"):',
        'if o.breakpoints is not None and split_floats(o.breakpoints, "--breakpoints") is None:',
        AUDIT,
        "fit --model piecewise --breakpoints , writes a one-line model",
    ),
    Mutant(
        "audit-fit-rate-interval-zero",
        P + "pipeline/fit.py",
        "(np.isfinite(o.rate_interval) and o.rate_interval > 0)",
        "(np.isfinite(o.rate_interval) and o.rate_interval >= 0)",
        AUDIT,
        "fit --rate-interval 0 refused for a 'Ṫ span' instead of naming the option",
    ),
    Mutant(
        "audit-fit-run-twice",
        P + "pipeline/fit.py",
        "        if digest in seen:\n",
        "        if str(path) in seen:\n",
        AUDIT,
        "fit a.csv a.csv (or a copy) counts one run twice, exit 0",
    ),
    Mutant(
        "audit-c-float-max",
        P + "export/c/core.py",
        'if self.real == "float" and abs(x) > FLT_MAX:',
        'if self.real == "float" and abs(x) > 10.0 * FLT_MAX:',
        AUDIT,
        "export-c --float of a -1e39 constant: exit 1 from the compiler, files left",
    ),
    Mutant(
        "audit-c-float-tiny-kept",
        P + "export/c/core.py",
        'if self.real == "float" and abs(x) < FLT_MIN:',
        'if self.real == "float" and abs(x) < 0.0:',
        AUDIT,
        "export-c --float writes 1e-50f: the compiler's truncation warning fails the build",
    ),
    Mutant(
        "audit-c-float-overflow-unsaid",
        P + "export/c/files.py",
        "if not math.isfinite(err.max_abs):",
        'if err.max_abs > float("inf"):',
        AUDIT,
        "export-c --float whose float build gives inf: exit 0, the error shown as '—'",
    ),
    Mutant(
        "audit-sim-budget-in-seconds",
        P + "simulate/scenarios.py",
        "check_sample_budget(duration_s * rate_hz + 1,",
        "check_sample_budget(duration_s + 1,",
        AUDIT,
        "the sample budget counts seconds, not samples: --rate-hz 1e9 reaches MemoryError",
    ),
    Mutant(
        "audit-sim-budget-one-run",
        P + "simulate/scenarios.py",
        "check_sample_budget(float(runs) * n_run,",
        "check_sample_budget(n_run,",
        AUDIT,
        "--runs 1e6 judged as one run: a million generators spawned (hang)",
    ),
    Mutant(
        "audit-program-absolute-zero",
        P + "profiles.py",
        "cold = np.flatnonzero(c < ABSOLUTE_ZERO_C)",
        "cold = np.flatnonzero(c < 2.0 * ABSOLUTE_ZERO_C)",
        AUDIT,
        "a chamber program step to -300 °C simulated",
    ),
    Mutant(
        "audit-demo-seed-negative",
        P + "cli/demo_cmd.py",
        "if seed < 0:",
        "if seed < -10:",
        AUDIT,
        "demo --seed -5: exit 1 from numpy with a half-made folder",
    ),
    # issue 39 slice h39-left
    Mutant(
        "h39left-confidence-floor-zero",
        P + "stability/edf.py",
        "    if not CONFIDENCE_MIN <= c <= CONFIDENCE_MAX:",
        "    if not 0.0 < c < 1.0:",
        H39L,
        "--confidence 1e-300 accepted: an interval of zero width beside the estimate",
    ),
    Mutant(
        "h39left-confidence-unchecked-noise",
        P + "stability/analysis.py",
        "    check_confidence(confidence)\n    moved = motion_in(rec, gyro, accel)",
        "    moved = motion_in(rec, gyro, accel)",
        H39L,
        "noise --confidence 1e-300 accepted",
    ),
    Mutant(
        "h39left-station-fifo-no-such-file",
        P + "station/config.py",
        '    refuse_special_input(p, "station file (STATION.toml)")',
        "    pass",
        H39L,
        "station check FIFO: 'no such file'",
    ),
    Mutant(
        "h39left-port-fifo-passes",
        P + "station/config.py",
        '    if why is not None and why != "it is a character device":',
        "    if False:",
        H39L,
        "a FIFO as a sensor port: pyserial's 'Inappropriate ioctl'",
    ),
    Mutant(
        "h39left-dead-worker-stops-batch",
        P + "fleet/batch.py",
        "        return lost_unit(task, exc)",
        "        raise",
        H39L,
        "a local worker's death stops the batch, its unit unnamed",
    ),
    Mutant(
        "h39left-compensate-every-column",
        P + "compensate/files.py",
        "    available = names_list(names)",
        '    available = ", ".join(repr(c) for c in names)',
        H39L,
        "compensate's error lists 10 000 column names on one line",
    ),
    Mutant(
        "h39left-summary-csv-formula",
        P + "fleet/batch.py",
        "        _for_spreadsheets(df).to_csv(fh, index=False)",
        "        df.to_csv(fh, index=False)",
        H39L,
        "fleet summary.csv: a channel name '=1+2' runs as a formula",
    ),
    Mutant(
        "h39left-formula-trigger-minus-dropped",
        P + "outputs.py",
        'FORMULA_TRIGGERS: tuple[str, ...] = ("=", "+", "-", "@", "\\t", "\\r")',
        'FORMULA_TRIGGERS: tuple[str, ...] = ("=", "+", "@", "\\t", "\\r")',
        H39L,
        "a name beginning with '-' left as a formula",
    ),
    Mutant(
        "h39left-summary-header-not-neutralised",
        P + "fleet/batch.py",
        "    out.columns = [neutralise_cell(c) for c in out.columns]",
        "    out.columns = list(out.columns)",
        H39L,
        "summary.csv: a channel's column name '=1+2.unit' runs as a formula",
    ),
    Mutant(
        "h39left-compensate-formula-silent",
        P + "compensate/files.py",
        "    warn_formula_names(dst, source.names)  # every output column",
        "    pass  # every output column",
        H39L,
        "compensate CSV: a formula name written without a word",
    ),
    Mutant(
        "h39left-counts-share-never",
        P + "recording.py",
        "    if first is None or fractional < NON_INTEGER_COUNTS_SHARE * finite:",
        "    if first is None or fractional <= finite:",
        H39L,
        "values declared as counts that are fractions: silent",
    ),
    Mutant(
        "h39left-counts-integers-warn",
        P + "recording.py",
        "        frac = ok & (part != np.round(part))",
        "        frac = ok",
        H39L,
        "integer counts warned as fractions",
    ),
    Mutant(
        "h39left-signal-error-every-column",
        P + "pipeline/reading.py",
        '            + (names_list(names) or "see thermocal inspect FILE")',
        '            + (", ".join(repr(c) for c in names) or "see thermocal inspect FILE")',
        H39L,
        "allan/fit/noise: 'name the signal column' lists 10 000 names on one line",
    ),
    # issue 42 slice h42-speed
    Mutant(
        "h42s-lane-offset-dropped",
        P + "stability/deviations.py",
        "    off += v  # v_j = off_c + t[i, c]",
        "    off *= 1.0  # v_j = off_c + t[i, c]",
        DIGITS,
        "MDEV lanes: each column's inner sums without the running offset (v_a + column totals)",
    ),
    Mutant(
        "h42s-lane-cross-term-halved",
        P + "stability/deviations.py",
        "+ 2.0 * float(bufs.ones @ (t @ off))",
        "+ float(bufs.ones @ (t @ off))",
        DIGITS,
        "MDEV lanes: Σ (off + t)² expanded with the cross term once, not twice",
    ),
    Mutant(
        "h42s-lane-tail-double-counted",
        P + "stability/deviations.py",
        "tot + _modified_tail(x, mm, nt, e, v) - v * v",
        "tot + _modified_tail(x, mm, nt, e, v) - 0.0 * v",
        DIGITS,
        "MDEV: the inner sum where the lane blocks stop counted twice (lanes and tail)",
    ),
    Mutant(
        "h42s-doubling-one-short",
        P + "stability/deviations.py",
        "        while k < m:  # d[i]",
        "        while k < m // 2:  # d[i]",
        DIGITS,
        "MDEV at m = 2, 4, 8: window sums of m/2 second differences, not m",
    ),
    Mutant(
        "h42s-phase-mean-kept",
        P + "stability/deviations.py",
        "    np.subtract(values, offset, out=x[1:])",
        "    np.subtract(values, 0.0, out=x[1:])",
        DIGITS,
        "rate → phase without the mean removed: the phase's running sum carries the 1e6 °/h",
    ),
    # issue 39 lead: the triad simulators' sample budget
    Mutant(
        "lead-turntable-sim-budget-off",
        P + "turntable/simulate.py",
        "if not wanted <= MAX_SIMULATED_SAMPLES:",
        "if wanted < 0:",
        AUDIT,
        "simulate turntable-16 --rate-hz 1e12 allocates unchecked: MemoryError, exit 1",
    ),
    Mutant(
        "lead-multipos-sim-budget-off",
        P + "multipos/simulate.py",
        "if not wanted <= MAX_SIMULATED_SAMPLES:",
        "if wanted < 0:",
        AUDIT,
        "simulate multipos --rate-hz 1e12 allocates unchecked: MemoryError, exit 1",
    ),
)


def _tree_files() -> list[str]:
    """Every file of the work tree git knows or would add (tracked and new, not ignored)."""
    out = subprocess.run(
        ["git", "-C", str(ROOT), "ls-files", "-z", "--cached", "--others", "--exclude-standard"],
        capture_output=True, check=True,
    )  # fmt: skip
    names = sorted({n for n in out.stdout.decode().split("\0") if n})
    return [n for n in names if (ROOT / n).is_file()]


def _copy_tree(dst: Path) -> None:
    for name in _tree_files():
        target = dst / name
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(ROOT / name, target)


def applies(mutant: Mutant, root: Path = ROOT) -> str | None:
    """None when ``mutant.old`` occurs exactly once in its file, else why not."""
    path = root / mutant.file
    if not path.is_file():
        return f"{mutant.file} does not exist"
    n = path.read_text(encoding="utf-8").count(mutant.old)
    if n != 1:
        return f"expression found {n} times in {mutant.file} (must be exactly once)"
    missing = [t for t in mutant.tests if not (root / t).exists()]
    if missing:
        return f"test file(s) missing: {', '.join(missing)}"
    return None


@dataclass(frozen=True)
class Outcome:
    mutant: Mutant
    status: str  # killed | SURVIVED | timeout | ERROR
    seconds: float
    detail: str


def run_one(mutant: Mutant, copy: Path, full: bool, timeout_s: float) -> Outcome:
    """Apply ``mutant`` in ``copy``, run its tests, restore the file."""
    why = applies(mutant, copy)
    if why is not None:
        return Outcome(mutant, "ERROR", 0.0, why)
    target = copy / mutant.file
    original = target.read_text(encoding="utf-8")
    target.write_text(original.replace(mutant.old, mutant.new), encoding="utf-8")
    env = {**os.environ, "PYTHONPATH": str(copy / "src"), "PYTHONDONTWRITEBYTECODE": "1"}
    tests = ["tests"] if full else list(mutant.tests)
    cmd = [sys.executable, "-m", "pytest", "-x", "-q", "-p", "no:cacheprovider",
           "-p", "no:randomly", *tests]  # fmt: skip
    t0 = time.perf_counter()
    try:
        proc = subprocess.run(
            cmd, cwd=copy, env=env, capture_output=True, text=True, check=False,
            timeout=timeout_s,
        )  # fmt: skip
    except subprocess.TimeoutExpired:
        return Outcome(mutant, "timeout", time.perf_counter() - t0, f"> {timeout_s:g} s")
    finally:
        target.write_text(original, encoding="utf-8")
    dt = time.perf_counter() - t0
    lines = proc.stdout.strip().splitlines()
    last = lines[-1] if lines else proc.stderr.strip()[-200:]
    if proc.returncode == 0:
        return Outcome(mutant, "SURVIVED", dt, last)
    if proc.returncode in (2, 3, 4, 5):  # interrupted, internal/usage error, no tests
        failed = [x for x in lines if x.startswith(("FAILED", "ERROR"))]
        if not failed:
            return Outcome(mutant, "ERROR", dt, f"pytest exit {proc.returncode}: {last}")
    first = next((x for x in lines if x.startswith(("FAILED", "ERROR"))), last)
    return Outcome(mutant, "killed", dt, first)


def _worker(jobs: queue.Queue[Mutant], results: list[Outcome], lock: threading.Lock,
            full: bool, timeout_s: float) -> None:  # fmt: skip
    with tempfile.TemporaryDirectory(prefix="thermocal-mutant-") as tmp:
        copy = Path(tmp)
        _copy_tree(copy)
        env = {**os.environ, "PYTHONPATH": str(copy / "src")}
        probe = subprocess.run(
            [sys.executable, "-c", "import thermocal; print(thermocal.__file__)"],
            cwd=copy, env=env, capture_output=True, text=True, check=False,
        )  # fmt: skip
        if not probe.stdout.strip().startswith(str(copy)):
            raise SystemExit(f"error: the copy imports {probe.stdout.strip()!r}, not itself")
        while True:
            try:
                m = jobs.get_nowait()
            except queue.Empty:
                return
            out = run_one(m, copy, full, timeout_s)
            with lock:
                results.append(out)
                print(f"{out.status:8s} {out.seconds:6.1f} s  {m.name:40s} {m.what}", flush=True)
                if out.status in ("ERROR", "SURVIVED"):
                    print(f"         {out.detail}", flush=True)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    ap.add_argument("names", nargs="*", help="run the mutants whose name contains one of these")
    ap.add_argument("--jobs", type=int, default=1, help="mutants run at once (default 1)")
    ap.add_argument("--full", action="store_true", help="run the whole suite per mutant")
    ap.add_argument("--timeout", type=float, default=900.0, help="seconds per mutant")
    ap.add_argument("--check", action="store_true", help="only check that each mutant applies")
    ap.add_argument("--list", action="store_true", help="list the mutants and exit")
    args = ap.parse_args(argv)
    names = [m.name for m in MUTANTS]
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        print(f"error: duplicate mutant names: {', '.join(dup)}", file=sys.stderr)
        return 2
    chosen = [m for m in MUTANTS if not args.names or any(w in m.name for w in args.names)]
    if args.list:
        for m in chosen:
            print(f"{m.name:40s} {m.file}  {m.what}")
        return 0
    if args.check:
        bad = [(m, why) for m in chosen if (why := applies(m)) is not None]
        for m, why in bad:
            print(f"ERROR    {m.name}: {why}")
        print(f"{len(chosen) - len(bad)} of {len(chosen)} mutants apply; {len(bad)} do not")
        return 1 if bad else 0
    jobs: queue.Queue[Mutant] = queue.Queue()
    for m in chosen:
        jobs.put(m)
    results: list[Outcome] = []
    lock = threading.Lock()
    t0 = time.perf_counter()
    threads = [
        threading.Thread(target=_worker, args=(jobs, results, lock, args.full, args.timeout))
        for _ in range(max(1, min(args.jobs, len(chosen))))
    ]
    for th in threads:
        th.start()
    for th in threads:
        th.join()
    order = {m.name: i for i, m in enumerate(MUTANTS)}
    results.sort(key=lambda o: order[o.mutant.name])
    by = {
        s: [o for o in results if o.status == s] for s in ("killed", "timeout", "SURVIVED", "ERROR")
    }
    killed = len(by["killed"]) + len(by["timeout"])
    total = len(results)
    print(
        f"\n{total} mutants in {time.perf_counter() - t0:.0f} s: killed {killed} "
        f"({len(by['timeout'])} by timeout), survived {len(by['SURVIVED'])}, "
        f"errors {len(by['ERROR'])} (did not apply: not counted as killed)"
    )
    print(f"kill rate {100.0 * killed / max(total, 1):.1f} % of all {total}")
    for status in ("SURVIVED", "ERROR", "timeout"):
        for o in by[status]:
            print(f"  {status}: {o.mutant.name} ({o.mutant.file}): {o.detail}")
    return 0 if killed == total else 1


if __name__ == "__main__":
    raise SystemExit(main())
