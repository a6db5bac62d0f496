"""Issue 25: say when the data cannot support the answer (thermocal.adequacy).

Every case is written here the way other tools write files (units in column names, deg/s,
mg), through the command line; the figures the tests expect are computed here.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from typer.testing import CliRunner

from thermocal.adequacy import Needs, judge, stillness, stillness_test
from thermocal.cli import app
from thermocal.models.format import checksum


def _cli(*argv: str) -> tuple[int, str]:
    res = CliRunner().invoke(app, [*argv])
    return res.exit_code, res.output


def _write(path: Path, t: np.ndarray, cols: dict[str, np.ndarray]) -> Path:
    pd.DataFrame({"time (s)": t, **cols}).to_csv(path, index=False)
    return path


# --- the narrow sweep: 6 samples over 0.34 °C ----------------------------------------------


def _narrow(tmp_path: Path) -> Path:
    t = np.arange(6, dtype=np.float64) * 10.0
    temp = 24.0 + np.array([0.0, 0.05, 0.12, 0.2, 0.28, 0.34])
    gx = 0.1 + 0.002 * np.array([0.3, -0.2, 0.1, 0.4, -0.1, 0.2])
    return _write(tmp_path / "narrow.csv", t, {"gx [deg/s]": gx, "T1 [degC]": temp})


def test_a_narrow_sweep_is_refused_with_what_is_missing(tmp_path: Path) -> None:
    data = _narrow(tmp_path)
    out = tmp_path / "m.json"
    code, text = _cli(
        "fit",
        str(data),
        "--model",
        "poly",
        "--order",
        "3",
        "--signal",
        "gx [deg/s]",
        "--temps",
        "T1 [degC]",
        "-o",
        str(out),
    )
    assert code == 2, text
    assert not out.exists()
    last = text.strip().splitlines()[-1]
    assert last.startswith("error: ") and "the data cannot support this fit" in last
    # the span: 0.34 °C against 15 °C for a cubic; the samples: 6 for 4 coefficients
    assert "spans 0.34 °C" in last and "≥ 15 °C" in last
    assert "6 samples for 4 coefficients" in last


def test_narrow_with_override_is_written_marked_and_exported_with_a_warning(
    tmp_path: Path,
) -> None:
    data = _narrow(tmp_path)
    out = tmp_path / "m.json"
    code, text = _cli(
        "fit",
        str(data),
        "--model",
        "poly",
        "--order",
        "1",
        "--signal",
        "gx [deg/s]",
        "--temps",
        "T1 [degC]",
        "-o",
        str(out),
        "--allow-narrow",
        "--json",
    )
    assert code == 0, text
    assert "fitted anyway (--allow-narrow)" in text
    d = json.loads(out.read_text())
    ad = d["adequacy"]
    assert ad["verdict"] == "overridden" and ad["overrides"] == ["--allow-narrow"]
    span = {t["name"]: t for t in ad["tests"]}["temperature_span"]
    assert span["verdict"] == "fail" and span["figure"] == pytest.approx(0.34, abs=1e-9)
    assert span["threshold"] == 5.0
    params = tmp_path / "px4.params"
    code, text = _cli(
        "export-params",
        str(out),
        "--format",
        "px4",
        "--gyro",
        "gx [deg/s],gx [deg/s],gx [deg/s]",
        "-o",
        str(params),
    )
    # the firmware parameters say what they rest on (a duplicated axis may be refused too)
    if code == 0:
        assert "rest on data that do not support them" in text
    else:
        assert code == 2


def _failed_unoverridden(src: Path, dst: Path) -> None:
    """A model file whose adequacy failed without an override (a hand edit or another
    tool), re-signed so that the loader accepts it."""
    d = json.loads(src.read_text())
    d["adequacy"]["overrides"] = []
    d["adequacy"]["verdict"] = "fail"
    d.pop("checksum", None)
    d["checksum"] = checksum(d)
    dst.write_text(json.dumps(d))


def test_firmware_outputs_refuse_a_failed_adequacy(tmp_path: Path) -> None:
    data = _narrow(tmp_path)
    ok = tmp_path / "m.json"
    assert _cli("fit", str(data), "--model", "poly", "--order", "1", "--signal", "gx [deg/s]",
                "--temps", "T1 [degC]", "-o", str(ok), "--allow-narrow")[0] == 0  # fmt: skip
    bad = tmp_path / "bad.json"
    _failed_unoverridden(ok, bad)
    code, text = _cli("export-c", str(bad), "-o", str(tmp_path / "c"))
    assert code == 2 and "temperature_span" in text and "no firmware parameters" in text
    assert not (tmp_path / "c").exists() or not any((tmp_path / "c").iterdir())
    code, text = _cli(
        "export-params", str(bad), "--format", "px4", "-o", str(tmp_path / "p.params")
    )
    assert code == 2 and "temperature_span" in text
    assert not (tmp_path / "p.params").exists()


def test_ardupilot_minimum_sweep_at_export(tmp_path: Path) -> None:
    """A line over 8 °C is a fine fit (≥ 5 °C) but ArduPilot's learning needs 10 °C: its
    parameters are refused, PX4's written."""
    n = 3000
    t = np.arange(n) * 1.0
    temp = 20.0 + 8.0 * t / t[-1]
    rng = np.random.default_rng(3)
    cols = {}
    for ax, b in zip("xyz", (0.01, -0.02, 0.03), strict=True):
        cols[f"g{ax} [rad/s]"] = b + 1e-4 * (temp - 24.0) + rng.normal(0, 1e-4, n)
    data = _write(tmp_path / "g.csv", t, {**cols, "T1 [degC]": temp})
    cal = tmp_path / "cal.json"
    code, text = _cli(
        "fit",
        str(data),
        "--model",
        "poly",
        "--order",
        "1",
        "--signal",
        ",".join(cols),
        "--temps",
        "T1 [degC]",
        "-o",
        str(cal),
    )
    assert code == 0, text
    g = ",".join(cols)
    code, text = _cli(
        "export-params",
        str(cal),
        "--format",
        "ardupilot",
        "--gyro",
        g,
        "-o",
        str(tmp_path / "a.parm"),
    )
    assert code == 2 and "ArduPilot" in text and "10 °C" in text, text
    code, text = _cli(
        "export-params", str(cal), "--format", "px4", "--gyro", g, "-o", str(tmp_path / "p.params")
    )
    assert code == 0, text


def test_two_point_soak_cannot_carry_a_cubic(tmp_path: Path) -> None:
    """Two soaks (20 and 40 °C) determine a line, warned (no check of its shape), and
    cannot determine a cubic: refused without an override."""
    n = 1200
    t = np.arange(2 * n) * 1.0
    temp = np.r_[np.full(n, 20.0), np.full(n, 40.0)] + np.random.default_rng(1).normal(
        0, 0.01, 2 * n
    )
    ax = 2.0 + 0.05 * (temp - 30.0) + np.random.default_rng(2).normal(0, 0.1, 2 * n)
    data = _write(tmp_path / "soak.csv", t, {"ax (mg)": ax, "T1 (degC)": temp})
    code, text = _cli(
        "fit",
        str(data),
        "--model",
        "poly",
        "--order",
        "3",
        "--signal",
        "ax (mg)",
        "--temps",
        "T1 (degC)",
        "-o",
        str(tmp_path / "c.json"),
    )
    assert code == 2 and "2 distinct temperature(s)" in text and "needs ≥ 4" in text
    code, text = _cli(
        "fit",
        str(data),
        "--model",
        "poly",
        "--order",
        "1",
        "--signal",
        "ax (mg)",
        "--temps",
        "T1 (degC)",
        "-o",
        str(tmp_path / "l.json"),
    )
    assert code == 0 and "2 distinct temperatures for a polynomial of order 1" in text


def test_rate_terms_need_a_range_of_rates(tmp_path: Path) -> None:
    """A steady ramp at one rate cannot separate Ṫ terms from the constant."""
    n = 7200
    t = np.arange(n) * 1.0
    temp = -20.0 + 0.5 * t / 60.0  # 0.5 °C/min throughout
    g = 3.0 + 0.01 * temp + np.random.default_rng(5).normal(0, 0.05, n)
    data = _write(tmp_path / "ramp.csv", t, {"gz [deg/h]": g, "T1 [degC]": temp})
    code, text = _cli(
        "fit",
        str(data),
        "--model",
        "poly",
        "--terms",
        "T1,dT1",
        "--signal",
        "gz [deg/h]",
        "--temps",
        "T1 [degC]",
        "-o",
        str(tmp_path / "m.json"),
    )
    assert code == 2 and "Ṫ spans" in text and "--allow-narrow" in text
    code, text = _cli(
        "fit",
        str(data),
        "--model",
        "poly",
        "--terms",
        "T1,T1^2",
        "--signal",
        "gz [deg/h]",
        "--temps",
        "T1 [degC]",
        "-o",
        str(tmp_path / "m.json"),
    )
    assert code == 0, text


# --- stillness: motion against thermal drift -----------------------------------------------


def _still_sweep(seed: int = 0, minutes: float = 40.0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A bench sweep at 100 Hz: temperature −10 → 50 °C, gyro x whose thermal bias drifts by
    1 °/s over the sweep (strong MEMS drift), white noise 0.05 °/s [deg/s]."""
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, minutes * 60.0, 0.01)
    temp = -10.0 + 60.0 * t / t[-1]
    gx = 0.2 + 1.0 * ((temp + 10.0) / 60.0) ** 2 + rng.normal(0.0, 0.05, t.size)
    return t, temp, gx


def test_a_still_sweep_with_strong_thermal_drift_is_not_motion(tmp_path: Path) -> None:
    t, temp, gx = _still_sweep()
    data = _write(tmp_path / "still.csv", t, {"gx [deg/s]": gx, "T1 [degC]": temp})
    code, text = _cli(
        "fit",
        str(data),
        "--model",
        "poly",
        "--order",
        "2",
        "--signal",
        "gx [deg/s]",
        "--temps",
        "T1 [degC]",
        "-o",
        str(tmp_path / "m.json"),
        "--json",
    )
    assert code == 0, text
    assert "moved" not in text
    d = json.loads((tmp_path / "m.json").read_text())
    st = {x["name"]: x for x in d["adequacy"]["tests"]}["stillness"]
    assert st["verdict"] == "pass" and st["figure"] == 0.0


def test_a_bump_is_named_with_its_time(tmp_path: Path) -> None:
    """1.5 s at 20 °/s, 900 s into the sweep: warned with its time and size."""
    t, temp, gx = _still_sweep(1)
    gx = gx.copy()
    gx[(t >= 900.0) & (t < 901.5)] += 20.0
    data = _write(tmp_path / "bump.csv", t, {"gx [deg/s]": gx, "T1 [degC]": temp})
    code, text = _cli(
        "fit",
        str(data),
        "--model",
        "poly",
        "--order",
        "2",
        "--signal",
        "gx [deg/s]",
        "--temps",
        "T1 [degC]",
        "-o",
        str(tmp_path / "m.json"),
    )
    assert code == 0, text
    assert "the sensor moved at 900.0–902.0 s (up to 20" in text


def test_a_flight_like_log_is_refused_unless_allowed(tmp_path: Path) -> None:
    """The sensor turning at tens of °/s for most of the record (a flight)."""
    t, temp, gx = _still_sweep(2, minutes=20.0)
    flight = gx + 30.0 * np.sin(2 * np.pi * t / 7.0) * np.sin(2 * np.pi * t / 61.0)
    data = _write(tmp_path / "flight.csv", t, {"gx [deg/s]": flight, "T1 [degC]": temp})
    argv = ["fit", str(data), "--model", "poly", "--order", "2", "--signal", "gx [deg/s]",
            "--temps", "T1 [degC]", "-o", str(tmp_path / "m.json")]  # fmt: skip
    code, text = _cli(*argv)
    assert code == 2 and "the sensor moved during" in text and "--allow-motion" in text
    assert not (tmp_path / "m.json").exists()
    code, text = _cli(*argv, "--allow-motion")
    assert code == 0 and "fitted anyway (--allow-motion)" in text
    assert json.loads((tmp_path / "m.json").read_text())["adequacy"]["verdict"] == "overridden"


# --- the functions against hand computations -----------------------------------------------


def test_stillness_threshold_follows_the_noise() -> None:
    """A noisy sensor (σ = 3 °/s white at 100 Hz): the 1-s medians (over every 2nd sample:
    ≤ 64 a block) scatter 1.25·3/√50, so the threshold is 8× that, not the 0.3 °/s floor,
    and the noise alone is still."""
    rng = np.random.default_rng(9)
    t = np.arange(0.0, 600.0, 0.01)
    g = rng.normal(0.0, 3.0, t.size) * 3600.0
    mot = stillness(t, g, 0.3 * 3600.0)
    per_block = 100 // math.ceil(100 / 64)  # 100 a block, decimated to every 2nd: 50
    expected = 8.0 * 1.25 * 3.0 * 3600.0 / math.sqrt(per_block)
    assert mot.threshold == pytest.approx(expected, rel=0.05)
    assert mot.share == 0.0 and not mot.steps


def test_judge_counts_distinct_temperatures_like_a_hand_count() -> None:
    """Three soaks (10, 25, 40 °C) hold 3 distinct temperatures: a quadratic is just
    determined (warn), a cubic refused; the span is 30 °C."""
    temps = np.r_[np.full(100, 10.0), np.full(100, 25.0), np.full(100, 40.0)][:, None]
    times = np.arange(300.0)
    for order, verdict in ((2, "warn"), (3, "fail")):
        ad = judge(Needs({"T": order}, order + 1), [times], [temps], ["T"])
        tests = {t.name: t for t in ad.tests}
        assert tests["distinct_temperatures"].figure == 3.0
        assert tests["distinct_temperatures"].verdict == verdict
        assert tests["temperature_span"].figure == 30.0


def test_a_re_oriented_accelerometer_is_a_step() -> None:
    """A triad tilted 10° about y at 300 s: a step of 2 g sin(5°) = 174.3 mg at 300 s."""
    rng = np.random.default_rng(4)
    t = np.arange(0.0, 600.0, 0.02)
    tilt = np.where(t >= 300.0, math.radians(10.0), 0.0)
    a = np.column_stack([1000 * np.sin(tilt), np.zeros_like(t), 1000 * np.cos(tilt)])
    a = a + rng.normal(0.0, 1.0, a.shape)
    test = stillness_test(t, a, "accel", "acc")
    assert test.verdict == "fail" and "at 300.0 s" in test.message and "(10.0°)" in test.message
    mot = stillness(t, a, 20.0)
    assert mot.steps[0][1] == pytest.approx(2000.0 * math.sin(math.radians(5.0)), rel=0.01)


# --- turntable over temperature: the soaks ---------------------------------------------------


def test_turntable_soaks_too_close_are_refused_or_marked(tmp_path: Path) -> None:
    """Two soak runs moved to 20 and 22 °C: a line in temperature needs 5 °C — refused;
    with --allow-narrow written, marked 'overridden' in the calibration, and export-c
    warns; a record edited to a plain failure makes export-c refuse."""
    from thermocal.turntable.simulate import simulate_turntable_thermal
    from thermocal.writers import write_recording

    runs = [r for r in simulate_turntable_thermal(seed=11) if not r[1]["held_out"]][:2]
    paths = []
    for (rec, truth), base in zip(runs, (20.0, 22.0), strict=True):
        t = rec.columns["T_imu"]
        rec.columns["T_imu"] = base + (t - t.mean()) * 0.01  # drifting 0.015 °C in the run
        p = tmp_path / f"{truth['label']}.parquet"
        write_recording(rec, p)
        paths.append(str(p))
    cal = tmp_path / "cal.json"
    code, text = _cli("turntable", *paths, "--temps", "T_imu", "-o", str(cal))
    assert code == 2 and "the soak temperatures spans 2" in text and "≥ 5 °C" in text, text
    assert not cal.exists()
    code, text = _cli("turntable", *paths, "--temps", "T_imu", "-o", str(cal), "--allow-narrow")
    assert code == 0, text
    tri = json.loads(cal.read_text())["triads"][0]
    assert tri["adequacy"]["verdict"] == "overridden"
    code, text = _cli("export-c", str(cal), "-o", str(tmp_path / "c"))
    assert code == 0 and "rest on data that do not support them" in text
    d = json.loads(cal.read_text())
    for t in d["triads"]:
        t["adequacy"]["overrides"] = []
    d.pop("checksum")
    d["checksum"] = checksum(d)
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(d))
    code, text = _cli("export-c", str(bad), "-o", str(tmp_path / "c2"))
    assert code == 2 and "temperature_span" in text, text


def test_fit_prints_in_the_data_unit(tmp_path: Path) -> None:
    """The residual of a °/s gyro is printed and given in °/s (it was °/h, ×3600)."""
    t, temp, gx = _still_sweep(4, minutes=20.0)
    data = _write(tmp_path / "g.csv", t, {"gx [deg/s]": gx, "T1 [degC]": temp})
    code, text = _cli(
        "fit", str(data), "--model", "poly", "--order", "2", "--signal", "gx [deg/s]",
        "--temps", "T1 [degC]", "-o", str(tmp_path / "m.json"), "--json",
    )  # fmt: skip
    assert code == 0, text
    d = json.loads(text[text.index("{") :])
    # the residual of a quadratic fit to a quadratic bias is the white noise, 0.05 °/s
    assert d["unit"] == "deg/s" and d["model_unit"] == "deg/h"
    assert d["rms_residual"] == pytest.approx(0.05, rel=0.02)
    assert d["rms_residual_model_unit"] == pytest.approx(d["rms_residual"] * 3600.0, rel=1e-12)


class _ColumnsWhenAsked:
    """An (n, k) array-like that hands out a new copy of a column at each ``[:, j]`` (as
    :class:`thermocal.pipeline.fit_columns.TemperatureBlocks` does) and refuses to be read
    whole."""

    def __init__(self, values: np.ndarray) -> None:
        self._values, self.shape, self.ndim = values, values.shape, 2

    def __getitem__(self, key: object) -> np.ndarray:
        assert isinstance(key, tuple) and key[0] == slice(None), key
        return self._values[:, key[1]].copy()

    def __array__(self, *a: object, **k: object) -> np.ndarray:
        raise AssertionError("read whole")


@pytest.mark.parametrize("with_nan", [False, True])
def test_temperatures_read_a_column_at_a_time_are_judged_as_an_array(with_nan: bool) -> None:
    """judge() takes each run's temperatures a column at a time: an array-like that reads
    its columns when asked is judged, test for test, as the array itself (the span's
    percentiles, distinct bins and range ends by a formula written here), NaN dropped."""
    t = np.arange(0.0, 20_000.0, 1.0)
    temps = np.column_stack([10.0 + 30.0 * t / t[-1], 20.0 + 5.0 * np.sin(t / 900.0)])
    if with_nan:
        temps[::97, 0] = np.nan
    needs = Needs({"T1": 2, "T2": 1}, 6)
    want = judge(needs, [t, t], [temps, temps], ["T1", "T2"]).to_dict()
    lazy: list = [_ColumnsWhenAsked(temps)]
    got = judge(needs, [t, t], [*lazy, _ColumnsWhenAsked(temps)], ["T1", "T2"]).to_dict()
    assert got == want
    one = judge(needs, [t], lazy, ["T1", "T2"]).to_dict()
    assert one == judge(needs, [t], [temps], ["T1", "T2"]).to_dict()
    span = next(x for x in one["tests"] if x["name"] == "temperature_span")  # T1's
    col = temps[:, 0][np.isfinite(temps[:, 0])]
    lo, hi = np.percentile(col, [0.1, 99.9])
    assert span["figure"] == pytest.approx(hi - lo, rel=1e-12)
