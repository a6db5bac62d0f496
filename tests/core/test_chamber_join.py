"""The clock join of a chamber log and a recording (thermocal.chamber_join): the offset and
drift found by correlation within their stated uncertainty, given and absolute offsets, a
log that does not cover the recording refused."""

from __future__ import annotations

import numpy as np
import pytest

from thermocal.chamber_join import (
    join_clock,
    joined_values,
    timezone_seconds,
    timezone_text,
)
from thermocal.errors import ThermocalInputError

KNOTS_S = [0, 1500, 5000, 8000, 12000, 15500, 19000, 23000, 30000]
KNOTS_C = [22, 22, 65, 65, -20, -20, 40, 40, 25]


def _air(tau: np.ndarray) -> np.ndarray:
    return np.interp(tau, KNOTS_S, KNOTS_C)


def _case(
    seed: int, drift_ppm: float, offset_s: float = 1234.5, rho: float = 0.0
) -> dict[str, np.ndarray]:
    """A log every 10 s in °F to 0.1 °F, a 1 Hz recording of 25 000 s whose sensor reads the
    air plus 0.05 °C noise (AR(1) with lag-one correlation ``rho``), the log's clock gaining
    ``drift_ppm``."""
    from scipy.signal import lfilter

    rng = np.random.default_rng(seed)
    lt = np.arange(0.0, 30000.0, 10.0)
    lv = (np.round(_air(lt) * 1.8 + 32.0, 1) - 32.0) / 1.8
    t = np.arange(0.0, 25000.0, 1.0)
    white = 0.05 * np.sqrt(1.0 - rho**2) * rng.standard_normal(t.size)
    noise = lfilter([1.0], [1.0, -rho], white)
    y = _air(offset_s + (1.0 + drift_ppm * 1e-6) * t) + noise
    return {"t": t, "lt": lt, "lv": lv, "y": y}


@pytest.mark.parametrize("rho", [0.0, 0.9])
def test_drift_of_100_ppm_recovered_within_its_sigma(rho: float) -> None:
    z_drift, z_offset, sigmas = [], [], []
    for seed in range(12):
        c = _case(seed, 100.0, rho=rho)
        j = join_clock(c["t"], c["lt"], c["lv"], rec_temp_c=c["y"])
        assert j.method == "correlation" and j.drift_sigma_ppm is not None
        assert j.offset_sigma_s is not None
        z_drift.append((j.drift_ppm - 100.0) / j.drift_sigma_ppm)
        z_offset.append((j.offset_s - 1234.5) / j.offset_sigma_s)
        sigmas.append(j.drift_sigma_ppm)
    # the stated σ is the spread: the errors' rms in σ near 1, none beyond 3.5 σ, and
    # about two thirds within one σ; with correlated noise (rho 0.9) too, where σ without
    # the effective-sample factor (1 + ρ)/(1 − ρ) would be 4.4 times too small
    for z in (np.array(z_drift), np.array(z_offset)):
        assert 0.6 < float(np.sqrt(np.mean(z**2))) < 1.5
        assert float(np.max(np.abs(z))) < 3.5
        assert np.mean(np.abs(z) <= 1.0) >= 0.5
    assert max(sigmas) < (15.0 if rho == 0.0 else 40.0)  # 100 ppm resolved, several σ from 0


def test_a_given_offset_is_used_as_given() -> None:
    c = _case(0, 0.0)
    j = join_clock(c["t"], c["lt"], c["lv"], offset_s=1234.5)
    assert (j.method, j.offset_s, j.offset_sigma_s, j.drift_ppm, j.drift_sigma_ppm) == (
        "given", 1234.5, None, 0.0, None
    )  # fmt: skip
    values = joined_values(j, c["t"], c["lt"], c["lv"])
    # the log's 0.1 °F digits and its 10 s linear interpolation of a piecewise-linear air
    np.testing.assert_allclose(values, _air(1234.5 + c["t"]), atol=0.05 / 1.8 + 1e-9)
    j2 = join_clock(c["t"], c["lt"], c["lv"], offset_s=1234.5, drift_ppm=100.0)
    assert j2.covered_s == (1234.5, 1234.5 + 24999.0 * (1 + 100e-6))
    drifting = joined_values(j2, c["t"], c["lt"], c["lv"])  # 2.5 s gained by the end
    np.testing.assert_allclose(
        drifting, _air(1234.5 + (1 + 100e-6) * c["t"]), atol=0.05 / 1.8 + 1e-9
    )


def test_an_absolute_offset_states_its_zone() -> None:
    c = _case(0, 0.0)
    j = join_clock(
        c["t"], c["lt"], c["lv"], absolute_offset_s=600.0, timezone=timezone_text(3600.0)
    )
    assert (j.method, j.offset_s, j.timezone) == ("absolute", 600.0, "UTC+01:00")


def test_a_log_that_does_not_overlap_is_refused() -> None:
    c = _case(0, 0.0)
    with pytest.raises(ThermocalInputError, match="does not overlap the recording"):
        join_clock(c["t"], c["lt"], c["lv"], offset_s=40000.0)
    with pytest.raises(ThermocalInputError, match="does not overlap the recording"):
        join_clock(c["t"], c["lt"], c["lv"], offset_s=-30000.0)
    with pytest.raises(ThermocalInputError, match=r"covers only 20\.0 % of the recording"):
        join_clock(c["t"], c["lt"], c["lv"], offset_s=25000.0)  # 5000 of 25 000 s


def test_a_log_from_another_run_is_refused_by_correlation() -> None:
    c = _case(0, 0.0)
    other = 30.0 + 0.0 * c["lv"]
    other[::2] += 1.0  # a log that never follows the recording's sweep
    with pytest.raises(ThermocalInputError, match="does not follow the recording's"):
        join_clock(c["t"], c["lt"], other, rec_temp_c=c["y"])
    with pytest.raises(ThermocalInputError, match="the log cannot cover the recording"):
        join_clock(c["t"], c["lt"][:1000], c["lv"][:1000], rec_temp_c=c["y"])
    with pytest.raises(ThermocalInputError, match="has none"):
        join_clock(c["t"], c["lt"], c["lv"])


def test_time_zones() -> None:
    assert timezone_seconds("+05:30") == 19800.0
    assert timezone_seconds("-0800") == -28800.0
    assert timezone_text(-19800.0) == "UTC-05:30"
    for bad in ("5", "+15:00", "+02:75", "CET"):
        with pytest.raises(ThermocalInputError, match="chamber_tz"):
            timezone_seconds(bad)


def test_a_coarse_log_s_rounding_is_in_the_sigma() -> None:
    # a log of one row a minute to 0.1 °F: its rounding (0.056 °C, q²/12 a reading) moves
    # the offset and drift more than the sensor's noise does; each seed a chamber program of
    # its own (other roundings), a recording 1.5 °C warm of the air
    z_offset, z_drift = [], []
    for seed in range(12):
        rng = np.random.default_rng(100 + seed)
        knots_s = np.array([0, 1800, 5400, 9000, 12600, 16200, 21600]) + rng.uniform(-200, 200, 7)
        knots_s[0] = 0.0
        knots_c = np.array([25, 25, 70, 70, -15, -15, 25]) + rng.uniform(-3, 3, 7)
        lt = np.arange(0.0, 21600.0, 60.0)
        lv = (np.round(np.interp(lt, knots_s, knots_c) * 1.8 + 32.0, 1) - 32.0) / 1.8
        offset = 1820.0 + rng.uniform(-30.0, 30.0)
        t = np.arange(0.0, 18000.0)
        y = np.interp(offset + t, knots_s, knots_c) + 1.5 + 0.05 * rng.standard_normal(t.size)
        j = join_clock(t, lt, lv, rec_temp_c=y)
        assert j.offset_sigma_s is not None and j.drift_sigma_ppm is not None
        z_offset.append((j.offset_s - offset) / j.offset_sigma_s)
        z_drift.append(j.drift_ppm / j.drift_sigma_ppm)
    for z in (np.array(z_offset), np.array(z_drift)):
        assert 0.6 < float(np.sqrt(np.mean(z**2))) < 1.5
        assert float(np.max(np.abs(z))) < 3.5
