"""Accelerometers with gravity in the data, and coefficients about TREF (issue 15).

References from outside the code: WGS-84 normal gravity at the equator and the poles
(NIMA TR8350.2, 3rd ed., table 3.4: γe = 9.7803253359, γp = 9.8321849378 m/s²); the
simulator's true cubic in x = (T − 25)/40, which about TREF = 25 °C has the coefficients
c_j / 40^j.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from thermocal import units
from thermocal.cli import main
from thermocal.errors import UnitError
from thermocal.simulate import SCENARIOS
from thermocal.writers import write_recording


def test_normal_gravity_matches_the_wgs84_table() -> None:
    assert units.normal_gravity_m_s2(0.0) == pytest.approx(9.7803253359, abs=1e-10)
    assert units.normal_gravity_m_s2(90.0) == pytest.approx(9.8321849378, abs=1e-9)
    assert units.normal_gravity_m_s2(-90.0) == pytest.approx(9.8321849378, abs=1e-9)
    g45 = units.normal_gravity_m_s2(45.0)
    assert 9.806 < g45 < 9.8063  # between, and not the mean of, the two
    with pytest.raises(UnitError):
        units.normal_gravity_m_s2(91.0)


@pytest.mark.parametrize(
    ("axis", "gaxis", "want"),
    [("z", "+z", 1000.0), ("z", "-z", -1000.0), ("x", "+z", 0.0), ("y", "-y", -1000.0)],
)
def test_gravity_on_axis(axis: str, gaxis: str, want: float) -> None:
    assert units.gravity_on_axis_mg(axis, gaxis, units.STANDARD_GRAVITY_M_S2) == want


def test_gravity_axis_is_parsed_strictly() -> None:
    with pytest.raises(UnitError, match="pointing up"):
        units.parse_gravity_axis("up")


@pytest.fixture(scope="module")
def imu(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path, dict]:
    d = tmp_path_factory.mktemp("grav")
    ((mod, truth),) = SCENARIOS["mems-imu"](4, rate_hz=0.2)
    ((val, _),) = SCENARIOS["mems-imu"](4, run="validation", rate_hz=0.2)
    write_recording(mod, d / "mod.parquet")
    write_recording(val, d / "val.parquet")
    return d / "mod.parquet", d / "val.parquet", truth


def _fit(mod: Path, out: Path, *extra: str) -> dict:
    import contextlib
    import io

    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        status = main(["fit", str(mod), "--model", "poly", "--order", "3", "--temps", "T_die",
                       "-o", str(out), "--json", *extra])  # fmt: skip
    assert status == 0, buf.getvalue()
    return dict(json.loads(buf.getvalue()))


def test_gravity_axis_keeps_gravity_in_the_compensated_output(
    imu: tuple[Path, Path, dict], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    mod, val, _truth = imu
    cal = tmp_path / "cal.json"
    res = _fit(mod, cal, "--signal", "ax,ay,az", "--gravity-axis", "+z", "--gravity", "9.80665")
    ch = res["channels"]
    # the triad is fitted together: gravity along its measured mean direction f̄/|f̄|,
    # g = 1000 mg (the simulator's horizontal mean biases read as a tilt of a few degrees)
    m = pd.read_parquet(mod)
    f = np.array([m[n].mean() for n in ("ax", "ay", "az")])
    want = 1000.0 * f / np.linalg.norm(f)
    got = np.array([ch[n]["known_input"]["value"] for n in ("ax", "ay", "az")])
    np.testing.assert_allclose(got, want, atol=1e-6)
    assert "+z up" in ch["az"]["known_input"]["what"]
    assert "measured direction" in ch["az"]["known_input"]["what"]
    assert main(["compensate", str(cal), str(val), "-o", str(tmp_path / "c.parquet")]) == 0
    capsys.readouterr()
    d = pd.read_parquet(tmp_path / "c.parquet")
    # gravity stays: the compensated z output is its share of 1 g plus what the model did
    # not explain
    comp_az = d["az_comp"] - want[2]
    assert float(np.mean(comp_az)) == pytest.approx(0.0, abs=0.2)
    # and the temperature-induced bias is gone from it (the model is the bias alone)
    err = (d["az_model"] - d["az_model"].mean()) - (d["truth_az"] - d["truth_az"].mean())
    assert float(np.sqrt(np.mean(err**2))) < 0.03 * float(d["truth_az"].std())


def test_without_gravity_axis_a_warning_says_compensation_takes_gravity_out(
    imu: tuple[Path, Path, dict], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    mod, _val, _t = imu
    res = _fit(mod, tmp_path / "m.json", "--signal", "az")
    err = capsys.readouterr().err
    assert "gravity is in the data" in err and "--gravity-axis" in err
    assert any("gravity is in the data" in w for w in res["warnings"]) or "az_comp" in err


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--signal", "ax,ay,az", "--gravity-axis", "+x"], "ax should read about +1000.0 mg"),
        (["--signal", "ax,ay,az", "--gravity-axis", "-z"], "az should read about -1000.0 mg"),
        (["--signal", "az", "--gravity-axis", "up"], "pointing up"),
        (["--signal", "az", "--gravity", "9.8"], "--gravity applies with --gravity-axis"),
        (["--signal", "az", "--gravity-axis", "+z", "--gravity", "98.1"], "9.78-9.83"),
        (["--signal", "gx,gy", "--latitude", "45", "--axis", "up"], "one signal at a time"),
        (["--signal", "az", "--model", "piecewise", "--tref", "25"], "--tref applies"),
    ],
)
def test_orientation_mistakes_are_refused(
    imu: tuple[Path, Path, dict], tmp_path: Path, capsys: pytest.CaptureFixture[str],
    args: list[str], message: str,
) -> None:  # fmt: skip
    mod, _v, _t = imu
    out = tmp_path / "m.json"
    base = ["fit", str(mod), "--temps", "T_die", "-o", str(out)]
    if "--model" not in args:
        base += ["--model", "poly", "--order", "3"]
    assert main([*base, *args]) == 2
    assert message in capsys.readouterr().err
    assert not out.exists()


def test_a_tilted_horizontal_axis_is_warned(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    ((mod, _t),) = SCENARIOS["mems-imu"](6, rate_hz=0.2)
    ax = mod.column("ax") - mod.column("ax").mean() + 208.0  # asin(0.208) = 12.0°
    frame = pd.DataFrame({"time": mod.time_s, "T_die": mod.column("T_die"), "ax": ax,
                          "az": mod.column("az") - 22.0})  # fmt: skip
    frame.to_csv(tmp_path / "tilt.csv", index=False)
    res = _fit(tmp_path / "tilt.csv", tmp_path / "m.json", "--signal", "ax,az",
               "--signal-unit", "mg", "--time-unit", "s", "--temp-unit", "degC",
               "--gravity-axis", "+z")  # fmt: skip
    err = capsys.readouterr().err
    assert "tilt of about 12°" in err  # asin(0.208) = 12.0°
    assert "standard gravity" in err  # no --gravity nor --latitude: stated
    assert res["channels"]["ax"]["known_input"]["value"] == 0.0


def test_tref_coefficients_recover_the_simulators_truth(
    imu: tuple[Path, Path, dict], tmp_path: Path
) -> None:
    mod, _v, truth = imu
    res = _fit(mod, tmp_path / "cal.json", "--signal", "ax,az", "--gravity-axis", "+z",
               "--gravity", "9.80665", "--tref", "25")  # fmt: skip
    for name in ("ax", "az"):
        tref = res["channels"][name]["tref"]
        assert tref["tref_c"] == 25.0
        got = [c["value"] for c in tref["coefficients"]]
        names = [c["name"] for c in tref["coefficients"]]
        assert names == ["const", "(T1-TREF)", "(T1-TREF)^2", "(T1-TREF)^3"]
        c = truth["channels"][name]["coefficients"]
        want = [c[j] / 40.0**j for j in range(4)]
        for j in range(4):
            se = tref["coefficients"][j]["stderr"]
            # the constant holds also the noise mean; the slopes come from the temperature
            tol = max(6.0 * se, 0.002 * abs(want[j]) if j else 0.05)
            assert got[j] == pytest.approx(want[j], abs=tol), (name, j, got[j], want[j])


def test_tref_coefficients_are_the_same_polynomial(
    imu: tuple[Path, Path, dict], tmp_path: Path
) -> None:
    mod, _v, _t = imu
    res = _fit(mod, tmp_path / "m.json", "--signal", "gx", "--tref", "-10")
    raw = [c["value"] for c in res["coefficients"]]
    about = [c["value"] for c in res["tref"]["coefficients"]]
    T = np.linspace(-20.0, 70.0, 13)
    p_raw = np.polyval(raw[::-1], T)
    p_ref = np.polyval(about[::-1], T + 10.0)
    np.testing.assert_allclose(p_ref, p_raw, rtol=1e-10, atol=1e-9 * float(np.max(np.abs(p_raw))))
