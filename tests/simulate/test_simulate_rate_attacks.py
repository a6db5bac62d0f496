"""The triad simulators refuse an absurd sample rate (one ``error:`` line, exit 2)."""

from __future__ import annotations

import contextlib
import signal
import warnings
from collections.abc import Iterator
from pathlib import Path
from types import FrameType

import numpy as np
import pytest

from thermocal.cli import main

N = 1200


"""Rows of the good recording: 1200 s at 1 Hz, a temperature ramp 10 → 50 °C."""


def _frame() -> dict[str, np.ndarray]:
    rng = np.random.default_rng(39)
    t = np.arange(N, dtype=float)
    temp = 10.0 + 40.0 * t / (N - 1)
    gyro = 0.5 + 0.02 * (temp - 25.0) + 1e-4 * (temp - 25.0) ** 2 + rng.normal(0, 0.002, N)
    return {"time": t, "gyro": gyro, "T1": temp}


@contextlib.contextmanager
def _alarm(seconds: int = 120) -> Iterator[None]:
    def hung(_sig: int, _frame: FrameType | None) -> None:
        raise TimeoutError(f"no result after {seconds} s")

    old = signal.signal(signal.SIGALRM, hung)
    signal.alarm(seconds)
    try:
        yield
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)


@pytest.mark.parametrize("scenario", ["turntable-16", "turntable-thermal", "multipos"])
def test_the_triad_simulators_refuse_an_absurd_rate(
    scenario: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    with warnings.catch_warnings(), _alarm():
        warnings.simplefilter("ignore")
        code = main(["simulate", scenario, "-o", str(tmp_path / "s"), "--rate-hz", "1e12"])
    err = capsys.readouterr().err
    assert code == 2, err[-500:]
    lines = err.strip().splitlines()
    assert lines[-1].startswith("error: ") and "--rate-hz" in lines[-1], err[-500:]
    assert sum(ln.startswith("error: ") for ln in lines) == 1, err[-500:]
    assert not (tmp_path / "s").exists(), "a simulation folder was left"
