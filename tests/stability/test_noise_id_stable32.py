"""Noise identification against Stable32's α column where thermocal used to differ from it.

* Lag-1 on phase data: the decimated phase is not detrended.  Reference: Stable32's α = 0 at
  m = 10⁴ on the Cs 5071A record of allantools' test data (tests/Cs5071A/, LGPL-3.0,
  commit 599dc9ea; ``oadev_decade.txt``, ``adev_decade.txt``, … all read 0 there).  The
  lag-1 method at m uses only the phase decimated by m, so the 56 decimated points are
  quoted below (x[::10000] of ``5071A_phase.txt.gz``, seconds) and identified at m = 1.
* B1 reading phase noise is split into white and flicker PM by R(n) (SP 1065 §5.6):
  PHASE.DAT at decade τ, where Stable32 reads flicker PM at m = 100 and 200 (m = 200 has 5
  averages and keeps m = 100's α), through the CLI; and simulated white and flicker PM
  (the simulator's noise is the reference).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from stable32_phasedat import phase_csv, rows, run_allan
from thermocal.stability.edf import identify_noise, modified_allan_ratio

CS5071A_EVERY_10000 = [
    7.64278624201e-07, 7.84350492714e-07, 7.847157191e-07, 7.85515800438e-07,
    7.85663110692e-07, 7.84771097597e-07, 7.85887711834e-07, 7.87205689471e-07,
    7.88774862773e-07, 7.90872775067e-07, 7.91970567303e-07, 7.92636527015e-07,
    7.93119956806e-07, 7.93578188622e-07, 7.93055805145e-07, 7.95078890643e-07,
    7.94155759999e-07, 7.93694944628e-07, 7.93705542929e-07, 7.95170041313e-07,
    7.95669112812e-07, 7.97192315653e-07, 7.97143943866e-07, 7.99079646571e-07,
    7.99725702313e-07, 8.02001510272e-07, 8.02240485526e-07, 8.03050636591e-07,
    8.02520377167e-07, 8.03466846302e-07, 8.03265607196e-07, 8.03260237674e-07,
    8.04936105038e-07, 8.06420541513e-07, 8.07343701678e-07, 8.08552932411e-07,
    8.09622784393e-07, 8.09683817889e-07, 8.09937731259e-07, 8.09852768319e-07,
    8.11196716767e-07, 8.11546998241e-07, 8.1249999078e-07, 8.13299226522e-07,
    8.1571756496e-07, 8.16014921698e-07, 8.14355446454e-07, 8.15042692899e-07,
    8.14280876103e-07, 8.14637198817e-07, 8.1393987539e-07, 8.14481734364e-07,
    8.13523811786e-07, 8.13641465648e-07, 8.14755810882e-07, 8.17133151825e-07,
]  # fmt: skip


def test_lag1_on_phase_does_not_detrend_as_stable32() -> None:
    """With a line (or a quadratic) removed from these 56 points, lag-1 reads white PM."""
    z = np.asarray(CS5071A_EVERY_10000)
    nid = identify_noise(z, 1, dmax=2, phase_input=True)
    assert (nid.method, nid.alpha) == ("lag1", 0)


@pytest.mark.parametrize(
    ("dev", "ref"),
    [("mtotdev", "phase_dat_mtotdev_decade.txt"), ("ttotdev", "phase_dat_ttotdev_decade.txt")],
)
def test_flicker_pm_read_as_stable32_on_phasedat_decade(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], dev: str, ref: str
) -> None:
    r = rows(ref)
    assert r.shape[0] == 8
    obj = run_allan(capsys, phase_csv(tmp_path), dev, r[:, 1])
    np.testing.assert_array_equal(obj[f"{dev}_alpha"], r[:, 3].astype(int))
    assert obj[f"{dev}_alpha_method"][6] == "b1-rn"  # m = 100: B1 read PM, R(n) flicker
    np.testing.assert_allclose(obj[dev], r[:, 5], rtol=1e-4)
    np.testing.assert_allclose(obj[f"{dev}_low"], r[:, 4], rtol=2e-3)
    np.testing.assert_allclose(obj[f"{dev}_high"], r[:, 6], rtol=2e-3)


def test_white_pm_r_of_n_is_one_over_n() -> None:
    """White PM: Mod σ² / σ² = 1/n exactly in expectation (three disjoint blocks of m)."""
    x = np.random.default_rng(0).standard_normal(200_000)
    for m in (1, 4, 16, 64):
        assert modified_allan_ratio(x, m) * m == pytest.approx(1.0, abs=0.04)


def _flicker_pm(n: int, rng: np.random.Generator) -> np.ndarray:
    """Phase with a 1/f spectrum: white Gaussian spectrum shaped by f^(−1/2)."""
    f = np.fft.rfftfreq(n)
    amp = np.zeros_like(f)
    amp[1:] = f[1:] ** -0.5
    spec = amp * (rng.standard_normal(f.size) + 1j * rng.standard_normal(f.size))
    return np.fft.irfft(spec, n)


def test_b1_phase_noise_split_by_r_of_n() -> None:
    """At m = 1000 of 20 000 points (19 averages: B1), every record B1 reads as PM is
    called flicker PM when it is flicker PM and white PM when it is white PM."""
    counts = {1: 0, 2: 0}
    for seed in range(30):
        rng = np.random.default_rng(seed)
        for truth, x in ((1, _flicker_pm(20_000, rng)), (2, rng.standard_normal(20_000))):
            nid = identify_noise(x, 1000, dmax=2, phase_input=True)
            if nid.method == "b1-rn":
                assert nid.alpha == truth, (seed, truth)
                counts[truth] += 1
    assert counts[1] >= 20 and counts[2] >= 20
