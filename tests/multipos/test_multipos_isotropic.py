"""A latitude of the wrong sign in ``multipos`` reads as a g-sensitivity ``A = c·I``: the
vertical earth rate taken off each pose is ``Ω sin L`` along the up direction ``u``, and the
error ``Ω (sin L_true − sin L_given) u`` is what ``c I f = c (g/g₀) u`` gives.  As in
``turntable`` (one shared :func:`thermocal.multipos.gsens.isotropic_part`), such an ``A`` is
reported with the reason, never taken off the rates nor stored in the calibration.

Simulated sessions at +45° without any g-sensitivity (the simulator's truth), calibrated with
``--latitude -45``: ``c`` within 3σ of ``2 Ω sin 45° · g₀/g`` (the formula written here,
21.3 °/h/g), the rates not corrected, the calibration written without ``A`` (format version 1);
the gyro's scale factors and misalignments within 3.5σ of the truth.  With the right latitude
nothing is beyond 3σ."""

from __future__ import annotations

import json
import math
import re
from pathlib import Path

import numpy as np

from gsens_session import GYRO_THETA, MULTIPOS, run, write_session
from thermocal.units import EARTH_RATE_RAD_S

G0 = 9.80665
WRONG = [a if a != "45.0" else "-45" for a in MULTIPOS]


def _c_true(g_m_s2: float) -> float:
    """2 Ω sin 45° in °/h, per g of local gravity in standard g."""
    omega_deg_h = math.degrees(EARTH_RATE_RAD_S) * 3600.0
    return 2.0 * omega_deg_h * math.sin(math.radians(45.0)) * G0 / g_m_s2


def test_a_wrong_latitude_is_reported_not_subtracted(tmp_path: Path) -> None:
    assert "-45" in WRONG
    for seed in range(2):
        s = write_session(tmp_path, seed=seed, a_deg_h_g=np.zeros((3, 3)))
        cal = tmp_path / f"c{seed}.json"
        code, out, err = run(["multipos", str(tmp_path / "s.csv"), *WRONG, "-o", str(cal),
                              "--json"])  # fmt: skip
        assert code == 0, err
        d = json.loads(out)
        g = d["runs"][0]["gyro"]
        assert g["g_sensitivity"] is not None and not g["g_sensitivity_subtracted"]
        note = g["g_sensitivity_note"]
        m = re.match(r"the g-sensitivity is c·I alone \(c = ([-0-9.e+]+) ± ([0-9.e+-]+) °/h/g\)",
                     note)  # fmt: skip
        assert m is not None and "latitude" in note, note
        c, sc = float(m.group(1)), float(m.group(2))
        assert abs(c - _c_true(s["g_m_s2"])) < 3 * sc, (c, sc, _c_true(s["g_m_s2"]))
        stored = d["gyro"]["g_sensitivity"]
        assert not stored["stored"] and stored["why"].startswith("not stored: the g-sens")
        assert json.loads(cal.read_text())["format_version"] == 1
        e = np.array(g["scale_factor_ppm"] + g["misalignment_arcsec"]) - GYRO_THETA[3:]
        sig = np.array(g["scale_factor_ppm_sigma"] + g["misalignment_arcsec_sigma"])
        assert np.all(np.abs(e) < 3.5 * sig), np.abs(e / sig).max()


def test_the_right_latitude_finds_nothing(tmp_path: Path) -> None:
    write_session(tmp_path, seed=0, a_deg_h_g=np.zeros((3, 3)))
    code, out, err = run(["multipos", str(tmp_path / "s.csv"), *MULTIPOS, "-o",
                          str(tmp_path / "c.json"), "--json"])  # fmt: skip
    assert code == 0, err
    g = json.loads(out)["runs"][0]["gyro"]
    assert not any(any(r) for r in g["g_sensitivity"]["significant"])
    assert g["g_sensitivity_note"] is None and not g["g_sensitivity_subtracted"]
