"""``allan --noise-id stable32``: Stable32's α column, from outputs Stable32 printed.

References from outside thermocal:
* the OCXO frequency record and Stable32 1.60's all-τ OADEV, ADEV and HDEV outputs of it
  (tests/data/stable32_ocxo, allantools' test data, LGPL-3.0): 273, 261 and 261 averaging
  factors, 69 of each with 8–29 averages, where the B1 ratio decides;
* PHASE.DAT's MTOT, TTOT and Htot outputs (tests/data/stable32_phasedat): m = 128, 256 and
  decade m = 200, with 7, 3 and 5 averages, where the total family's rule decides.

What the two rules do differently is stated in thermocal.stability.edf.STABLE32_B1_MIN_TOTAL:
Stable32 judges B1 against its theory at n = the deviation's number of terms (not at the
number of averages), reads the total family down to 6 averages and ADEV/HDEV down to 10;
thermocal's default keeps Barnes' n and bounds B1 by the shorter τ's α (better interval
coverage for random-walk FM, tests/stability/test_stability_coverage.py), so it differs from
Stable32 there."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from stable32_phasedat import allan_refuses, phase_csv, rows, run_allan
from thermocal.cli import main
from thermocal.stability.family import stability

OCXO = Path(__file__).parents[1] / "data" / "stable32_ocxo"


def _ocxo_rows(name: str) -> np.ndarray:
    out = []
    for ln in (OCXO / name).read_text(encoding="latin-1").splitlines():
        if ln.strip() and not ln.lstrip().startswith("#"):
            out.append([float(v) for v in ln.split()])
    return np.array(out)


def _ocxo_fractional() -> np.ndarray:
    f = np.loadtxt(OCXO / "ocxo_frequency.txt", comments="#")
    assert f.size == 19982
    return (f - 1.0e7) / 1.0e7  # Stable32's input: (f − 10 MHz)/10 MHz


@pytest.fixture(scope="module")
def ocxo() -> np.ndarray:
    return _ocxo_fractional()


def _b1_range(r: np.ndarray, n: int) -> np.ndarray:
    groups = n // r[:, 0].astype(int)
    return (groups >= 8) & (groups < 30)


def test_oadev_alpha_column_equals_stable32_where_b1_decides(ocxo: np.ndarray) -> None:
    """All 69 B1 rows equal Stable32's α with its rule; thermocal's own rule, by design,
    reads random-walk FM at most of them (Stable32: flicker and white FM)."""
    r = _ocxo_rows("stable32_oadev_alltau.txt")
    assert r.shape[0] == 273
    s32 = stability(ocxo, 1.0, ["oadev"], r[:, 1], noise_id="stable32").curves["oadev"]
    own = stability(ocxo, 1.0, ["oadev"], r[:, 1]).curves["oadev"]
    np.testing.assert_allclose(s32.dev, r[:, 5], rtol=1e-4)  # the same data
    sel = _b1_range(r, ocxo.size)
    assert sel.sum() == 69
    assert (s32.alpha[sel] == r[sel, 3]).all()
    assert (own.alpha[sel] == r[sel, 3]).sum() < 35
    # every row; m = 5 reads Stable32's flicker PM only with the averages' mean removed (not
    # their line), m = 113 and 463 its random-walk FM only with r1·(n − 1)/n (2δ = −0.503,
    # −0.509 with r1 as Riley & Greenhall print it, a hair past −0.5)
    np.testing.assert_array_equal(s32.alpha, r[:, 3])
    assert [int(s32.alpha[np.flatnonzero(r[:, 0] == k)[0]]) for k in (5, 113, 463)] == [1, -2, -2]
    assert (own.alpha == r[:, 3]).sum() < 200


@pytest.mark.parametrize("dev", ["adev", "hdev"])
def test_non_overlapping_b1_from_10_averages(ocxo: np.ndarray, dev: str) -> None:
    """Non-overlapping ADEV and HDEV: B1 at n = their terms (averages − 1, − 2) and from 10
    averages (below: the shorter τ's α): all 69 B1 rows equal Stable32's α (66 and 60 with
    B1 read down to 8 averages), and every row."""
    r = _ocxo_rows(f"stable32_{dev}_alltau.txt")
    c = stability(ocxo, 1.0, [dev], r[:, 1], noise_id="stable32").curves[dev]
    np.testing.assert_allclose(c.dev, r[:, 5], rtol=1e-4)
    np.testing.assert_array_equal(c.n_terms, r[:, 2])
    sel = _b1_range(r, ocxo.size)
    assert sel.sum() == 69
    assert (c.alpha[sel] == r[sel, 3]).all()
    np.testing.assert_array_equal(c.alpha, r[:, 3])


@pytest.mark.parametrize(
    ("dev", "ref"),
    [
        ("mtotdev", "phase_dat_mtotdev_octave.txt"),
        ("ttotdev", "phase_dat_ttotdev_octave.txt"),
        ("htotdev", "phase_dat_htotdev_octave.txt"),
        ("mtotdev", "phase_dat_mtotdev_decade.txt"),
        ("ttotdev", "phase_dat_ttotdev_decade.txt"),
    ],
)
def test_total_family_equals_stable32_through_the_cli(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], dev: str, ref: str
) -> None:
    """Every printed row: α, value (Htot with Stable32's bias correction) and bounds.  At
    m = 128 (7 averages) B1 with R(n) reads flicker PM, at 256 (3) and decade 200 (5) the
    shorter τ's flicker PM is kept; thermocal's default keeps white FM from m = 64 (octave
    τ)."""
    r = rows(ref, commented=True)
    extra = ("--bias-correct",) if dev == "htotdev" else ()
    obj = run_allan(capsys, phase_csv(tmp_path), dev, r[:, 1], "--noise-id", "stable32", *extra)
    assert obj["noise_id"] == "stable32"
    np.testing.assert_array_equal(obj[f"{dev}_alpha"], r[:, 3].astype(int))
    np.testing.assert_allclose(obj[dev], r[:, 5], rtol=1e-4)
    np.testing.assert_allclose(obj[f"{dev}_low"], r[:, 4], rtol=2e-3)
    np.testing.assert_allclose(obj[f"{dev}_high"], r[:, 6], rtol=2e-3)
    own = run_allan(capsys, phase_csv(tmp_path), dev, r[:, 1], *extra)
    assert own["noise_id"] == "thermocal"
    if "octave" in ref:  # decade: m = 100 reads flicker PM (12 averages), 200 keeps it
        assert own[f"{dev}_alpha"][-2:] == [0, 0]


def test_ocxo_through_the_cli(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """The B1 rows of the OADEV output through ``allan`` on a CSV of the record (in parts
    per 10¹², a unit the reader does not know: counts)."""
    y = _ocxo_fractional() * 1e12
    path = tmp_path / "ocxo.csv"
    path.write_text("time (s),y\n" + "".join(f"{i},{v!r}\n" for i, v in enumerate(y.tolist())))
    r = _ocxo_rows("stable32_oadev_alltau.txt")
    sel = _b1_range(r, y.size)
    taus = ",".join(f"{t:g}" for t in r[sel, 1])
    code = main(["allan", str(path), "--signal", "y", "--signal-unit", "counts", "--deviation",
                 "oadev", "--taus", taus, "--noise-id", "stable32", "--json"])  # fmt: skip
    cap = capsys.readouterr()
    assert code == 0, cap.err
    obj = json.loads(cap.out)
    assert obj["oadev_alpha"] == r[sel, 3].astype(int).tolist()


@pytest.mark.parametrize(
    ("extra", "words"),
    [
        (["--deviation", "oadev", "--noise-id", "stable31"], "--noise-id 'stable31'"),
        (["--noise-id", "stable32"], "--deviation"),
    ],
)
def test_bad_noise_id_is_exit_2(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], extra: list[str], words: str
) -> None:
    assert words in allan_refuses(tmp_path, capsys, *extra)
