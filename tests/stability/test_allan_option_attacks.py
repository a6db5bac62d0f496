"""Hostile ``allan`` / ``noise`` options through the CLI, every input hashed before and after:
``--confidence`` out of range (and 0.95 against the chi-square interval), counts that are
not integers, a missing ``--signal`` listing 20 columns and how many more."""

from __future__ import annotations

import hashlib
import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from thermocal.cli import main


def _digest(p: Path) -> str:
    return hashlib.sha256(p.read_bytes()).hexdigest()


def _digests(folder: Path) -> dict[Path, str]:
    return {p: _digest(p) for p in folder.rglob("*") if p.is_file()}


def _refused(code: int, err: str, *needles: str) -> str:
    """Exit 2, no traceback, exactly one ``error:`` line holding every needle; that line."""
    assert "Traceback" not in err, err
    assert code == 2, f"exit {code}; stderr: {err}"
    errors = [ln for ln in err.splitlines() if ln.startswith("error: ")]
    assert len(errors) == 1, err
    for n in needles:
        assert n in errors[0], (n, errors[0])
    return errors[0]


def _white_csv(path: Path, n: int = 4000, sigma: float = 0.01, rate: float = 100.0) -> None:
    rng = np.random.default_rng(39)
    cols = {"time_s": np.arange(n) / rate}
    for c in ("gx_dps", "gy_dps", "gz_dps"):
        cols[c] = rng.normal(0.0, sigma, n)
    pd.DataFrame({**cols, "temp_c": 25.0}).to_csv(path, index=False)


@pytest.mark.parametrize("value", ["1e-300", "0", "0.3", "1", "1.5", "nan", "0.9999999999999"])
def test_allan_confidence_outside_its_range_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], value: str
) -> None:
    """``--confidence 1e-300`` gave an interval of zero width, (0.0006486 … 0.0006486),
    beside the estimate 0.0006258, exit 0; 0, 1, 1.5 and NaN were refused without the
    option's name.  Accepted: 0.5 ≤ c ≤ 1 − 1e-9."""
    _white_csv(tmp_path / "a.csv")
    before = _digests(tmp_path)
    code = main(["allan", str(tmp_path / "a.csv"), "--signal", "gx_dps", "--confidence", value])
    _o, err = capsys.readouterr()
    _refused(code, err, "--confidence", "0.5")
    assert _digests(tmp_path) == before


def test_noise_confidence_outside_its_range_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    _white_csv(tmp_path / "a.csv")
    before = _digests(tmp_path)
    out = tmp_path / "n.json"
    code = main(["noise", str(tmp_path / "a.csv"), "--gyro", "gx_dps,gy_dps,gz_dps",
                 "--format", "json", "-o", str(out), "--confidence", "1e-300"])  # fmt: skip
    _o, err = capsys.readouterr()
    _refused(code, err, "--confidence", "1e-300")
    assert not out.exists()
    assert _digests(tmp_path) == before


def test_allan_confidence_95_matches_the_chi_square_interval(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A valid 0.95 still works, and its interval at the first τ is the chi-square one
    computed here with scipy (NIST SP 1065 eq. 45) from the edf the command reports."""
    import json

    from scipy import stats

    _white_csv(tmp_path / "a.csv")
    code = main(["allan", str(tmp_path / "a.csv"), "--signal", "gx_dps", "--confidence",
                 "0.95", "--json"])  # fmt: skip
    out, err = capsys.readouterr()
    assert code == 0, err
    d = json.loads(out)
    d = d.get("gx_dps", d) if isinstance(d, dict) else d
    adev, edf = d["adev"][0], d["edf"][0]
    lo = adev * math.sqrt(edf / stats.chi2.ppf(0.975, edf))
    hi = adev * math.sqrt(edf / stats.chi2.ppf(0.025, edf))
    assert d["adev_low"][0] == pytest.approx(lo, rel=1e-9)
    assert d["adev_high"][0] == pytest.approx(hi, rel=1e-9)


def _adev_tau0(y: np.ndarray) -> float:
    """The overlapping Allan deviation at τ = τ0 written here: √(½ ⟨(ȳ₂ − ȳ₁)²⟩)."""
    return float(np.sqrt(0.5 * np.mean(np.diff(y) ** 2)))


@pytest.mark.parametrize("integers", [False, True])
def test_allan_counts_that_are_not_integers_warn(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], integers: bool
) -> None:
    """``--signal-unit counts`` on a column of fractions (0.01 σ white noise, physical
    values) gave an ADEV in "counts" without a word; now one warning names the column,
    --signal-unit and the metadata's scale_factor.  Integer counts: no warning.  Both:
    the ADEV at τ0 is the one computed here."""
    import json

    rng = np.random.default_rng(5)
    n = 2000
    y = rng.normal(0.0, 30.0, n).round() if integers else rng.normal(0.0, 0.01, n)
    pd.DataFrame({"time": np.arange(n) / 100.0, "g": y}).to_csv(tmp_path / "c.csv", index=False)
    before = _digests(tmp_path)
    code = main(["allan", str(tmp_path / "c.csv"), "--signal", "g", "--signal-unit", "counts",
                 "--time-unit", "s", "--json"])  # fmt: skip
    out, err = capsys.readouterr()
    assert code == 0, err
    warn = [ln for ln in err.splitlines() if ln.startswith("warning:")]
    if integers:
        assert not warn, err
    else:
        assert len(warn) == 1, err
        for needle in ("'g'", "counts", "not integers", "--signal-unit", "scale_factor"):
            assert needle in warn[0], (needle, warn[0])
    assert _digests(tmp_path) == before
    d = json.loads(out)
    d = d.get("g", d)
    assert d["tau_s"][0] == pytest.approx(0.01) and d["unit"] == "counts"
    assert d["adev"][0] == pytest.approx(_adev_tau0(y), rel=1e-9)


def test_allan_without_signal_lists_20_columns_and_how_many_more(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The same list in every command's "name the signal column with --signal" error."""
    wide = tmp_path / "wide.csv"
    names = ["time"] + [f"col{k:05d}" for k in range(9999)]
    rows = "\n".join(",".join([str(r)] + ["1"] * 9999) for r in range(3))
    wide.write_text(",".join(names) + "\n" + rows + "\n")
    before = _digests(tmp_path)
    code = main(["allan", str(wide), "--time-unit", "s"])
    _o, err = capsys.readouterr()
    line = _refused(code, err, "--signal", "'col00019'", "(9,979 more)")
    assert "'col00020'" not in line and len(line) < 2000
    assert _digests(tmp_path) == before
