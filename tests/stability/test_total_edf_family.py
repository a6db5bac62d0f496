"""The EDF of every total deviation as the deviations' pipeline gives it (``stability``'s
curves, the numbers behind ``allan --deviation``'s bounds), pinned at every noise type to
published values written here, not read from the code:

* TOTDEV, white / flicker / random-walk FM: ν = b·N/m − c, (b, c) = (1.50, 0), (1.17, 0.22),
  (0.93, 0.36) (NIST SP 1065, 2008, Table 7; Howe's TOTVAR EDF);
* MTOT and TTOT at white PM and random-walk FM, m ≥ 10: ν = b·N/m − c, (b, c) = (1.90, 2.10),
  (0.75, 0.31) (SP 1065 Table 8);
* Htot at white / flicker / random-walk FM, m ≥ 16: ν = (N/m)/(b0 + b1·m/N), (b0, b1) =
  (0.559, 1.004), (0.868, 1.140), (0.938, 1.696) (SP 1065 §5.2.14; Howe et al., PTTI 2000,
  Table 1);

and, at the noise types PHASE.DAT holds, to Stable32's printed 68.3 % bounds (their ratio to
the deviation, which a bias correction leaves alone; tests/data/stable32_phasedat, allantools'
test data, LGPL-3.0).  An EDF 1.5 or 0.7 times these fails every case.
"""

from __future__ import annotations

import numpy as np
import pytest

from stable32_phasedat import DATA
from stable32_phasedat import rows as _rows
from thermocal.stability.edf import confidence_interval
from thermocal.stability.family import stability

N_PHASE = 1001  # PHASE.DAT's phase points


def _pipeline_edf(dev: str, m: int, alpha: int) -> float:
    x = np.loadtxt(DATA / "PHASE.DAT", comments="#")
    assert x.size == N_PHASE
    curve = stability(x, 1.0, [dev], [float(m)], data_type="phase", alpha=alpha).curves[dev]
    assert curve.m.tolist() == [m]
    return float(curve.edf[0])


SP1065_LINEAR = [
    ("totdev", 0, 1.50, 0.0),
    ("totdev", -1, 1.17, 0.22),
    ("totdev", -2, 0.93, 0.36),
    ("mtotdev", 2, 1.90, 2.10),
    ("mtotdev", -2, 0.75, 0.31),
    ("ttotdev", 2, 1.90, 2.10),
    ("ttotdev", -2, 0.75, 0.31),
]


@pytest.mark.parametrize("m", [16, 100])
@pytest.mark.parametrize(("dev", "alpha", "b", "c"), SP1065_LINEAR)
def test_total_edf_follows_sp1065_tables_7_and_8(
    dev: str, alpha: int, b: float, c: float, m: int
) -> None:
    assert _pipeline_edf(dev, m, alpha) == pytest.approx(b * N_PHASE / m - c, rel=1e-12)


@pytest.mark.parametrize("m", [16, 100])
@pytest.mark.parametrize(
    ("alpha", "b0", "b1"), [(0, 0.559, 1.004), (-1, 0.868, 1.140), (-2, 0.938, 1.696)]
)
def test_htot_edf_follows_howe_2000(alpha: int, b0: float, b1: float, m: int) -> None:
    want = (N_PHASE / m) / (b0 + b1 * m / N_PHASE)
    assert _pipeline_edf("htotdev", m, alpha) == pytest.approx(want, rel=1e-12)


@pytest.mark.parametrize(
    ("dev", "ref"),
    [
        ("totdev", "phase_dat_totdev_octave.txt"),
        ("mtotdev", "phase_dat_mtotdev_decade.txt"),
        ("ttotdev", "phase_dat_ttotdev_decade.txt"),
        ("htotdev", "phase_dat_htotdev_octave.txt"),
    ],
)
def test_total_edf_gives_stable32s_bounds(dev: str, ref: str) -> None:
    """Every printed row with Stable32's α given: the bounds over the deviation to 2e-3."""
    r = _rows(ref, commented=True)
    assert r.shape[0] >= 8
    for m, _tau, _n, alpha, low, value, high in r:
        edf = _pipeline_edf(dev, int(m), int(alpha))
        lo, hi = confidence_interval(1.0, edf)
        assert float(lo) == pytest.approx(low / value, rel=2e-3), (m, edf)
        assert float(hi) == pytest.approx(high / value, rel=2e-3), (m, edf)
