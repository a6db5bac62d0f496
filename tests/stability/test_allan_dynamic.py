"""``thermocal allan --dynamic W``: the overlapping ADEV in sliding windows, a heat map,
and a warning when the noise changes within the record (issue 29 item 3)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from thermocal.cli import main

FS_HZ = 10.0
N = 36000  # one hour


def _csv(path: Path, y: np.ndarray) -> Path:
    t = np.arange(y.size) / FS_HZ
    lines = ["time [s],gyro z [deg/h]", *(f"{a:.2f},{v:.7g}" for a, v in zip(t, y, strict=True))]
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


def _run(path: Path, capsys: pytest.CaptureFixture[str], *extra: str) -> tuple[dict, str]:  # type: ignore[type-arg]
    code = main(
        ["allan", str(path), "--time", "time [s]", "--signal", "gyro z [deg/h]",
         "--dynamic", "600", "--json", *extra]
    )  # fmt: skip
    assert code == 0
    cap = capsys.readouterr()
    return json.loads(cap.out), cap.err


def test_noise_doubling_halfway_is_warned(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    rng = np.random.default_rng(5)
    y = rng.normal(0.0, 0.5, N)
    y[N // 2 :] *= 2.0
    plot = tmp_path / "adev.png"
    out, err = _run(_csv(tmp_path / "doubling.csv", y), capsys, "--plot", str(plot))
    assert "warning:" in err and "not stationary" in err
    dyn = out["dynamic"]
    assert dyn["stationary"] is False and dyn["changes"]
    assert dyn["window_s"] == pytest.approx(600.0)
    adev = np.array([[np.nan if v is None else v for v in row] for row in dyn["adev"]])
    assert adev.shape == (len(dyn["t_s"]), len(dyn["tau_s"]))
    # each window's ADEV at τ = 0.1 s is the window's sample std of white noise (numpy):
    # the first window 0.5 · √(1 − …) ≈ its own std, the last twice the first
    w = int(600 * FS_HZ)
    j0 = dyn["tau_s"].index(pytest.approx(0.1))
    first, last = y[:w], y[N - w :]
    for row, seg in ((0, first), (-1, last)):
        x = np.concatenate([[0.0], np.cumsum(seg - seg.mean())]) / FS_HZ
        d2 = x[2:] - 2 * x[1:-1] + x[:-2]
        expect = math.sqrt(np.sum(d2**2) / (2 * 0.1**2 * d2.size))
        assert adev[row, j0] == pytest.approx(expect, rel=1e-6)
    assert adev[-1, j0] / adev[0, j0] == pytest.approx(2.0, rel=0.1)
    assert (tmp_path / "adev_dynamic.png").stat().st_size > 1000


def test_stationary_record_is_not_warned(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    rng = np.random.default_rng(6)
    y = rng.normal(0.0, 0.5, N) + np.cumsum(rng.normal(0.0, 0.002, N))
    out, err = _run(_csv(tmp_path / "steady.csv", y), capsys)
    assert "not stationary" not in err
    assert out["dynamic"]["stationary"] is True and out["dynamic"]["changes"] == []


def test_window_longer_than_half_the_record_is_exit_2(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = _csv(tmp_path / "short.csv", np.random.default_rng(1).normal(0, 1, 1000))
    args = ["allan", str(path), "--time", "time [s]", "--signal", "gyro z [deg/h]"]
    assert main([*args, "--dynamic", "80"]) == 2
    assert "--dynamic" in capsys.readouterr().err
