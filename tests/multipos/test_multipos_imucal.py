"""``thermocal multipos --poses`` on imucal's own example Ferraris session (issue 38), against
imucal's result on the same data.

**The data** (``tests/data/imucal_ferraris/``, MIT, see its README): a 6-DOF IMU at 102.4 Hz,
gyro in deg/s, accelerometer in m/s², the six faces ``x_p … z_a`` then the three turns
``x_rot``, ``y_rot``, ``z_rot`` (clockwise, with the named axis up), as imucal's guide
tells users to record them.  The file has a sample counter and no time column; thermocal
needs one, so the test writes ``time_s = n_samples / 102.4`` (imucal's
``sampling_rate_hz=102.4``) beside a copy of the data.

**The reference** was computed with imucal 2.6.0 itself, in a scratch venv
(``python3 -m venv /tmp/imucal-venv; /tmp/imucal-venv/bin/pip install imucal``), as its
``examples/basic_ferraris.py`` does::

    data = pd.read_csv("example_ferraris_session.csv", header=0, index_col=0)
    section_list = pd.read_json("example_ferraris_session_list.json").T
    regions = ferraris_regions_from_section_list(data, section_list)
    ci = FerrarisCalibration().compute(regions, sampling_rate_hz=102.4,
                                       from_acc_unit="m/s^2", from_gyr_unit="deg/s")

and the numbers below are ``ci.K_g @ ci.R_g``, ``ci.K_a @ ci.R_a``, ``ci.b_g``, ``ci.b_a``
printed to 17 digits.  imucal is no dependency of thermocal.

**The mapping.** imucal calibrates ``ω = R_g⁻¹ K_g⁻¹ (ω_raw − K_ga a − b_g)``, i.e. the raw
rate is ``K_g R_g ω + K_ga a + b_g``; thermocal's model is ``ω_raw = (I + E_g) ω + b_g``.
So ``I + E_g = K_g R_g`` (imucal builds it as ``W_s / (−360°)``, the integrated turns as
columns, so ``K_g R_g`` is exactly that matrix): thermocal's scale factor i is
``(K_g R_g)_ii − 1`` [ppm] — not ``K_g,ii − 1``, which differs by the misalignments'
second order (+27 924 against +27 903 ppm on x) — and its misalignment ``ab`` is the
element of :data:`thermocal.turntable.model.MISALIGNMENT_INDEX` (``yx`` = row 0,
column 1 …) [rad → ″].  Both take the gyro bias as the mean of every sample of the six
faces (without ``--latitude`` thermocal takes no earth rate off, as imucal).  The same
holds for the accelerometer: ``I + E_a = K_a R_a`` (``R_a = K_a⁻¹ U_a_d / 2g`` with
imucal's ``grav = 9.81``, thermocal's six-face closed form with ``--gravity 9.81``).

**The tolerance.** imucal's gyro comes from the three turns alone, each taken exactly
about its axis; thermocal's from the turns and the five motions between the faces, with
the g-sensitivity ``K_ga`` imucal takes off and thermocal does not model
(``K_ga g T/360°`` ≈ 35 ppm on x, well inside σ).  A hand's turn leans off its axis:
thermocal finds the lean in the data (the turns disagree with the motions; 0.36° per
component here, reported as ``turn_axis_lean_deg``) and counts it, so its misalignments
lean on the motions; imucal's take the lean as the gyro's (each is off by the lean,
about 1300″).  So the scale factors (the lean enters them only as 1 − cos) must agree
within thermocal's σ (1σ, σ below 1000 ppm), the misalignments within
``√(σ² + lean²)``; the lean itself is checked against the accelerometer: the mean up
direction during each turn is 0.21–0.34° off the turn's axis (computed in the test).
The check is not vacuous: the bug this test was written for (every turn taken about the
up direction of the last face, z_a) gave +6.46e6 / +8.34e6 / −75 300 ppm.
"""

from __future__ import annotations

import contextlib
import io
import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from thermocal.cli import main
from thermocal.errors import ThermocalWarning
from thermocal.multipos.calibrate import SessionResult, calibrate_session
from thermocal.multipos.poses import parse_poses
from thermocal.multipos.simulate import random_truth, simulate_session
from thermocal.turntable.model import MISALIGNMENT_INDEX, MISALIGNMENT_NAMES

DATA = Path(__file__).parents[1] / "data" / "imucal_ferraris"
CSV = DATA / "example_ferraris_session.csv"
POSES = DATA / "example_ferraris_session_list.json"
RATE_HZ = 102.4
GRAV = 9.81  # imucal's default grav [m/s²]
MG = 9.80665e-3
RAD_TO_ARCSEC = 180.0 / np.pi * 3600.0
DEG = np.pi / 180.0

# imucal 2.6.0 on this session (module docstring)
IMUCAL_KG_RG = np.array([
    [1.0279030921108503, -0.00046689722733542574, -0.006590606955485163],
    [-0.00021830076271155843, 0.982423943314377, -0.0027347345695309115],
    [0.009697592565938506, 0.0076281835698891395, 0.9982342394732935],
])  # fmt: skip
IMUCAL_KA_RA = np.array([
    [0.9966083432390234, -0.014782310326065154, -0.007457416390046589],
    [0.008597647264494957, 1.002399044531187, 0.0018480118201669386],
    [0.01364307550082869, 0.0020504932882582476, 1.0233023499168432],
])  # fmt: skip
IMUCAL_B_G = np.array([-0.5996686296674446, -0.36984313466306884, 0.0587739354671091])  # deg/s
IMUCAL_B_A = np.array([0.5371174244458201, -0.6162029930860964, 0.3988673423902682])  # m/s²


def _theta_of(m: np.ndarray) -> np.ndarray:
    """Scale factors [ppm] and misalignments [″] (thermocal's order) of ``I + E = m``."""
    e = m - np.eye(3)
    mis = [e[MISALIGNMENT_INDEX[n]] * RAD_TO_ARCSEC for n in MISALIGNMENT_NAMES]
    return np.concatenate([np.diag(e) * 1e6, mis])


def _run(args: list[str]) -> tuple[int, str, str]:
    o, e = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(o), contextlib.redirect_stderr(e):
        code = main(args)
    return code, o.getvalue(), e.getvalue()


def _with_time(dst: Path) -> Path:
    """A copy of the session with ``time_s = n_samples / 102.4`` in front (docstring)."""
    lines = CSV.read_text(encoding="ascii").splitlines()
    out = ["time_s," + lines[0].split(",", 1)[1]]
    for ln in lines[1:]:
        n, rest = ln.split(",", 1)
        out.append(f"{int(n) / RATE_HZ!r},{rest}")
    dst.write_text("\n".join(out) + "\n", encoding="ascii")
    return dst


def _cli_args(csv: Path, poses: Path, out: Path) -> list[str]:
    return ["multipos", str(csv), "--time", "time_s", "--time-unit", "s",
            "--accel", "acc_x,acc_y,acc_z", "--gyro", "gyr_x,gyr_y,gyr_z",
            "--accel-unit", "m/s^2", "--gyro-unit", "deg/s", "--gravity", str(GRAV),
            "--poses", str(poses), "-o", str(out)]  # fmt: skip


@pytest.fixture(scope="module")
def session(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    d = tmp_path_factory.mktemp("imucal")
    csv = _with_time(d / "session.csv")
    code, out, err = _run([*_cli_args(csv, POSES, d / "cal.json"), "--json"])
    assert code == 0, err
    assert "warning" not in err.lower(), err
    return {"dir": d, "csv": csv, "cli": json.loads(out)}


@pytest.fixture(scope="module")
def api() -> SessionResult:
    """The Python API on the same arrays: accelerometer in mg, gyro in rad/s."""
    raw = np.genfromtxt(CSV, delimiter=",", names=True)
    t = raw["n_samples"] / RATE_HZ
    acc = np.column_stack([raw[c] for c in ("acc_x", "acc_y", "acc_z")]) / MG
    gyr = np.column_stack([raw[c] for c in ("gyr_x", "gyr_y", "gyr_z")]) * DEG
    secs = parse_poses(json.loads(POSES.read_text(encoding="utf-8")), t.size, str(POSES))
    return calibrate_session(t, acc, gyr, g_mg=GRAV / MG, sections=secs, where=str(CSV),
                             sections_from=str(POSES))  # fmt: skip


def test_gyro_scale_factors_and_misalignments_equal_imucal_within_sigma(
    session: dict[str, Any],
) -> None:
    """Through the CLI: the gyro scale factors within 1σ of imucal's (+27 903 / −17 576 /
    −1 766 ppm), σ below 1000 ppm; the misalignments within √(σ² + lean²) of imucal's
    (module docstring)."""
    g = session["cli"]["gyro"]
    run = session["cli"]["runs"][0]["gyro"]
    assert g["method"] == "rotations between poses and 360° turns" and run["n_turns"] == 3
    mine = np.concatenate([g["scale_factor_ppm"], g["misalignment_arcsec"]])
    sig = np.concatenate([g["scale_factor_ppm_sigma"], g["misalignment_arcsec_sigma"]])
    ref = _theta_of(IMUCAL_KG_RG)
    np.testing.assert_allclose(ref[0:3], [27903.09, -17576.06, -1765.76], atol=0.01)
    assert np.all(sig[0:3] < 1000.0), sig
    lean = run["turn_axis_lean_deg"] * 3600.0
    tol = np.concatenate([sig[0:3], np.sqrt(sig[3:] ** 2 + lean**2)])
    z = (mine - ref) / tol
    assert np.all(np.abs(z) < 1.0), dict(zip(["x", "y", "z", *MISALIGNMENT_NAMES], z, strict=True))


def test_turn_axis_lean_agrees_with_the_accelerometer(session: dict[str, Any]) -> None:
    """The lean thermocal finds (sd per component) against the accelerometer's own view:
    the angle between the calibrated mean specific force during each turn and the turn's
    axis (0.21°, 0.34°, 0.23°; a hand's centripetal push in it too), written here with
    thermocal's accelerometer calibration.  Their rms angle, per component (÷√2), and
    the lean agree within a factor 3: the lean is the board's, not a fitting artefact."""
    lean = session["cli"]["runs"][0]["gyro"]["turn_axis_lean_deg"]
    a = session["cli"]["accel"]
    e = np.diag(np.asarray(a["scale_factor_ppm"]) * 1e-6)
    for n, v in zip(MISALIGNMENT_NAMES, a["misalignment_arcsec"], strict=True):
        e[MISALIGNMENT_INDEX[n]] = v / RAD_TO_ARCSEC
    raw = np.genfromtxt(CSV, delimiter=",", names=True)
    acc = np.column_stack([raw[c] for c in ("acc_x", "acc_y", "acc_z")])
    secs = json.loads(POSES.read_text(encoding="utf-8"))
    off = []
    for j, name in enumerate(("x_rot", "y_rot", "z_rot")):
        m = acc[secs[name]["start"] : secs[name]["end"]].mean(axis=0) - a["bias"]
        c = np.linalg.solve(np.eye(3) + e, m)
        off.append(np.degrees(np.arccos(abs(c[j]) / np.linalg.norm(c))))
    np.testing.assert_allclose(off, [0.21, 0.34, 0.23], atol=0.01)
    per_component = float(np.sqrt(np.mean(np.square(off)) / 2.0))
    assert 1.0 / 3.0 < lean / per_component < 3.0, (lean, per_component)


def test_gyro_bias_equals_imucal(session: dict[str, Any]) -> None:
    """The gyro bias is imucal's (the mean of every sample of the six faces, no earth rate
    taken off without --latitude) to 1e-9 °/s, in the data's unit."""
    g = session["cli"]["gyro"]
    assert g["bias_unit"] == "deg/s"
    np.testing.assert_allclose(g["bias"], IMUCAL_B_G, rtol=0, atol=1e-9)


def test_accelerometer_equals_imucal(session: dict[str, Any]) -> None:
    """The accelerometer's E is imucal's ``K_a R_a − I`` (the same closed form: Ferraris's
    eq. 21–23) to 1e-6 ppm/″.  Its bias is the mean of the six face means (all three
    pairs, since ``f_j+ + f_j− = 2b`` for every j), written here; imucal's ``b_a`` takes
    component j of pair j only, so the two differ by the pairs' disagreement on this
    hand-held session (up to 0.04 m/s² between pairs), which bounds their difference."""
    a = session["cli"]["accel"]
    assert a["method"] == "six-face" and a["bias_unit"] == "m/s^2"
    mine = np.concatenate([a["scale_factor_ppm"], a["misalignment_arcsec"]])
    np.testing.assert_allclose(mine, _theta_of(IMUCAL_KA_RA), rtol=0, atol=1e-6)
    raw = np.genfromtxt(CSV, delimiter=",", names=True)
    acc = np.column_stack([raw[c] for c in ("acc_x", "acc_y", "acc_z")])
    secs = json.loads(POSES.read_text(encoding="utf-8"))
    m = {k: acc[v["start"] : v["end"]].mean(axis=0) for k, v in secs.items()
         if not k.endswith("_rot")}  # fmt: skip
    np.testing.assert_allclose(a["bias"], sum(m.values()) / 6.0, rtol=0, atol=1e-9)
    pairs = np.array([(m[f"{ax}_p"] + m[f"{ax}_a"]) / 2 for ax in "xyz"])  # (pair, axis)
    spread = pairs.max(axis=0) - pairs.min(axis=0)
    assert np.all(np.abs(np.asarray(a["bias"]) - IMUCAL_B_A) <= spread), spread


def test_python_api_equals_cli(session: dict[str, Any], api: SessionResult) -> None:
    """``calibrate_session`` on the arrays gives the CLI's gyro figures."""
    g = session["cli"]["gyro"]
    assert api.gyro is not None and api.gyro.n_turns == 3
    np.testing.assert_allclose(api.gyro.theta[3:6], g["scale_factor_ppm"], rtol=1e-9)
    np.testing.assert_allclose(api.gyro.theta[6:], g["misalignment_arcsec"], rtol=1e-9)
    np.testing.assert_allclose(api.gyro.theta[0:3] / 3600.0, IMUCAL_B_G, atol=1e-9)


def _one_error_line(err: str) -> str:
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("error:"), err
    return lines[0]


def test_swapped_turns_refused(session: dict[str, Any]) -> None:
    """A POSES file whose x_rot and y_rot are swapped: exit 2, one line naming the file,
    the section, what the gyro measured and the POSES file to fix; nothing written."""
    d = session["dir"]
    secs = json.loads(POSES.read_text(encoding="utf-8"))
    secs["x_rot"], secs["y_rot"] = secs["y_rot"], secs["x_rot"]
    bad = d / "swapped.json"
    bad.write_text(json.dumps(secs), encoding="utf-8")
    out = d / "swapped_cal.json"
    code, _o, err = _run(_cli_args(session["csv"], bad, out))
    line = _one_error_line(err)
    assert code == 2 and not out.exists()
    # the first turn recorded (about x) is now named y_rot
    assert str(session["csv"]) in line and "'y_rot'" in line and str(bad) in line, line
    assert "mostly about x" in line and "from the sensor's y axis" in line, line


def test_part_of_a_turn_refused(session: dict[str, Any]) -> None:
    """A z_rot section that holds only the first half of the turn: exit 2, the angle the
    gyro measured (178.4°, computed here from the data) in the one line."""
    d = session["dir"]
    secs = json.loads(POSES.read_text(encoding="utf-8"))
    raw = np.genfromtxt(CSV, delimiter=",", names=True)
    gyr = np.column_stack([raw[c] for c in ("gyr_x", "gyr_y", "gyr_z")]) - IMUCAL_B_G
    s0, e0 = secs["z_rot"]["start"], secs["z_rot"]["end"]
    half = int(np.argmax(np.abs(np.cumsum(gyr[s0:e0, 2]) / RATE_HZ) >= 180.0))
    secs["z_rot"]["end"] = s0 + half
    angle = float(np.linalg.norm(gyr[s0 : s0 + half].sum(axis=0) / RATE_HZ))
    assert 170.0 < angle < 190.0
    bad = d / "half.json"
    bad.write_text(json.dumps(secs), encoding="utf-8")
    code, _o, err = _run(_cli_args(session["csv"], bad, d / "half_cal.json"))
    line = _one_error_line(err)
    assert code == 2 and "'z_rot'" in line and "not one full turn" in line, line
    assert str(bad) in line and f"turns {angle:.1f}° about z" in line, line


def test_implausible_gyro_scale_is_warned() -> None:
    """A gyro read 25 % too large (a wrong unit or count scale) and no turn to judge it:
    the fit finds scale factors near +25 % (truth within ±0.8 %) and says so in a warning,
    never silently."""
    rng = np.random.default_rng(38)
    t0, _t1 = random_truth(rng)
    s = simulate_session(rng, t0.accel, t0.gyro, n_poses=14)
    with pytest.warns(ThermocalWarning, match=r"gyro scale factor x \+2\d\.\d%") as rec:
        res = calibrate_session(s["time_s"], s["accel_mg"], s["gyro_deg_s"] * DEG * 1.25,
                                g_mg=s["g_m_s2"] / MG, latitude_deg=45.0)  # fmt: skip
    assert res.gyro is not None
    np.testing.assert_allclose(res.gyro.theta[3:6], (1.25 * (1 + t0.gyro[3:6] * 1e-6) - 1)
                               * 1e6, atol=2000.0)  # fmt: skip
    assert any("gyro_unit" in str(w.message) for w in rec)


@pytest.mark.parametrize("form", ["csv", "columns-json", "txt"])
def test_section_list_as_imucal_users_save_it(session: dict[str, Any], form: str) -> None:
    """imucal's example reads its list with ``pd.read_json(...).T`` and its docstring saves
    one with ``section_list.to_csv(...)``; ``section_list.to_json()`` writes pandas'
    column orientation.  Both, written here by pandas, give the gyro figures of the
    example's own JSON file; the CSV is known by its text when its name is not ``.csv``."""
    import pandas as pd

    d = session["dir"]
    section_list = pd.read_json(POSES).T
    if form in ("csv", "txt"):  # pandas writes the same text whatever the name
        poses = d / f"calibration_sections.{form}"
        section_list.to_csv(poses)
    else:
        poses = d / "calibration_sections.json"
        section_list.to_json(poses)
        assert set(json.loads(poses.read_text(encoding="utf-8"))) == {"start", "end"}
    code, out, err = _run([*_cli_args(session["csv"], poses, d / f"cal_{form}.json"), "--json"])
    assert code == 0, err
    g, ref = json.loads(out)["gyro"], session["cli"]["gyro"]
    np.testing.assert_allclose(g["scale_factor_ppm"], ref["scale_factor_ppm"], rtol=1e-12)
    np.testing.assert_allclose(g["misalignment_arcsec"], ref["misalignment_arcsec"], rtol=1e-12)


def test_csv_section_list_without_start_end_refused(session: dict[str, Any]) -> None:
    """A CSV section list whose header lacks ``start``/``end``: exit 2, one line naming it."""
    d = session["dir"]
    poses = d / "sections_bad.csv"
    poses.write_text("part,from,to\nx_p,540,1271\n", encoding="utf-8")
    code, _o, err = _run(_cli_args(session["csv"], poses, d / "cal_bad.json"))
    line = _one_error_line(err)
    assert code == 2 and str(poses) in line and "'start' and 'end'" in line, line


def test_turns_without_gyro_columns_are_said(session: dict[str, Any]) -> None:
    """The section list names three turns but --gyro is not given: the accelerometer is
    calibrated (exit 0, imucal's E) and one warning says the turns are not used and
    which option uses them."""
    args = _cli_args(session["csv"], POSES, session["dir"] / "acc_only.json")
    i = args.index("--gyro")
    del args[i : i + 2]
    j = args.index("--gyro-unit")
    del args[j : j + 2]
    code, out, err = _run([*args, "--json"])
    assert code == 0, err
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("warning:"), err
    assert "x_rot, y_rot, z_rot" in lines[0] and "--gyro X,Y,Z" in lines[0], lines[0]
    a = json.loads(out)["accel"]
    mine = np.concatenate([a["scale_factor_ppm"], a["misalignment_arcsec"]])
    np.testing.assert_allclose(mine, _theta_of(IMUCAL_KA_RA), rtol=0, atol=1e-6)


def test_gyro_columns_in_another_order_refused(session: dict[str, Any]) -> None:
    """--gyro gyr_y,gyr_x,gyr_z (x and y exchanged): x_rot now turns about the gyro's
    second column, exit 2, and the line points at the --gyro columns too."""
    args = _cli_args(session["csv"], POSES, session["dir"] / "cal_order.json")
    args[args.index("gyr_x,gyr_y,gyr_z")] = "gyr_y,gyr_x,gyr_z"
    code, _o, err = _run(args)
    line = _one_error_line(err)
    assert code == 2 and "'x_rot'" in line and "mostly about y" in line, line
    assert "order of the --gyro columns" in line, line


def test_the_lean_is_said_in_the_table_output(session: dict[str, Any]) -> None:
    """Without --json the lean the JSON reports is said in words, with what it means."""
    lean = session["cli"]["runs"][0]["gyro"]["turn_axis_lean_deg"]
    code, out, err = _run(_cli_args(session["csv"], POSES, session["dir"] / "cal_human.json"))
    assert code == 0, err
    text = " ".join(out.split())
    assert f"the 360° turns lean {lean:.2g}° off their axes" in text, text[-400:]
    assert "misalignments rest on the motions" in text
