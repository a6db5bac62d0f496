"""Tests that catch a tired developer's bugs in ``stability/`` (issue 39, slice h39-allan):
each kills a mutant of ``benchmarks/mutation_check.py`` (``h39a-…``) that the other tests
let survive.  Every reference comes from outside the code under test:

* the EDF tables: every coefficient as published — C. A. Greenhall and W. J. Riley,
  "Uncertainty of stability variances based on finite differences", Proc. 35th PTTI (2003),
  Tables 1–3 (the same in allantools 2024.06's transcription, ``ci.greenhall_table1/2/3``);
  NIST SP 1065 (2008) Table 7 (TOTVAR) and Table 8 (MTOTVAR), also as allantools 2024.06
  prints them; Htot's (b0, b1) of SP 1065 §5.2.14 (Howe et al., PTTI 2000), whose white FM
  row gives Stable32's printed PHASE.DAT Htot EDF 108.8, 52.9, 25.1 (N = 1001, m = 16–64);
  Theo1's empirical EDF fits of SP 1065 §5.2.16 — each formula written here and evaluated
  with those coefficients;
* R(n)'s theory (SP 1065 §5.6; Allan & Barnes 1981) written here with f_h = 1/(2 τ0);
* simulator truth: random-run FM (S_y ∝ f⁻⁴) for the Hadamard family's α; white noise that
  drops twentyfold for a while for the dynamic ADEV; a rate lattice of a known step in
  rad/s (IEEE Std 952-1997 C.1: Q = step·τ0/√12); three gyro axes of known density and
  random walk for the noise model;
* Theo1's τ = 0.75 m τ0 (SP 1065 §5.2.16) and B1's need of 8 averages.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from thermocal.stability import allan, edf, family
from thermocal.stability import noise_model as nm

# --- Greenhall & Riley 2003, Tables 1–3 (1/edf ≈ (a0 − a1/r)/r, [α][d − 1]) ---------------

TABLE1 = {  # modified variances (F = 1)
    2: ((2 / 3, 1 / 3), (7 / 9, 1 / 2), (22 / 25, 2 / 3)),
    1: ((0.840, 0.345), (0.997, 0.616), (1.141, 0.843)),
    0: ((1.079, 0.368), (1.033, 0.607), (1.184, 0.848)),
    -1: (None, (1.048, 0.534), (1.180, 0.816)),
    -2: (None, (1.302, 0.535), (1.175, 0.777)),
    -3: (None, None, (1.194, 0.703)),
    -4: (None, None, (1.489, 0.702)),
}
TABLE2 = {  # unmodified variances (F = m)
    2: ((3 / 2, 1 / 2), (35 / 18, 1.0), (231 / 100, 3 / 2)),
    1: ((78.6, 25.2), (790.0, 410.0), (9950.0, 6520.0)),
    0: ((2 / 3, 1 / 6), (2 / 3, 1 / 3), (7 / 9, 1 / 2)),
    -1: (None, (0.852, 0.375), (0.997, 0.617)),
    -2: (None, (1.079, 0.368), (1.033, 0.607)),
    -3: (None, None, (1.053, 0.553)),
    -4: (None, None, (1.302, 0.535)),
}
TABLE3 = ((6.0, 4.0), (15.23, 12.0), (47.8, 40.0))  # flicker PM: (b0 + b1 ln m)²
N_BIG = 100_000  # J = (d + 1)·m > 100 and r = M/m > d + 1: the tables' regime
M_BIG = 60


def _entries(table):  # type: ignore[no-untyped-def]
    return [(a, d) for a, row in table.items() for d in (1, 2, 3) if row[d - 1] is not None]


@pytest.mark.parametrize(("alpha", "d"), _entries(TABLE1))
def test_greenhall_table1_every_coefficient(alpha: int, d: int) -> None:
    a0, a1 = TABLE1[alpha][d - 1]
    big_m = 1 + N_BIG - (M_BIG + M_BIG * d)  # L = m/F + m d, S = m: M = 1 + N − L
    r = big_m / M_BIG
    got = edf.greenhall_edf(alpha, d, M_BIG, N_BIG, overlapping=True, modified=True)
    assert got == pytest.approx(1.0 / ((a0 - a1 / r) / r), rel=1e-12)


@pytest.mark.parametrize(("alpha", "d"), [e for e in _entries(TABLE2) if e[0] <= 1])
def test_greenhall_table2_every_coefficient(alpha: int, d: int) -> None:
    a0, a1 = TABLE2[alpha][d - 1]
    big_m = 1 + N_BIG - (1 + M_BIG * d)  # F = m: L = 1 + m d
    r = big_m / M_BIG
    norm = 1.0
    if alpha == 1:
        b0, b1 = TABLE3[d - 1]
        norm = (b0 + b1 * math.log(M_BIG)) ** 2
    got = edf.greenhall_edf(alpha, d, M_BIG, N_BIG, overlapping=True, modified=False)
    assert got == pytest.approx(1.0 / ((a0 - a1 / r) / (norm * r)), rel=1e-12)


@pytest.mark.parametrize("d", [1, 2, 3])
def test_greenhall_white_pm_row(d: int) -> None:
    """Table 2's α = +2 row (3/2, 1/2; 35/18, 1; 231/100, 3/2) is case 4's
    C(4d, 2d)/C(2d, d)² and d/2, with 1/edf = (a0 − a1/r)/M."""
    a0, a1 = TABLE2[2][d - 1]
    assert math.comb(4 * d, 2 * d) / math.comb(2 * d, d) ** 2 == pytest.approx(a0, rel=1e-15)
    big_m = 1 + N_BIG - (1 + M_BIG * d)
    got = edf.greenhall_edf(2, d, M_BIG, N_BIG, overlapping=True, modified=False)
    assert got == pytest.approx(1.0 / ((a0 - a1 / (big_m / M_BIG)) / big_m), rel=1e-12)


# --- SP 1065 Tables 7, 8, §5.2.14 (b·N/m − c; Htot (N/m)/(b0 + b1 m/N)) -------------------

TOTVAR = {0: (1.50, 0.0), -1: (1.17, 0.22), -2: (0.93, 0.36)}
MTOTVAR = {2: (1.90, 2.1), 1: (1.20, 1.40), 0: (1.10, 1.2), -1: (0.85, 0.50), -2: (0.75, 0.31)}
HTOTVAR = {0: (0.559, 1.004), -1: (0.868, 1.140), -2: (0.938, 1.696)}


@pytest.mark.parametrize("alpha", sorted(TOTVAR))
@pytest.mark.parametrize(("n", "m"), [(1001, 4), (20_000, 300)])
def test_totvar_edf_table7(alpha: int, n: int, m: int) -> None:
    b, c = TOTVAR[alpha]
    assert edf.edf_totdev(n, m, alpha) == pytest.approx(b * n / m - c, rel=1e-12)


@pytest.mark.parametrize("alpha", [2, -2])  # the rows thermocal takes from Table 8 (m ≥ 10)
def test_mtotvar_edf_table8(alpha: int) -> None:
    b, c = MTOTVAR[alpha]
    assert edf.edf_mtotdev(5001, 40, alpha) == pytest.approx(b * 5001 / 40 - c, rel=1e-12)


def test_mtotvar_table8_rows_kept() -> None:
    """α = +1, 0, −1 take Stable32's line (edf_mtotdev's docstring); Table 8's rows are
    kept as published all the same."""
    assert edf._MTOT == MTOTVAR


@pytest.mark.parametrize("alpha", sorted(HTOTVAR))
@pytest.mark.parametrize(("n", "m"), [(1001, 16), (1001, 64), (20_000, 512)])
def test_htotvar_edf(alpha: int, n: int, m: int) -> None:
    b0, b1 = HTOTVAR[alpha]
    assert edf.edf_htotdev(n, m, alpha) == pytest.approx((n / m) / (b0 + b1 * m / n), rel=1e-12)


def test_htotvar_white_fm_is_stable32s() -> None:
    """Stable32's PHASE.DAT Htot EDF (white FM, N = 1001) at m = 16, 32, 64."""
    got = [edf.edf_htotdev(1001, m, 0) for m in (16, 32, 64)]
    assert got == pytest.approx([108.8, 52.9, 25.1], abs=0.05)


def _theo1_sp1065(n: float, t: float, alpha: int) -> float:
    """SP 1065 §5.2.16's Theo1 EDF, τ = t τ0 (t = 0.75 m), N phase points."""
    if alpha == 2:
        return 0.86 * (n + 1) * (n - 4 * t / 3) / (n - t) * t / (t + 1.14)
    if alpha == 1:
        num = 4.798 * n**2 - 6.374 * n * t + 12.387 * t
        return num / (math.sqrt(t + 36.6) * (n - t)) * t / (t + 0.3)
    if alpha == 0:
        return ((4.1 * n + 0.8) / t - (3.1 * n + 6.5) / n) * t**1.5 / (t**1.5 + 5.2)
    if alpha == -1:
        return (2 * n**2 - 1.3 * n * t - 3.5 * t) / (n * t) * t**3 / (t**3 + 2.3)
    a = 4.4 * n
    return (a - 2) / (2.9 * t) * ((a - 1) ** 2 - 8.6 * t * (a - 1) + 11.4 * t**2) / (a - 3) ** 2


@pytest.mark.parametrize("alpha", [2, 1, 0, -1, -2])
@pytest.mark.parametrize(("n", "m"), [(1001, 2), (1001, 40), (5001, 400)])
def test_theo1_edf_every_coefficient(alpha: int, n: int, m: int) -> None:
    want = _theo1_sp1065(float(n), 0.75 * m, alpha)
    assert edf.edf_theo1(n, m, alpha) == pytest.approx(want, rel=1e-12)


# --- R(n) ---------------------------------------------------------------------------------


@pytest.mark.parametrize("m", [1, 4, 100])
def test_rn_theory_flicker_pm_half_the_sampling_rate(m: int) -> None:
    """Flicker PM: R(n) = 3 ln(256/27) / (2 (1.038 + 3 ln(2π f_h τ))) with the measurement
    bandwidth f_h = 1/(2 τ0) (the Nyquist frequency of the phase samples), τ = n τ0."""
    tau0 = 0.25
    f_h = 1.0 / (2.0 * tau0)
    want = 3 * math.log(256 / 27) / (2 * (1.038 + 3 * math.log(2 * math.pi * f_h * m * tau0)))
    assert edf._r_theory(m, 1) == pytest.approx(want, rel=1e-12)
    assert edf._r_theory(m, 2) == pytest.approx(1.0 / m, rel=1e-12)


# --- the Hadamard family reads random-run FM ------------------------------------------------


def test_hadamard_reads_random_run_fm() -> None:
    """Rate samples that are the double sum of white noise: S_y ∝ f⁻⁴ (α = −4), which the
    Hadamard deviations (d = 3) identify; the Allan family stops at −2."""
    y = np.cumsum(np.cumsum(np.random.default_rng(7).normal(0.0, 1.0, 20_000)))
    res = family.stability(y, 1.0, ["ohdev", "hdev", "oadev"], "octave")
    assert res.curves["ohdev"].alpha[:6].tolist() == [-4] * 6
    assert res.curves["hdev"].alpha[:6].tolist() == [-4] * 6
    assert res.curves["oadev"].alpha[:6].tolist() == [-2] * 6


# --- Theo1's noise is that of its own τ --------------------------------------------------------


def test_theo1_noise_identified_at_its_tau() -> None:
    """Theo1 at m = 128 averages over τ = 0.75·128 τ0 = 96 τ0: on 1000 samples that is 10
    averages, enough for B1 (8); m = 128 itself would leave 7 and identify nothing."""
    y = np.random.default_rng(0).normal(0.0, 1.0, 1000)  # white FM
    c = family.stability(y, 1.0, ["theo1"], [1.5, 96.0]).curves["theo1"]
    assert c.m.tolist() == [2, 128]
    assert c.tau_s.tolist() == [1.5, 96.0]
    assert c.alpha_method[1] == "b1"
    assert c.alpha.tolist() == [0, 0]


# --- the dynamic ADEV flags a quieter stretch ----------------------------------------------------


def test_dynamic_adev_flags_a_quiet_stretch() -> None:
    """White noise σ = 1 except 800–1200 s, where σ = 0.05 (τ0 = 0.1 s): the windows
    there have ADEV(τ0) ≈ 0.05 against the whole record's ≈ √(0.8 + 0.2·0.05²) ≈ 0.895."""
    y = np.random.default_rng(11).normal(0.0, 1.0, 20_000)
    y[8000:12000] *= 0.05
    whole = allan.overlapping_adev(y.copy(), 0.1, "octave")
    assert whole.adev[0] == pytest.approx(math.sqrt(0.8 + 0.2 * 0.05**2), rel=0.03)
    dyn = allan.dynamic_adev(y, 0.1, 200.0, whole)
    assert not dyn.stationary
    quiet = [
        c for c in dyn.changes if 900.0 <= c["t_s"] <= 1100.0 and c["tau_s"] == pytest.approx(0.1)
    ]
    assert quiet, dyn.changes
    assert all(c["adev"] == pytest.approx(0.05, rel=0.1) for c in quiet)


# --- the quantisation of rad/s data is in µrad --------------------------------------------------


def test_rad_per_s_quantization_in_urad() -> None:
    """A rad/s record on a lattice of step 1e-4 rad/s, τ0 = 0.01 s: Q = step·τ0/√12 =
    2.887e-7 rad = 0.2887 µrad (IEEE Std 952-1997 C.1)."""
    step, tau0 = 1e-4, 0.01
    v = np.round(np.random.default_rng(12).normal(0.0, 1e-3, 50_000) / step) * step
    q = nm.output_quantization(v, tau0, "rad/s")
    assert q is not None
    assert q.step == pytest.approx(step, rel=1e-9)
    assert q.angle_q_unit == "urad"
    assert q.angle_q == pytest.approx(step * tau0 / math.sqrt(12.0) * 1e6, rel=1e-9)


# --- the noise model's random walk is the largest walk ------------------------------------------


def test_noise_model_random_walk_is_the_largest_walk() -> None:
    """Three gyro axes at 100 Hz, 1000 s: gx loud white noise (N = 1e-3 rad/s/√Hz, inside
    the densities an IMU can have) and a small walk (K = 1e-6 rad/s²/√Hz), gy the reverse
    (1e-5, 1e-4), gz between (1e-4, 1e-5):
    Kalibr's density is gx's N, its random walk gy's K (simulator truth)."""
    rng = np.random.default_rng(12)
    fs, n = 100.0, 100_000
    dt = 1.0 / fs
    truth = {"gx": (1e-3, 1e-6), "gy": (1e-5, 1e-4), "gz": (1e-4, 1e-5)}
    axes = []
    for name, (dens, walk) in truth.items():
        v = rng.normal(0.0, dens / math.sqrt(dt), n) + np.cumsum(
            rng.normal(0.0, walk * math.sqrt(dt), n)
        )
        axes.append(nm.axis_noise(v, dt, name=name, sensor="gyro", unit="rad/s"))
    model = nm.noise_model(axes, fs)
    k = model.kalibr()
    assert model.chosen["gyroscope_noise_density"].name == "gx"
    assert model.chosen["gyroscope_random_walk"].name == "gy"
    assert k["gyroscope_noise_density"] == pytest.approx(1e-3, rel=0.05)
    assert k["gyroscope_random_walk"] == pytest.approx(1e-4, rel=0.15)
