"""The triad calibrations' messages name the library's parameters for a Python user and the
command's options on the command line: the same refusal seen both ways (``multipos`` given
both a gravity and a latitude; a ``turntable`` run recorded at a latitude of the other sign,
whose least-squares residuals are far beyond the white noise)."""

from __future__ import annotations

import json
import warnings
from pathlib import Path

import numpy as np
import pytest

from thermocal.cli import main
from thermocal.errors import ThermocalInputError
from thermocal.pipeline.multipos import MultiposOptions, calibrate_files
from thermocal.turntable.calibration import calibrate
from thermocal.turntable.simulate import simulate_turntable16
from thermocal.writers import write_recording

A = ("accel_x", "accel_y", "accel_z")


def _errors(capsys: pytest.CaptureFixture[str]) -> list[str]:
    return [ln for ln in capsys.readouterr().err.splitlines() if ln.startswith("error: ")]


def test_gravity_and_latitude_named_both_ways(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    f = tmp_path / "s.csv"  # never read: the options are refused first
    opts = MultiposOptions(A, gravity_m_s2=9.8, latitude_deg=45.0)
    with pytest.raises(ThermocalInputError) as err:
        calibrate_files([f], tmp_path / "cal.json", opts)
    assert str(err.value) == "give gravity_m_s2 or latitude_deg, not both"
    code = main(["multipos", str(f), "--accel", ",".join(A), "--gravity", "9.8",
                 "--latitude", "45", "-o", str(tmp_path / "cal.json")])  # fmt: skip
    assert code == 2
    assert _errors(capsys) == ["error: give --gravity or --latitude, not both"]


def test_a_run_at_the_other_latitude_names_the_encoders_both_ways(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    rec, truth = simulate_turntable16(3, rate_hz=10.0, dwell_s=20.0, latitude_deg=40.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ok = calibrate(rec, latitude_deg=40.0, min_dwell_s=15.0)
        with pytest.raises(ThermocalInputError) as err:
            calibrate(rec, latitude_deg=-40.0, min_dwell_s=15.0)
    # the run itself is sound: at its own latitude the bias is the simulator's within 4 σ
    z = (ok.kalman.theta[0:3] - np.array(truth["bias_deg_h"])) / ok.kalman.sigma[0:3]
    assert np.all(np.abs(z) < 4.0), z
    assert "least-squares residuals" in str(err.value)
    assert str(err.value).endswith(
        "check latitude_deg, the encoder columns (alpha_column, beta_column, encoder_unit) "
        "and their zeros (alpha_offset_deg); nothing written"
    )
    f = tmp_path / "run.csv"
    write_recording(rec, f)
    code = main(["turntable", str(f), "--latitude", "-40", "--min-dwell", "15",
                 "-o", str(tmp_path / "res.json")])  # fmt: skip
    assert code == 2
    (line,) = _errors(capsys)
    assert line.endswith(
        "check --latitude, the encoder columns (--alpha, --beta, --encoder-unit) and their "
        "zeros (--alpha-offset); nothing written"
    )
    assert not (tmp_path / "res.json").exists()


def test_an_encoder_zero_off_by_two_degrees_is_warned_with_the_option_in_the_json(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The α encoder read 2° more than the geometry's angle (an encoder zero off, the case
    the warning is for): the library's result names ``alpha_offset_deg``; the command's
    ``--json`` and its ``warning:`` line name ``--alpha-offset``, with the same value."""
    rec, _ = simulate_turntable16(3, rate_hz=10.0, dwell_s=20.0, latitude_deg=40.0)
    rec = rec.with_columns({"alpha_deg": rec.columns["alpha_deg"] + 2.0}, {"alpha_deg": "deg"})
    with pytest.warns(UserWarning, match="alpha_offset_deg"):
        res = calibrate(rec, latitude_deg=40.0, min_dwell_s=15.0)
    (said,) = [w for w in res.warnings if "encoder's zero" in w]
    assert "declare it with alpha_offset_deg " in said and "--alpha-offset" not in said
    f = tmp_path / "run.csv"
    write_recording(rec, f)
    code = main(["turntable", str(f), "--latitude", "40", "--min-dwell", "15",
                 "-o", str(tmp_path / "res.json"), "--json"])  # fmt: skip
    assert code == 0
    out, err = capsys.readouterr()
    (shown,) = [w for w in json.loads(out)["warnings"] if "encoder's zero" in w]
    assert shown == said.replace("alpha_offset_deg", "--alpha-offset")
    assert any("--alpha-offset" in ln for ln in err.splitlines() if ln.startswith("warning:"))
