"""The default ``thermocal allan FILE`` path takes its intervals from the implementation of
``--deviation oadev`` (issue 29 item 1: Greenhall's EDF with the noise identified per τ):
the same α, EDF and bounds, equal to Stable32's on its PHASE.DAT (given as rate data)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from thermocal.cli import main

DATA = Path(__file__).parents[1] / "data" / "stable32_phasedat"


def _json(capsys: pytest.CaptureFixture[str], args: list[str]) -> dict:  # type: ignore[type-arg]
    code = main(["allan", *args, "--json"])
    cap = capsys.readouterr()
    assert code == 0, cap.err
    return json.loads(cap.out)  # type: ignore[no-any-return]


def test_default_allan_bounds_equal_stable32_phase_dat(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """PHASE.DAT's 1000 first differences as a rate column (τ0 = 1 s): the overlapping
    ADEV of the rate equals Stable32's of the phase, and the default path's 68.3 % bounds
    equal Stable32's to 2e-3 (measured: 3.3e-4 at most, Stable32's five printed digits;
    SP 1065 Table 5's simple EDF, the default path before, was off by up to 3.4e-3, at
    τ = 128 s), its α Stable32's column."""
    x = np.loadtxt(DATA / "PHASE.DAT", comments="#")
    y = np.diff(x)  # rate over each τ0 = 1 s interval
    path = tmp_path / "rate.csv"
    path.write_text(
        "time (s),rate (deg/h)\n" + "".join(f"{i}.0,{float(v)!r}\n" for i, v in enumerate(y))
    )
    lines = (DATA / "phase_dat_oadev_octave.txt").read_text(encoding="latin-1").splitlines()
    r = np.array([[float(v) for v in ln.split()] for ln in lines if ln.strip() and ln[0] != "#"])
    obj = _json(capsys, [str(path), "--signal", "rate (deg/h)"])
    k = r.shape[0]  # Stable32 stops at τ = 128 s, thermocal goes on to 256 s
    np.testing.assert_allclose(obj["tau_s"][:k], r[:, 1], rtol=1e-12)
    np.testing.assert_allclose(obj["adev"][:k], r[:, 5], rtol=1e-4)
    np.testing.assert_allclose(obj["adev_low"][:k], r[:, 4], rtol=2e-3)
    np.testing.assert_allclose(obj["adev_high"][:k], r[:, 6], rtol=2e-3)
    assert obj["alpha"][:k] == r[:, 3].astype(int).tolist()
    assert "Greenhall" in obj["interval"]


def test_default_allan_equals_deviation_oadev_on_a_gapped_record(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Random-walk plus white rate in two gap-separated stretches: per τ the default path
    and ``--deviation oadev`` give the same deviation, bounds, EDF and α."""
    rng = np.random.default_rng(29)
    n = 3000
    y = np.cumsum(rng.standard_normal(n)) * 0.02 + rng.standard_normal(n) + 3.0
    t = np.arange(n, dtype=float) * 0.1
    t[1900:] += 60.0  # a 60 s gap
    path = tmp_path / "gyro.csv"
    path.write_text(
        "time (s),gz (deg/h)\n"
        + "".join(f"{float(a)!r},{float(b)!r}\n" for a, b in zip(t, y, strict=True))
    )
    d = _json(capsys, [str(path), "--signal", "gz (deg/h)"])
    f = _json(capsys, [str(path), "--signal", "gz (deg/h)", "--deviation", "oadev"])
    k = len(d["tau_s"])
    assert k >= 9 and d["n_segments"] == 2
    np.testing.assert_allclose(f["oadev_tau_s"][:k], d["tau_s"], rtol=1e-12)
    np.testing.assert_allclose(f["oadev"][:k], d["adev"], rtol=1e-12)
    np.testing.assert_allclose(f["oadev_low"][:k], d["adev_low"], rtol=1e-12)
    np.testing.assert_allclose(f["oadev_high"][:k], d["adev_high"], rtol=1e-12)
    np.testing.assert_allclose(f["oadev_edf"][:k], d["edf"], rtol=1e-12)
    assert f["oadev_alpha"][:k] == d["alpha"]
    assert f["oadev_alpha_method"][:k] == d["alpha_method"]
    assert len(set(d["alpha"])) > 1  # white at short τ, random walk at long τ
