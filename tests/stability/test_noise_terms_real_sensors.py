"""Noise terms read where the curve follows them (issue 38, "Noise on real sensors").

Records built here with known truth, shaped like the issue's static MEMS IMU:

* white rate noise through the sensor's own first-order low-pass filter at 20 Hz (sampled at
  100 Hz: local ADEV slopes near −0.3 and −0.4 at τ = 0.01–0.04 s, not −½), a flicker floor
  (IEEE 952 PSD (B²/2π)/f, flat ADEV 0.6643·B) and rate random walk.  The angle random walk
  must be read on the −½ stretch found in the data (the filtered points lie below the white
  noise's line), the bias instability at the curve's minimum with τ, interval and quality.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
import yaml
from scipy import signal

from thermocal.cli import main
from thermocal.stability import allan, periodic
from thermocal.stability import noise_model as nm

FS = 100.0
N_DEG_SQRT_H = 0.3  # angle random walk [°/√h]
B_DEG_H = 4.0  # bias instability [°/h]
K_DEG_H_SQRT_H = 10.0  # rate random walk [°/h/√h]: the curve turns up after ~300 s
F_CUT_HZ = 20.0  # the sensor's own first-order low-pass filter


def _flicker(rng: np.random.Generator, n: int, b: float, fs: float = FS) -> np.ndarray:
    """Flicker with IEEE 952's two-sided PSD (B²/2π)/f (one-sided B²/(πf))."""
    f = np.fft.rfftfreq(n, 1.0 / fs)
    s = np.zeros_like(f)
    s[1:] = b**2 / (math.pi * f[1:])
    z = (rng.standard_normal(f.size) + 1j * rng.standard_normal(f.size)) / math.sqrt(2.0)
    return np.asarray(np.fft.irfft(z * np.sqrt(s * fs * n / 2.0), n))


def _filtered_record(seed: int, hours: float = 1.5) -> np.ndarray:
    """Rate [°/h]: white noise of density N through a unit-gain first-order low-pass filter
    at 20 Hz (its DC gain 1 keeps σ² → N²/τ at long τ), flicker B, random walk K."""
    rng = np.random.default_rng(seed)
    n = int(hours * 3600 * FS)
    white = rng.standard_normal(n) * (N_DEG_SQRT_H * 60.0) * math.sqrt(FS)
    a = math.exp(-2.0 * math.pi * F_CUT_HZ / FS)
    shaped = signal.lfilter([1.0 - a], [1.0, -a], white)
    rrw = np.cumsum(rng.standard_normal(n)) * (K_DEG_H_SQRT_H / 60.0) / math.sqrt(FS)
    return np.asarray(12.0 + shaped + _flicker(rng, n, B_DEG_H) + rrw)


@pytest.fixture(scope="module")
def filtered() -> tuple[allan.AllanResult, allan.NoiseTerms]:
    res = allan.overlapping_adev(_filtered_record(38), 1.0 / FS, "octave", unit="deg/h")
    return res, allan.noise_terms(res)


def test_the_record_has_the_issues_filtered_short_tau(
    filtered: tuple[allan.AllanResult, allan.NoiseTerms],
) -> None:
    # the scenario, computed from the curve here: slopes between the points at 0.01–0.04 s
    # are far from −½ (the sensor's own filter), and those points lie below N/√τ
    res, _nt = filtered
    lt, ld = np.log(res.tau_s), np.log(res.adev)
    slopes = np.diff(ld) / np.diff(lt)
    assert slopes[0] > -0.35 and slopes[1] > -0.46, slopes[:3]
    n_native = N_DEG_SQRT_H * 60.0
    assert res.adev[0] < 0.8 * n_native / math.sqrt(res.tau_s[0])


def test_arw_is_read_on_the_half_stretch(
    filtered: tuple[allan.AllanResult, allan.NoiseTerms],
) -> None:
    _res, nt = filtered
    arw = nt.slope.angle_random_walk
    assert arw.value is not None and arw.low is not None and arw.high is not None, arw.reason
    assert arw.low <= N_DEG_SQRT_H <= arw.high, (arw.low, arw.high)
    assert arw.value == pytest.approx(N_DEG_SQRT_H, rel=0.03)  # before the fix: −11 %
    assert arw.tau_range_s is not None and arw.tau_range_s[0] >= 0.08  # above the filter
    assert arw.tau_range_s[1] > 2.0 * arw.tau_range_s[0]
    # the filtered points are left out of the fit, which then finds N too
    assert nt.shaped_below_s is not None and 0.02 < nt.shaped_below_s <= arw.tau_range_s[0]
    fit = nt.fit.angle_random_walk
    assert fit.value == pytest.approx(N_DEG_SQRT_H, rel=0.03)


def test_kalibr_density_inherits_the_half_stretch() -> None:
    ax = nm.axis_noise(_filtered_record(39, 1.0), 1.0 / FS, name="gz", sensor="gyro", unit="deg/h")
    n_si = N_DEG_SQRT_H * math.pi / 180.0 / 60.0  # °/√h → rad/s/√Hz
    assert ax.density.method == "slope"
    assert ax.density.value == pytest.approx(n_si, rel=0.04)
    assert ax.density.low is not None and ax.density.high is not None
    assert ax.density.low <= n_si <= ax.density.high


def _long_record(seed: int, fs: float = 10.0, hours: float = 20.0) -> np.ndarray:
    """Rate [°/h] of a day-long static record at 10 Hz: white N, flicker B, random walk K."""
    rng = np.random.default_rng(seed)
    n = int(hours * 3600 * fs)
    white = rng.standard_normal(n) * (N_DEG_SQRT_H * 60.0) * math.sqrt(fs)
    rrw = np.cumsum(rng.standard_normal(n)) * (K_DEG_H_SQRT_H / 60.0) / math.sqrt(fs)
    return np.asarray(white + _flicker(rng, n, B_DEG_H, fs) + rrw)


@pytest.mark.parametrize("seed", [381, 382])
def test_bias_instability_at_the_minimum(seed: int) -> None:
    res = allan.overlapping_adev(_long_record(seed), 0.1, "octave", unit="deg/h")
    nt = allan.noise_terms(res)
    bi = nt.bias_minimum
    assert bi is not None and bi.value is not None and bi.tau_s is not None
    assert bi.low is not None and bi.high is not None and bi.unit == "deg/h"
    # the minimum among the points of ≥ 5 degrees of freedom (the last points of one or two
    # fall far below the curve by chance)
    sure = res.edf >= 5.0
    k = int(np.argmin(np.where(sure, res.adev, np.inf)))
    assert bi.tau_s == res.tau_s[k] and bi.tau_s < res.tau_s[sure][-1]
    assert bi.value == pytest.approx(res.adev[k] / 0.6643, rel=1e-3)  # IEEE 952 C.3
    # the truth's curve at that τ (its other terms add to the floor), inside the interval
    tau = bi.tau_s
    level = math.sqrt(
        (0.6643 * B_DEG_H) ** 2
        + (N_DEG_SQRT_H * 60.0) ** 2 / tau
        + (K_DEG_H_SQRT_H / 60) ** 2 * tau / 3
    )
    assert bi.low <= level / 0.6643 <= bi.high, (bi.low, level / 0.6643, bi.high)
    assert bi.value == pytest.approx(B_DEG_H, rel=0.25)
    assert bi.quality == "good", bi.reason  # the curve rises beyond both intervals after it


def test_bias_minimum_at_the_records_end_is_flagged() -> None:
    rng = np.random.default_rng(7)
    res = allan.overlapping_adev(rng.standard_normal(2**14), 1.0, "octave")
    bi = allan.noise_terms(res).bias_minimum
    assert bi is not None and bi.quality == "poor"
    assert bi.tau_s == res.tau_s[res.edf >= 5.0][-1]
    assert "record's end" in (bi.reason or "")


# --- through the command line, as a user runs it -------------------------------------------


@pytest.fixture(scope="module")
def imu_csv(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Half an hour at 100 Hz: three filtered gyro axes [°/h] and three accelerometer axes
    [mg] of white noise only (N_a = 0.05 mg·√s), as a CSV with units in the column names."""
    rng = np.random.default_rng(3838)
    n = int(0.5 * 3600 * FS)
    cols = {"time [s]": np.arange(n) / FS}
    for i, ax in enumerate("xyz"):
        cols[f"g{ax} [deg/h]"] = _filtered_record(100 + i, 0.5)
    for ax in "xyz":
        cols[f"a{ax} [mg]"] = rng.standard_normal(n) * ACC_N_MG * math.sqrt(FS)
    # a gyro of white noise and rate random walk only: a clear minimum, no flicker term for
    # the least-squares fit to find
    cols["gw [deg/h]"] = rng.standard_normal(n) * 18.0 * math.sqrt(FS) + np.cumsum(
        rng.standard_normal(n)
    ) * (600.0 / 60.0) / math.sqrt(FS)
    path = tmp_path_factory.mktemp("h38") / "static.csv"
    np.savetxt(path, np.column_stack(list(cols.values())), delimiter=",",
               header=",".join(cols), comments="", fmt="%.7g")  # fmt: skip
    return path


ACC_N_MG = 0.05  # accelerometer white noise [mg·√s]
GYRO = "gx [deg/h],gy [deg/h],gz [deg/h]"


def test_allan_json_states_the_stretch_and_the_minimum(
    imu_csv: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["allan", str(imu_csv), "--signal", "gx [deg/h]", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    arw = doc["noise_slope"]["angle_random_walk"]
    assert arw["value"] == pytest.approx(N_DEG_SQRT_H, rel=0.04)
    assert arw["low"] <= N_DEG_SQRT_H <= arw["high"]
    assert arw["tau_range_s"][0] >= 0.08  # not the filtered short τ
    assert doc["shaped_below_s"] is not None and doc["shaped_below_s"] >= 0.04
    bm = doc["bias_instability_minimum"]
    k = int(np.argmin(np.where(np.asarray(doc["edf"]) >= 5.0, doc["adev"], np.inf)))
    assert bm["tau_s"] == doc["tau_s"][k]
    assert bm["value"] == pytest.approx(doc["adev"][k] / 0.6643, rel=1e-3)
    assert bm["quality"] in ("good", "rough", "poor") and bm["unit"] == "deg/h"


def test_allan_table_never_shows_a_dash_for_the_bias_instability(
    imu_csv: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("COLUMNS", "200")
    assert main(["allan", str(imu_csv), "--signal", GYRO + ",gw [deg/h]"]) == 0
    out = capsys.readouterr().out
    row = next(line for line in out.splitlines() if "at the curve's minimum" in line)
    cells = [c.strip() for c in row.split("│")[2:-1]]
    assert len(cells) == 4 and all("deg/h (τ" in c for c in cells), row
    b_row = next(line for line in out.splitlines() if line.startswith("│ bias instability"))
    b_cells = [c.strip() for c in b_row.split("│")[2:-1]]
    # the fit's value where it finds the term, else the minimum (never a bare dash); under
    # honest standard errors the fit finds B on gz only (gx, gy: C₀ within 3σ of zero)
    assert all(c.endswith("deg/h") or c.endswith("(minimum; fit: —)") for c in b_cells), b_row
    assert any(c.endswith("deg/h") for c in b_cells[:3]), b_row
    assert b_cells[3].endswith("(minimum; fit: —)"), b_row


def test_kalibr_file_inherits_the_half_stretch(imu_csv: Path, tmp_path: Path) -> None:
    out = tmp_path / "imu.yaml"
    rc = main(["noise", str(imu_csv), "--gyro", GYRO, "--accel", "ax [mg],ay [mg],az [mg]",
               "-o", str(out)])  # fmt: skip
    assert rc == 0
    text = out.read_text(encoding="utf-8")
    doc = yaml.safe_load(text)
    n_si = N_DEG_SQRT_H * math.pi / 180.0 / 60.0  # °/√h → rad/s/√Hz
    # the largest of three axes: above the truth by at most the spread of three estimates
    assert n_si * 0.99 <= doc["gyroscope_noise_density"] <= n_si * 1.05
    assert doc["accelerometer_noise_density"] == pytest.approx(ACC_N_MG * 9.80665e-3, rel=0.03)
    assert "stretch τ =" in text.split("gyroscope_noise_density:")[0]


# --- a pulse-quantised ring-laser gyro stored on a finer grid ---------------------------------

RLG_STEP = 0.00816  # rate of one angle pulse per sample [°/s]: 8.16e-5 ° per pulse at 100 Hz
STORAGE = 2.0**-13  # the logger's storage grid [°/s] (1.22e-4, 67× finer than the step)


def _rlg_record(seed: int, n: int = 200_000) -> tuple[np.ndarray, np.ndarray]:
    """(stored rate [°/s], pulse counts): a rate with dither noise integrated to angle,
    counted in pulses of RLG_STEP·τ0 with the remainder carried (IEEE 952 C.1), the rate
    pulses·RLG_STEP stored rounded to the storage grid, three samples corrupted."""
    rng = np.random.default_rng(seed)
    rate = 0.004 + rng.standard_normal(n) * 0.07
    theta = np.concatenate([[0.0], np.cumsum(rate) / FS])
    pulses = np.diff(np.floor(theta / (RLG_STEP / FS)))
    stored = np.round(pulses * RLG_STEP / STORAGE) * STORAGE
    stored[[10, 5000, 77777]] += STORAGE * np.array([3.0, -5.0, 11.0])  # glitches
    return stored, pulses


def test_pulse_quantisation_step_is_the_sensors_lattice() -> None:
    stored, pulses = _rlg_record(77)
    found = nm.lattice_step(stored)
    assert found is not None  # before the fix: the storage grid, 1.22e-4 °/s
    step, offset, levels, n = found
    assert step == pytest.approx(RLG_STEP, rel=1e-4)
    assert levels == np.unique(pulses).size and n == stored.size
    assert offset == pytest.approx(pulses.min() * RLG_STEP, abs=STORAGE)


def test_storage_grid_alone_is_still_found() -> None:
    # an ordinary rate rounded to the grid (no coarser lattice): the grid is the step
    rng = np.random.default_rng(78)
    v = np.round(rng.standard_normal(100_000) * 20.0 * STORAGE / STORAGE) * STORAGE
    found = nm.lattice_step(v)
    assert found is not None and found[0] == pytest.approx(STORAGE, rel=1e-9)


def test_allan_reports_the_pulse_step(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    stored, pulses = _rlg_record(79)
    path = tmp_path / "rlg.csv"
    t = np.arange(stored.size) / FS
    np.savetxt(path, np.column_stack([t, stored]), delimiter=",", header="time [s],gz [deg/s]",
               comments="", fmt=["%.2f", "%.12g"])  # fmt: skip
    assert main(["allan", str(path), "--signal", "gz [deg/s]", "--json"]) == 0
    oq = json.loads(capsys.readouterr().out)["output_quantization"]
    assert oq["value"] == pytest.approx(RLG_STEP, rel=1e-4) and oq["unit"] == "deg/s"
    assert oq["levels"] == np.unique(pulses).size


# --- a periodic term -------------------------------------------------------------------------

SINE_HZ, SINE_MG, ACC_WHITE = 0.56, 0.2, 0.05  # 0.56 Hz, 0.2 mg amplitude; N_a [mg·√s]


def _sine_record(seed: int, hours: float = 1.0) -> np.ndarray:
    """Accelerometer [mg] at 100 Hz: white noise and a 0.56 Hz sinusoid of 0.2 mg."""
    rng = np.random.default_rng(seed)
    n = int(hours * 3600 * FS)
    t = np.arange(n) / FS
    return np.asarray(
        rng.standard_normal(n) * ACC_WHITE * math.sqrt(FS)
        + SINE_MG * np.sin(2.0 * math.pi * SINE_HZ * t + 0.7)
    )


def test_periodic_term_named_with_its_frequency() -> None:
    y = _sine_record(56)
    res = allan.overlapping_adev(y, 1.0 / FS, "octave", unit="mg")
    found = periodic.periodic_terms(y, 1.0 / FS, "mg")
    nt = allan.annotate_periodic(allan.noise_terms(res), res, found)
    assert len(nt.periodic) == 1
    p = nt.periodic[0]
    assert abs(p.frequency_hz - SINE_HZ) <= p.resolution_hz
    assert p.amplitude == pytest.approx(SINE_MG, rel=0.05)
    # the ADEV bump the term names is the measured curve's (IEEE 952 C.1.7, written here)
    x = math.pi * SINE_HZ * res.tau_s
    model = np.sqrt(ACC_WHITE**2 / res.tau_s + (SINE_MG * np.sin(x) ** 2 / x) ** 2)
    near = (res.tau_s > 0.1) & (res.tau_s < 10.0)
    assert np.all(np.abs(res.adev[near] / model[near] - 1.0) < 0.05)
    assert nt.quality is not None and nt.quality.quality == "poor"
    assert "0.56 Hz" in (nt.quality.reason or "")
    assert "another noise process" not in (nt.quality.reason or "")


def test_no_periodic_term_in_noise_alone() -> None:
    rng = np.random.default_rng(57)
    n = int(3600 * FS)
    y = rng.standard_normal(n) + _flicker(rng, n, 0.5) + np.cumsum(rng.standard_normal(n)) * 0.01
    assert periodic.periodic_terms(y, 1.0 / FS, "mg") == ()


def test_welch_equals_scipys() -> None:
    rng = np.random.default_rng(58)
    x = rng.standard_normal(50_000) + np.arange(50_000) * 1e-4
    f, s, _n = periodic.welch(x, 100.0, 4096)
    f2, s2 = signal.welch(x, 100.0, "hann", 4096, detrend="linear")
    assert np.allclose(f, f2) and np.allclose(s, s2, rtol=1e-10)


def test_allan_warning_names_the_frequency(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    y = _sine_record(59, 0.5)
    path = tmp_path / "acc.csv"
    np.savetxt(path, np.column_stack([np.arange(y.size) / FS, y]), delimiter=",",
               header="time [s],az [mg]", comments="", fmt=["%.2f", "%.8g"])  # fmt: skip
    assert main(["allan", str(path), "--signal", "az [mg]", "--json"]) == 0
    cap = capsys.readouterr()
    assert "periodic term at 0.56 Hz" in cap.err and "another noise process" not in cap.err
    (p,) = json.loads(cap.out)["periodic"]
    assert abs(p["frequency_hz"] - SINE_HZ) <= p["resolution_hz"]
    assert p["amplitude"] == pytest.approx(SINE_MG, rel=0.05) and p["unit"] == "mg"
