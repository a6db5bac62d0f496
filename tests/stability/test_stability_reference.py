"""``thermocal allan --deviation`` against Stable32's published outputs for its PHASE.DAT
(copied from allantools' test data, LGPL-3.0, see tests/data/stable32_phasedat/README.md)
and against allantools' own functions (installed as a dev dependency).

Values to 1e-4 relative (Stable32 prints five digits); 68.3 % interval bounds to 2e-3 for
the deviations whose EDF Stable32 takes from Greenhall's algorithm (adev, oadev, mdev, tdev,
hdev, ohdev), from SP 1065 Table 7 (totdev) and from its own MTOT rule (mtotdev, ttotdev);
the identified α equals Stable32's column (the total family: to m = 64)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from stable32_phasedat import DATA
from stable32_phasedat import phase_csv as _phase_csv
from stable32_phasedat import rows as _rows
from stable32_phasedat import run_allan as _run
from thermocal.cli import main

WITH_INTERVALS = [
    ("adev", "phase_dat_adev_octave.txt"),
    ("oadev", "phase_dat_oadev_octave.txt"),
    ("mdev", "phase_dat_mdev_octave.txt"),
    ("tdev", "phase_dat_tdev_octave.txt"),
    ("hdev", "phase_dat_hdev_octave.txt"),
    ("ohdev", "phase_dat_ohdev_octave.txt"),
    ("totdev", "phase_dat_totdev_octave.txt"),
]


@pytest.mark.parametrize(("dev", "ref"), WITH_INTERVALS)
def test_values_intervals_and_alpha_equal_stable32(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], dev: str, ref: str
) -> None:
    r = _rows(ref)
    obj = _run(capsys, _phase_csv(tmp_path), dev, r[:, 1])
    np.testing.assert_allclose(obj[f"{dev}_tau_s"], r[:, 1], rtol=1e-12)
    np.testing.assert_allclose(obj[dev], r[:, 5], rtol=1e-4)
    np.testing.assert_allclose(obj[f"{dev}_low"], r[:, 4], rtol=2e-3)
    np.testing.assert_allclose(obj[f"{dev}_high"], r[:, 6], rtol=2e-3)
    np.testing.assert_array_equal(obj[f"{dev}_n"], r[:, 2])
    np.testing.assert_array_equal(obj[f"{dev}_alpha"], r[:, 3].astype(int))
    assert obj["alpha"] == r[:, 3].astype(int).tolist()


VALUES_ONLY = [
    ("mtotdev", "phase_dat_mtotdev_octave.txt", 9),
    ("ttotdev", "phase_dat_ttotdev_octave.txt", 9),
    ("htotdev", "phase_dat_htotdev_octave_nobias.txt", 5),
    ("theo1", "phase_dat_theo1_alpha0_decade.txt", 7),
]


@pytest.mark.parametrize(("dev", "ref", "rows"), VALUES_ONLY)
def test_total_and_theo1_values_equal_stable32(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], dev: str, ref: str, rows: int
) -> None:
    """The rows Stable32 printed without bias correction (every row of mtotdev and ttotdev,
    the first five of htotdev; Theo1 with α = 0, whose bias factor is 1)."""
    r = _rows(ref, commented=True)[:rows]
    assert r.shape[0] == rows
    obj = _run(capsys, _phase_csv(tmp_path), dev, r[:, 1])
    np.testing.assert_allclose(obj[f"{dev}_tau_s"], r[:, 1], rtol=1e-12)
    col = 5
    np.testing.assert_allclose(obj[dev], r[:, col], rtol=1e-4)
    if dev != "theo1":
        np.testing.assert_array_equal(obj[f"{dev}_n"], r[:, 2])


MODIFIED_TOTAL = [
    ("mtotdev", "phase_dat_mtotdev_octave.txt"),
    ("ttotdev", "phase_dat_ttotdev_octave.txt"),
]


@pytest.mark.parametrize(("dev", "ref"), MODIFIED_TOTAL)
def test_modified_total_intervals_equal_stable32(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], dev: str, ref: str
) -> None:
    """MTOT/TTOT bounds (Stable32's EDF rule, thermocal.stability.edf.edf_mtotdev) to 2e-3.

    Rows m = 1–64 through the CLI, with the α thermocal identifies (equal to Stable32's).  At
    m = 128 and 256 (7 and 3 averages) Stable32 identifies flicker PM for the total family
    where thermocal keeps the shorter τ's white FM, as Stable32 itself does for oadev at
    m = 128; with Stable32's α given (the library's ``alpha``) those bounds equal too."""
    from thermocal.stability.family import stability

    r = _rows(ref, commented=True)
    assert r.shape[0] == 9
    obj = _run(capsys, _phase_csv(tmp_path), dev, r[:, 1])
    k = 7
    np.testing.assert_array_equal(obj[f"{dev}_alpha"][:k], r[:k, 3].astype(int))
    np.testing.assert_allclose(obj[f"{dev}_low"][:k], r[:k, 4], rtol=2e-3)
    np.testing.assert_allclose(obj[f"{dev}_high"][:k], r[:k, 6], rtol=2e-3)
    assert "Stable32's MTOT EDF" in obj[f"{dev}_interval"]
    x = np.loadtxt(DATA / "PHASE.DAT", comments="#")
    assert (r[k:, 3] == 1).all()
    curve = stability(x, 1.0, [dev], r[k:, 1], data_type="phase", alpha=1).curves[dev]
    np.testing.assert_allclose(curve.low, r[k:, 4], rtol=2e-3)
    np.testing.assert_allclose(curve.high, r[k:, 6], rtol=2e-3)


@pytest.mark.parametrize(
    ("dev", "ref"), [("mtie", "phase_dat_mtie.txt"), ("tierms", "phase_dat_tierms.txt")]
)
def test_mtie_and_tie_rms_equal_stable32(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], dev: str, ref: str
) -> None:
    r = _rows(ref)
    obj = _run(capsys, _phase_csv(tmp_path), dev, r[:, 1])
    np.testing.assert_allclose(obj[dev], r[:, 3], rtol=1e-4)
    np.testing.assert_array_equal(obj[f"{dev}_n"], r[:, 2])
    assert obj[f"{dev}_unit"] == "s"  # a time deviation of phase data: the column's unit


def test_every_deviation_equals_allantools_on_rate_data(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Rate (frequency) data with a bias and a gap-free time column: every deviation equals
    allantools' function of the same data to 1e-9 (theo1 at its even m)."""
    at = pytest.importorskip("allantools")
    rng = np.random.default_rng(11)
    y = 3.0 + rng.standard_normal(1200) + np.cumsum(rng.standard_normal(1200)) * 0.02
    path = tmp_path / "gyro.csv"
    path.write_text(
        "time (s),rate [deg/s]\n" + "".join(f"{0.5 * i!r},{float(v)!r}\n" for i, v in enumerate(y))
    )
    names = ["adev", "oadev", "mdev", "tdev", "hdev", "ohdev", "totdev", "mtotdev", "ttotdev",
             "htotdev", "tierms", "mtie"]  # fmt: skip
    taus = np.array([0.5, 1.0, 2.0, 8.0, 32.0])
    code = main(["allan", str(path), "--signal", "rate [deg/s]", "--deviation", ",".join(names),
                 "--taus", ",".join(f"{t:g}" for t in taus), "--json"])  # fmt: skip
    cap = capsys.readouterr()
    assert code == 0, cap.err
    obj = json.loads(cap.out)
    for name in names:
        _t, ref, _e, _n = getattr(at, name)(y, rate=2.0, data_type="freq", taus=taus)
        np.testing.assert_allclose(obj[name], ref, rtol=1e-9, err_msg=name)
    assert obj["tdev_unit"] == "deg/s*s" and obj["oadev_unit"] == "deg/s"


def test_gap_is_never_differenced_across(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Two stretches with a 100 s gap: MDEV pools the two stretches' sums of squares
    (Σ S / Σ terms), computed here per stretch with numpy."""
    rng = np.random.default_rng(3)
    a, b = rng.standard_normal(800), 5.0 + rng.standard_normal(600)
    t = np.concatenate([np.arange(800.0), 900.0 + np.arange(600.0)])
    path = tmp_path / "g.csv"
    path.write_text(
        "time (s),rate [deg/h]\n"
        + "".join(
            f"{float(ti)!r},{float(v)!r}\n" for ti, v in zip(t, np.concatenate([a, b]), strict=True)
        )
    )

    def sums(y: np.ndarray, m: int) -> tuple[float, int]:
        x = np.concatenate([[0.0], np.cumsum(y)])
        cs = np.concatenate([[0.0], np.cumsum(x)])
        s = cs[m:] - cs[:-m]
        k = x.size - 3 * m + 1
        v = s[2 * m : 2 * m + k] - 2 * s[m : m + k] + s[:k]
        return float(v @ v) / (2.0 * m**4), k

    code = main(
        [
            "allan",
            str(path),
            "--signal",
            "rate [deg/h]",
            "--deviation",
            "mdev",
            "--taus",
            "1,4,16",
            "--json",
        ]
    )
    cap = capsys.readouterr()
    assert code == 0, cap.err
    obj = json.loads(cap.out)
    for i, m in enumerate((1, 4, 16)):
        (sa, ka), (sb, kb) = sums(a, m), sums(b, m)
        assert obj["mdev"][i] == pytest.approx(np.sqrt((sa + sb) / (ka + kb)), rel=1e-10)
        assert obj["mdev_n"][i] == ka + kb


def test_unknown_deviation_is_exit_2(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = _phase_csv(tmp_path)
    assert main(["allan", str(path), "--signal", "phase [s]", "--deviation", "oadev,foo"]) == 2
    assert "error:" in capsys.readouterr().err
    assert main(["allan", str(path), "--signal", "phase [s]", "--data-type", "angle"]) == 2


def test_phase_column_unit_is_not_taken_for_a_rate_unit(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``phase [s]`` with --data-type phase: the deviations are in the column's own unit, and
    no warning says a rate unit (deg/h) was assumed; a phase column naming no unit is told."""
    path = _phase_csv(tmp_path)
    code = main(["allan", str(path), "--signal", "phase [s]", "--data-type", "phase",
                 "--deviation", "mdev", "--taus", "1,2", "--json"])  # fmt: skip
    cap = capsys.readouterr()
    assert code == 0, cap.err
    assert "assuming" not in cap.err and "warning" not in cap.err
    assert json.loads(cap.out)["mdev_unit"] == "s/s"
    bare = tmp_path / "bare.csv"
    bare.write_text(path.read_text().replace("phase [s]", "phase", 1))
    code = main(["allan", str(bare), "--signal", "phase", "--data-type", "phase",
                 "--deviation", "mdev", "--taus", "1,2", "--json"])  # fmt: skip
    cap = capsys.readouterr()
    assert code == 0, cap.err
    assert "assuming deg/h" not in cap.err
    assert "phase column 'phase' names no unit" in cap.err
