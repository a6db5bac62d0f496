"""The chamber-to-C and noise-model tutorials run as written (the runner of
``test_tutorials.py``: every ``console``/``python`` block executed in order in an empty
folder, its printed numbers compared with the page's ``text`` block) and their numbers are
the simulator's truth: the truth JSON ``thermocal simulate --truth`` writes and the
``truth_bias`` column of the simulated chamber runs, or the N, B, K the noise page draws its
samples with (IEEE Std 952-1997 Annex C formulas, evaluated here independently).
"""

from __future__ import annotations

import contextlib
import io
import json
import math
import re
import shutil
import subprocess
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pytest

from thermocal.cli import main
from tutorial_pages import TUTORIALS, _numbers, _run_in_scratch

Pages = tuple[list[tuple[str, str]], Path]


def _run(tmp: Path, name: str) -> Pages:
    return _run_in_scratch(tmp, name), tmp


@pytest.fixture(scope="module")
def chamber(tmp_path_factory: pytest.TempPathFactory) -> Pages:
    return _run(tmp_path_factory.mktemp("chamber"), "chamber-to-c.md")


@pytest.fixture(scope="module")
def noise(tmp_path_factory: pytest.TempPathFactory) -> Pages:
    return _run(tmp_path_factory.mktemp("noise"), "noise-for-estimator.md")


def _row(printed: str, label: str) -> list[float]:
    """The numbers of the table row whose first cell starts with ``label``."""
    line = next(ln for ln in printed.splitlines() if ln.startswith(f"│ {label}"))
    return _numbers(line.split("│", 2)[2])


# --- chamber run → model → validation → compensation → C --------------------------------------


def _truth(tmp: Path, name: str) -> dict[str, Any]:
    truth: dict[str, Any] = json.loads((tmp / name).read_text(encoding="utf-8"))["files"][0]
    return truth


def _deg_per_h_per_count(truth: dict[str, Any]) -> float:
    """One pulse of a sample in °/h: 1/(K·Δt) arcsec/s, and 1 arcsec/s = 1 °/h."""
    return 1.0 / (float(truth["preset"]["scale_factor"]) / float(truth["sample_rate_hz"]))


def _noise_sigma(truth: dict[str, Any]) -> float:
    """σ of one sample [°/h]: white N/√Δt and the pulse quantisation q/√6 (the difference of
    two roundings of the accumulated angle, each uniform of variance q²/12)."""
    dt = 1.0 / truth["sample_rate_hz"]
    n = truth["preset"]["noise"]["white_density"]
    return math.sqrt(n**2 / dt + _deg_per_h_per_count(truth) ** 2 / 6.0)


def test_chamber_tutorial_prints_what_the_page_shows(chamber: Pages) -> None:
    pairs, _ = chamber
    assert len(pairs) == 7
    for printed, shown in pairs:
        assert _numbers(printed) == _numbers(shown)


def test_chamber_fit_leaves_the_simulated_noise(chamber: Pages) -> None:
    """The fit's rms residual is the simulated sensor's noise (white + pulse quantisation)
    from the truth JSON, to 2 %; the page's 0.0574 °/h is that figure."""
    pairs, tmp = chamber
    truth = _truth(tmp, "mod_truth.json")
    (rms,) = _row(pairs[2][0], "rms residual")
    sigma = _noise_sigma(truth)
    assert sigma == pytest.approx(0.0574, abs=5e-5)
    assert rms == pytest.approx(sigma, rel=0.02)
    # the page's "its T1 coefficient is 0.013 °/h/°C with the gradient term, the fit's
    # 0.001": the truth's linear T1 term plus every gradient g·(T1 − Tj), and the fit's
    bias = truth["preset"]["bias_model"]
    t1 = bias["poly"][0][0] + sum(g for i, _, g in bias["gradient"] if i == 0)
    t1 -= sum(g for _, j, g in bias["gradient"] if j == 0)
    assert t1 == pytest.approx(0.013)
    assert _row(pairs[2][0], "(T1-TREF)  ")[0] == pytest.approx(0.001, abs=1e-4)


def test_chamber_validation_figures_match_the_truth(chamber: Pages) -> None:
    """Weakly correlated runs (|r| < 0.4), and within the holds what compensation leaves
    is the white noise averaged over 100 s, N/√100 [IEEE 952 Allan σ²(τ) = N²/τ]."""
    pairs, tmp = chamber
    printed = pairs[3][0]
    r = float(re.search(r"r = (-?[\d.]+) \(weakly correlated\)", printed).group(1))  # type: ignore[union-attr]
    assert abs(r) < 0.4
    assert "verdict: improved" in printed
    n = _truth(tmp, "val_truth.json")["preset"]["noise"]["white_density"]
    _before, after, _ = _row(printed, "bias stability")
    assert after == pytest.approx(n / math.sqrt(100.0), rel=0.05)
    repeat_before, repeat_after, _ = _row(printed, "bias repeatability")
    assert repeat_after < 0.05 * repeat_before


def test_chamber_model_follows_the_true_bias_on_the_validation_run(chamber: Pages) -> None:
    """On the held-out run the compensated file's model equals the simulator's
    ``truth_bias`` to 0.0009 °/h rms (about its mean: the turn-on offset is no thermal
    bias), 1.4 % of the bias's own variation, and what compensation leaves is the noise."""
    _, tmp = chamber
    truth = _truth(tmp, "val_truth.json")
    per_count = _deg_per_h_per_count(truth)
    assert per_count == pytest.approx(1 / 20)  # the page's "/ 20 counts per °/h"
    d = pd.read_csv(tmp / "val_comp.csv")
    err = d["gyro_model"].to_numpy() * per_count - d["truth_bias"].to_numpy()
    assert float(np.std(d["truth_bias"])) == pytest.approx(0.064, abs=5e-4)
    assert float(np.std(err)) == pytest.approx(0.0009, abs=5e-5)
    left = d["gyro_comp"].to_numpy() * per_count - (d["truth_rate"] - d["truth_bias"]).to_numpy()
    assert float(np.std(left)) == pytest.approx(_noise_sigma(truth), rel=0.02)


OMEGA_E = 7.292115e-5  # earth rotation rate [rad/s], WGS-84 (NIMA TR8350.2)


def test_chamber_failed_check_is_the_earth_rate(chamber: Pages) -> None:
    """Without --latitude/--axis the model's constant holds Ω sin φ (φ = 45°, up axis), and
    validate says NOT improved with the compensated mean at −Ω sin φ (+ the small offset
    of the good model)."""
    pairs, _ = chamber
    earth = math.degrees(OMEGA_E) * 3600.0 * math.sin(math.radians(45.0))  # °/h
    good = _row(pairs[2][0], "const")[0]
    bad_fit, bad_validate = pairs[6][0].split("validation of poly model", 1)
    assert _row(bad_fit, "const")[0] - good == pytest.approx(earth, abs=2e-4)
    assert "verdict: NOT improved" in bad_validate
    assert "--latitude 45 --axis up" in bad_validate
    _before, after, _ = _row(bad_validate, "mean (about zero)")
    good_after = _row(pairs[3][0], "mean (about zero)")[1]
    assert after == pytest.approx(good_after - earth, abs=0.01)


def test_chamber_rate_terms_add_little_on_this_sensor(chamber: Pages, tmp_path: Path) -> None:
    """The page's claim: the same fit without the dT terms follows truth_bias on the
    validation run about as closely (0.0009 °/h rms)."""
    _, tmp = chamber
    model, comp = tmp_path / "no_rate.json", tmp_path / "no_rate.csv"
    fit = ["fit", str(tmp / "mod.csv"), "--model", "poly", "--terms", "T1,T1^2,T1^3,T2,T3,T3^2,T4"]
    with contextlib.redirect_stdout(io.StringIO()):
        assert main([*fit, "--latitude", "45", "--axis", "up", "-o", str(model)]) == 0
        assert main(["compensate", str(model), str(tmp / "val.csv"), "-o", str(comp)]) == 0
    d = pd.read_csv(comp)
    per_count = _deg_per_h_per_count(_truth(tmp, "val_truth.json"))
    err = d["gyro_model"].to_numpy() * per_count - d["truth_bias"].to_numpy()
    assert float(np.std(err)) == pytest.approx(0.0009, abs=5e-5)


C_MAIN = r"""
#include <stdio.h>
#include "model.h"
int main(void) {
    model_state s;
    double t, temps[MODEL_N_TEMPS], y;
    model_init(&s, %(dt)r);
    while (scanf("%%lf %%lf %%lf %%lf %%lf %%lf", &t, &temps[0], &temps[1], &temps[2],
                 &temps[3], &y) == 6) {
        printf("%%.17g\n", (double)model_update(&s, t, temps, y));
    }
    return 0;
}
"""


@pytest.mark.skipif(shutil.which("cc") is None, reason="no C compiler")
def test_chamber_c_export_follows_the_true_bias(chamber: Pages, tmp_path: Path) -> None:
    """The exported C, compiled and fed the validation run sample by sample (signal in
    °/h, as its header says), gives the same model as ``compensate`` and so follows
    ``truth_bias`` to 0.0009 °/h rms."""
    _, tmp = chamber
    truth = _truth(tmp, "val_truth.json")
    per_count = _deg_per_h_per_count(truth)
    dt = 1.0 / truth["sample_rate_hz"]
    (tmp_path / "main.c").write_text(C_MAIN % {"dt": dt}, encoding="utf-8")
    exe = tmp_path / "model"
    subprocess.run(
        ["cc", "-O1", "-std=c99", "-I", str(tmp / "c"), str(tmp_path / "main.c"),
         str(tmp / "c" / "model.c"), "-lm", "-o", str(exe)],
        check=True,
    )  # fmt: skip
    d = pd.read_csv(tmp / "val_comp.csv")
    rows = np.column_stack([d["time"], d["T1"], d["T2"], d["T3"], d["T4"], d["gyro"] * per_count])
    feed = "\n".join(" ".join(repr(float(v)) for v in r) for r in rows)
    out = subprocess.run([str(exe)], input=feed, capture_output=True, text=True, check=True)
    c_model = np.array([float(v) for v in out.stdout.split()])
    assert c_model.size == len(d)
    np.testing.assert_allclose(c_model, d["gyro_model"] * per_count, rtol=0, atol=1e-9)
    err = c_model - d["truth_bias"].to_numpy()
    assert float(np.std(err)) == pytest.approx(0.0009, abs=5e-5)


# --- noise model for an estimator -----------------------------------------------------------

DEG = math.pi / 180.0
# the page's truth: N [unit/√Hz], B [unit], K [unit/s/√Hz] in deg/s and m/s²
GYRO_N, GYRO_B, GYRO_K = 0.006, 0.003, 6e-5
ACCEL_N, ACCEL_K = 1e-3, 4e-5
PAGE_TRUTH = """truth = {
    "gyro": (0.006, 0.003, 6e-5),  # N [deg/s/√Hz], B [deg/s], K [deg/s²/√Hz]
    "accel": (1e-3, 0.0, 4e-5),  # N [m/s²/√Hz], B [m/s²], K [m/s³/√Hz]
}"""


def _axes(printed: str) -> dict[str, dict[str, Any]]:
    """axis → N, K, B as (value, low, high) and the K method, from the Python block."""
    out: dict[str, dict[str, Any]] = {}
    for line in printed.splitlines():
        m = re.match(r"(g[xyz]|a[xyz])  (.*) (bound|slope|fit)  (.*)", line)
        if m:
            n_k = _numbers(m.group(2))
            b = _numbers(m.group(4))
            out[m.group(1)] = {
                "N": (n_k[0], n_k[1], n_k[2]),
                "K": (n_k[3], n_k[4], n_k[5]),
                "method": m.group(3),
                "B": (b[0], b[1], b[2]),
            }
    return out


def _holds(term: tuple[float, float, float], truth: float) -> bool:
    return term[1] <= truth <= term[2]


def test_noise_tutorial_prints_what_the_page_shows(noise: Pages) -> None:
    pairs, _ = noise
    assert len(pairs) == 9
    for printed, shown in pairs:
        assert _numbers(printed) == _numbers(shown)
    page = (TUTORIALS / "noise-for-estimator.md").read_text(encoding="utf-8")
    assert PAGE_TRUTH in page  # the truth below is the one the page simulates


def test_noise_terms_hold_the_simulated_truth(noise: Pages) -> None:
    """Every axis's 95 % N interval holds the true density; every gyro K is an upper bound
    above the true K; every gyro B interval holds the true B; the accelerometer's (no
    flicker) minimum is that of the white and random-walk lines,
    min σ² = 2NK/√3 at τ = √3 N/K (σ² = N²/τ + K²τ/3), over 0.664."""
    axes = _axes(noise[0][3][0])
    assert sorted(axes) == ["ax", "ay", "az", "gx", "gy", "gz"]
    floor = math.sqrt(2 * ACCEL_N * ACCEL_K / math.sqrt(3)) / 0.664
    assert floor == pytest.approx(3.2e-4, abs=5e-6)  # the page's 3.2·10⁻⁴
    for name, ax in axes.items():
        n_true = GYRO_N * DEG if name.startswith("g") else ACCEL_N
        assert ax["N"][0] == pytest.approx(n_true, rel=0.01), name  # the value, in SI
        if name.startswith("g"):
            assert _holds(ax["N"], GYRO_N * DEG), name
            assert ax["method"] == "bound" and ax["K"][0] >= GYRO_K * DEG, name
            assert _holds(ax["B"], GYRO_B), name
        else:
            assert _holds(ax["N"], ACCEL_N), name
            assert _holds(ax["B"], floor), name
    # the random walk: every axis's interval holds it (the page says so; before the fit's
    # standard errors counted the Allan points' correlation, az's did not); Kalibr's too
    assert [_holds(axes[a]["K"], ACCEL_K) for a in ("ax", "ay", "az")] == [True, True, True]
    # a bound rests on the interval's upper end: at 95 % above the command line's 68.3 %
    cli = {ln.split("│")[1].strip(): _numbers(ln.split("│")[3])[0]
           for ln in noise[0][1][0].splitlines() if ln.startswith("│ g")}  # fmt: skip
    assert cli["gx"] == 6.711e-06 and axes["gx"]["K"][0] == 9.04e-06  # the page's figures
    assert all(axes[g]["K"][0] > cli[g] for g in ("gx", "gy", "gz"))
    kalibr_axis = max(("ax", "ay", "az"), key=lambda a: axes[a]["K"][0])
    assert _holds(axes[kalibr_axis]["K"], ACCEL_K)


def test_noise_kalibr_file_is_continuous_time_si(noise: Pages) -> None:
    """imu.yaml holds the largest axis in rad/s/√Hz (not deg/s, not discrete): within 1 %
    of the true 0.006 °/s/√Hz·π/180 and 1 mm/s²/√Hz; the page's conversions are computed."""
    pairs, tmp = noise
    values = {k: float(v) for k, v in re.findall(r"^(\w+): ([-\d.e+]+)$", pairs[2][0], re.M)}
    assert values["gyroscope_noise_density"] == pytest.approx(GYRO_N * DEG, rel=0.01)
    assert values["accelerometer_noise_density"] == pytest.approx(ACCEL_N, rel=0.01)
    assert values["gyroscope_random_walk"] >= GYRO_K * DEG
    assert values["update_rate"] == 100.0
    assert (tmp / "imu.yaml").is_file()
    python = pairs[3][0]
    page = (TUTORIALS / "noise-for-estimator.md").read_text(encoding="utf-8")
    n = values["gyroscope_noise_density"]
    assert f"= {n * 180 / math.pi * 60:.4g} °/√h" in python
    # Kalibr's discrete values at Δt = 0.01 s: σ_c/√Δt (white), σ_c·√Δt (walk)
    assert f"{n / 0.1 * 1e3:.3g}·10⁻³ rad/s per sample" in page
    assert f"{values['gyroscope_random_walk'] * 0.1 * 1e7:.2g}·10⁻⁷ rad/s per step" in page
    assert math.isclose(GYRO_N * 60, 0.36)  # 1 °/s/√Hz = 60 °/√h
    assert f"{DEG / 60 * 1e4:.4g}·10⁻⁴ rad/s/√Hz" in page  # 2.909
    assert f"{DEG / 3600 / 60 * 1e8:.3g}·10⁻⁸ rad/s²/√Hz" in page  # 8.08
    assert f"{9.80665e-6 * 1e6:.4g}·10⁻⁶ m/s²/√Hz" in page  # 9.807
