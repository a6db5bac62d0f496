"""The PSD beside the ADEV (:mod:`thermocal.stability.psd`): Welch's one-sided level of
white noise against 2σ²Δt computed here, the white level read from the PSD and from the
ADEV within 10 % of each other and of the simulated density, a vibration line found at its
frequency, and 1/f noise where the two disagree and say why."""

from __future__ import annotations

import numpy as np
import pytest

from thermocal.stability.noise_model import axis_noise
from thermocal.stability.psd import axis_psd, welch_psd, white_level

DT = 0.01
N = 1.0e-4  # rad/s/√Hz
SAMPLES = 360_000


def _white(rng: np.random.Generator) -> np.ndarray:
    return rng.normal(0.0, N / np.sqrt(DT), SAMPLES)


def test_welch_level_of_white_noise() -> None:
    y = _white(np.random.default_rng(5))
    f, s, k = welch_psd(y, DT)
    assert k >= 16 and f[-1] == pytest.approx(50.0)
    level, band = white_level(f, s)
    assert level == pytest.approx(2.0 * N**2, rel=0.02)  # one-sided: 2σ²Δt = 2N²
    assert band[0] < 0.1 and band[1] > 30.0


def test_psd_and_adev_agree_on_white_noise() -> None:
    for seed in range(3):
        y = _white(np.random.default_rng(seed))
        ax = axis_noise(y, DT, name="g", sensor="gyro", unit="rad/s")
        p = axis_psd(y, DT, ax)
        assert p.agree and abs(p.ratio - 1.0) <= 0.10
        assert p.psd_density == pytest.approx(N, rel=0.03)
        assert p.white_asd == pytest.approx(np.sqrt(2.0) * N, rel=0.03)
        assert not p.lines_hz and p.low_rise_hz is None


def test_vibration_line_is_found() -> None:
    rng = np.random.default_rng(8)
    t = np.arange(SAMPLES) * DT
    y = _white(rng) + 3e-3 * np.sin(2 * np.pi * 3.1 * t)
    ax = axis_noise(y, DT, name="g", sensor="gyro", unit="rad/s")
    p = axis_psd(y, DT, ax)
    assert p.lines_hz and abs(p.lines_hz[0][0] - 3.1) < 0.01
    assert "lines at 3.1" in p.words


def test_flicker_noise_disagreement_is_stated() -> None:
    rng = np.random.default_rng(9)
    f = np.fft.rfftfreq(SAMPLES, DT)
    amp = np.zeros(f.size)
    amp[1:] = np.sqrt(SAMPLES / DT * (1e-3) ** 2 / (4 * np.pi) / f[1:])  # B = 1e-3 rad/s
    spec = amp * (rng.standard_normal(f.size) + 1j * rng.standard_normal(f.size))
    y = _white(rng) + np.fft.irfft(spec, SAMPLES)
    ax = axis_noise(y, DT, name="g", sensor="gyro", unit="rad/s")
    p = axis_psd(y, DT, ax)
    assert not p.agree and "DISAGREE" in p.words
    assert p.low_rise_hz is not None and p.low_rise_hz > 1.0
    assert "rises below" in p.words
