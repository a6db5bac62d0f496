"""The array API of ``thermocal.stability``: deviations and noise terms of a numpy array,
checked against numpy computations written here and the simulator's truth."""

from __future__ import annotations

import math

import numpy as np
import pytest

from thermocal import stability
from thermocal.errors import ParameterError


def _oadev_numpy(y: np.ndarray, tau0: float, m: int) -> float:
    """NIST SP 1065 eq. 11 written directly: phase by cumulative sum, every second difference."""
    x = np.concatenate([[0.0], np.cumsum(y)]) * tau0
    d = x[2 * m :] - 2.0 * x[m:-m] + x[: -2 * m]
    return float(np.sqrt(np.mean(d**2) / (2.0 * (m * tau0) ** 2)))


def _mdev_numpy(y: np.ndarray, tau0: float, m: int) -> float:
    """NIST SP 1065 eq. 14: the second differences averaged over m consecutive starts."""
    x = np.concatenate([[0.0], np.cumsum(y)]) * tau0
    d = x[2 * m :] - 2.0 * x[m:-m] + x[: -2 * m]
    inner = np.convolve(d, np.ones(m), mode="valid")
    return float(np.sqrt(np.mean(inner**2) / (2.0 * m**2 * (m * tau0) ** 2)))


@pytest.fixture(scope="module")
def noisy() -> np.ndarray:
    rng = np.random.default_rng(11)
    return rng.normal(0.0, 0.3, 20_000) + np.cumsum(rng.normal(0.0, 0.002, 20_000))


def test_oadev_and_mdev_of_an_array_equal_the_formulas_written_in_numpy(noisy) -> None:  # type: ignore[no-untyped-def]
    r = stability.oadev(noisy, rate_hz=50.0, taus="octave")
    assert r.m.tolist() == [2**k for k in range(14)]
    assert r.tau_s == pytest.approx(r.m / 50.0)
    want = [_oadev_numpy(noisy, 0.02, int(m)) for m in r.m]
    assert r.dev == pytest.approx(want, rel=1e-9)
    assert np.all(r.low < r.dev) and np.all(r.dev < r.high)
    md = stability.mdev(noisy, 50.0, taus=[0.02, 0.2, 2.0])
    assert md.dev == pytest.approx([_mdev_numpy(noisy, 0.02, m) for m in (1, 10, 100)], rel=1e-9)


def test_phase_data_give_the_rate_data_deviation(noisy) -> None:  # type: ignore[no-untyped-def]
    x = np.concatenate([[0.0], np.cumsum(noisy)]) / 50.0
    a = stability.deviation("ohdev", noisy, 50.0, taus="decade", data_type="freq")
    b = stability.deviation("ohdev", x, 50.0, taus="decade", data_type="phase")
    assert b.dev == pytest.approx(a.dev, rel=1e-7)


def test_to_frame_and_to_dict_carry_the_same_numbers(noisy) -> None:  # type: ignore[no-untyped-def]
    r = stability.deviation("totdev", noisy[:4000], 50.0, unit="deg/h")
    frame = r.to_frame()
    d = r.to_dict()
    assert list(frame.columns[:4]) == ["tau_s", "m", "dev", "low"]
    assert frame["dev"].tolist() == pytest.approx(d["dev"])
    assert d["unit"] == "deg/h" and d["rate_hz"] == 50.0 and len(d["alpha_method"]) == len(frame)


def test_allan_noise_recovers_the_simulated_arw_and_rrw() -> None:
    rate_hz, n = 100.0, 400_000
    arw, rrw = 0.2, 0.02  # the truth: N [deg/s·√s], K [deg/s/√s]
    rng = np.random.default_rng(0)
    white = rng.normal(0.0, arw * math.sqrt(rate_hz), n)  # σ = N / √τ0
    walk = np.cumsum(rng.normal(0.0, rrw / math.sqrt(rate_hz), n))  # steps K √τ0
    r = stability.allan_noise(white + walk, rate_hz, unit="deg/s", confidence=0.95)
    # the truth's Allan deviation (IEEE 952 C.1: N²/τ + K²τ/3) inside every EDF interval
    a = r.adev
    truth = np.sqrt(arw**2 / a.tau_s + rrw**2 * a.tau_s / 3.0)
    assert np.all((a.adev_low <= truth) & (truth <= a.adev_high))
    assert a.tau_s.size == 18
    # the slope lines' EDF intervals hold the truth; deg/√s → deg/√h and deg/s/√s → /√h: × 60
    n_slope = r.term("angle_random_walk", "slope")
    k_slope = r.term("rate_random_walk", "slope")
    assert n_slope.low < arw * 60.0 < n_slope.high
    assert k_slope.low < rrw * 60.0 < k_slope.high
    n_fit, k_fit = r.term("angle_random_walk"), r.term("rate_random_walk")
    assert n_fit.unit == "deg/sqrt(h)" and k_fit.unit == "deg/s/sqrt(h)"
    assert n_fit.value == pytest.approx(arw * 60.0, rel=0.01)
    assert k_fit.value == pytest.approx(rrw * 60.0, rel=0.1)
    frame = r.to_frame()
    assert set(frame["method"]) == {"fit", "slope"} and len(frame) == 10


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda: stability.oadev(np.ones(100), rate_hz=0.0), "rate_hz must be positive"),
        (lambda: stability.oadev(np.ones(100), rate_hz="100"), "rate_hz must be a number"),
        (lambda: stability.oadev(np.ones(100), 1.0, taus="1,10"), "taus '1,10': use octave"),
        (lambda: stability.oadev(np.ones(100), 1.0, taus=[1.0, -1.0]), "taus: averaging"),
        (lambda: stability.oadev(np.ones(100), 1.0, data_type="time"), "data_type 'time'"),
        (lambda: stability.allan_noise(np.ones(100), 1.0, taus="all"), "taus 'all'"),
        (lambda: stability.oadev(np.ones((100, 3)), 1.0), r"y must be one-dim.*\(100, 3\)"),
        (lambda: stability.allan_noise(np.ones((3, 100)), 1.0), r"y must be one-dim.*\(3, 100\)"),
    ],
)
def test_bad_parameters_are_refused_by_name(call, message) -> None:  # type: ignore[no-untyped-def]
    with pytest.raises(ParameterError, match=message):
        call()


def test_a_noise_type_beyond_the_deviation_is_refused() -> None:
    y = np.random.default_rng(1).normal(size=1000)
    assert stability.hdev(y, 1.0, noise_type=-4).alpha.tolist() == [-4] * 9
    with pytest.raises(ParameterError, match="noise_type -3: α outside oadev's range"):
        stability.oadev(y, 1.0, noise_type=-3)


def test_the_array_functions_below_the_api_refuse_a_table_too() -> None:
    from thermocal.stability.allan import overlapping_adev
    from thermocal.stability.family import stability as family_stability

    table = np.ones((50, 3))
    with pytest.raises(ParameterError, match=r"rate must be one-dim.*\(50, 3\)"):
        overlapping_adev(table, 1.0)
    with pytest.raises(ParameterError, match=r"values must be one-dim.*\(50, 3\)"):
        family_stability(table, 1.0, ["oadev"])
