"""The total family's O(N log m) sums (:mod:`thermocal.stability.total`) against NIST SP 1065
eqs. 27–29 restated here subsequence by subsequence (the O(N·m) definition: each 3m-point
subsequence detrended by its half means, reflected to 9m points, its 6m modified second
differences squared), on white, flicker-like, random-walk and integrated random-walk records of
odd lengths, at every factor m from 2 to N/3, and through the command line on a gapped file."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from thermocal.stability import total


def _direct(z: np.ndarray, m: int) -> tuple[float, int]:
    """Σ_n (1/6m) Σ_j v_j² and N − 3m + 1, straight from the definition."""
    w = np.lib.stride_tricks.sliding_window_view(np.asarray(z, dtype=np.float64), 3 * m)
    h1 = (3 * m) // 2
    h2 = 3 * m - h1
    # half means: the first h1 points and the last h1 points, h2 apart
    slope = (w[:, h2:].mean(axis=1) - w[:, :h1].mean(axis=1)) / h2
    x0 = w - slope[:, None] * np.arange(3 * m)[None, :]
    ext = np.concatenate([x0[:, ::-1], x0, x0[:, ::-1]], axis=1)  # 9m points, even reflection
    kernel = np.ones(m) / m
    avg = np.array([np.convolve(row, kernel, mode="valid") for row in ext])  # 8m + 1 averages
    v = avg[:, : 6 * m] - 2.0 * avg[:, m : 7 * m] + avg[:, 2 * m : 8 * m]
    return float(np.sum(v * v) / (6.0 * m)), w.shape[0]


def _records(n: int) -> dict[str, np.ndarray]:
    rng = np.random.default_rng(41)
    e = rng.standard_normal(n)
    # flicker-like: a sum of first-order low-pass processes an octave apart
    fl = np.sum([_lowpass(e, 2.0**-k) / np.sqrt(2.0**-k) for k in range(8)], axis=0)
    return {
        "white": 3.0 + e,
        "flicker": 1e3 + fl,
        "random walk": np.cumsum(e),
        "integrated random walk": np.cumsum(np.cumsum(e)),
    }


def _lowpass(e: np.ndarray, a: float) -> np.ndarray:
    """y_i = y_{i−1} + a (e_i − y_{i−1})."""
    out = np.empty_like(e)
    acc = 0.0
    for i, v in enumerate(e):
        acc += a * (v - acc)
        out[i] = acc
    return out


@pytest.mark.parametrize("n", [61, 127])
def test_total_sum_equals_the_definition_at_every_factor(n: int) -> None:
    """Every m from 2 to N/3 (odd and even m, odd N: the half means leave the middle point
    out), four noise types: the same sum to 1e-10 relative (the digits lost are bounded by
    a row's length over m: about 1e-13 seen) and the same subsequence count."""
    for name, z in _records(n).items():
        for m in range(2, n // 3 + 1):
            want, k = _direct(z, m)
            got, kk = total.tot_sum(z, m)
            assert kk == k == n - 3 * m + 1, (name, m)
            assert got == pytest.approx(want, rel=1e-10), (name, m)


def test_total_sum_is_the_same_in_many_chunks(monkeypatch: pytest.MonkeyPatch) -> None:
    """Rows taken a few at a time (the last one shorter) give the sum of all rows at once,
    and the progress callback rises to 1."""
    z = np.cumsum(np.random.default_rng(7).standard_normal(1001))
    want = _direct(z, 5)[0]
    monkeypatch.setattr(total, "_ELEMENTS", 200)
    seen: list[float] = []
    got, k = total.tot_sum(z, 5, progress=seen.append)
    assert k == 1001 - 15 + 1
    assert got == pytest.approx(want, rel=1e-10)
    assert len(seen) > 3 and seen == sorted(seen) and seen[-1] == 1.0


def test_total_sum_of_too_short_a_series_is_empty() -> None:
    """Fewer than 3m points: no subsequence, a zero sum."""
    assert total.tot_sum(np.arange(8.0), 3) == (0.0, 0)


def test_total_family_through_the_command_line_on_a_gapped_file(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A phase file with a gap: mtotdev, ttotdev and htotdev as the command line prints them
    are the definition's sums pooled over the two stretches, Σ S / Σ count (SP 1065 eqs.
    27–29; HTOT at m = 1 is the overlapping Hadamard deviation)."""
    from thermocal.cli import main

    rng = np.random.default_rng(5)
    t = np.r_[np.arange(0.0, 400.0), np.arange(450.0, 751.0)]
    x = np.cumsum(rng.standard_normal(t.size)) + 0.05 * rng.standard_normal(t.size)
    path = tmp_path / "phase.csv"
    np.savetxt(path, np.c_[t, x], delimiter=",", header="time,x", comments="", fmt="%.17g")
    args = [str(path), "--signal", "x", "--data-type", "phase", "--time-unit", "s"]
    code = main(["allan", *args, "--deviation", "mtotdev,ttotdev,htotdev", "--json"])
    cap = capsys.readouterr()
    assert code == 0, cap.err
    assert "1 gaps in time" in cap.err
    res = json.loads(cap.out)
    parts = [x[:400], x[400:]]
    for i, tau in enumerate(res["tau_s"]):
        m = round(tau)
        mt = [_direct(p, m) for p in parts if p.size >= 3 * m]
        s_m = sum(s for s, _ in mt) / (2.0 * tau * tau)
        k_m = sum(k for _, k in mt)
        assert res["mtotdev"][i] == pytest.approx(np.sqrt(s_m / k_m), rel=1e-11)
        assert res["ttotdev"][i] == pytest.approx(np.sqrt(s_m * tau * tau / 3.0 / k_m), rel=1e-11)
        if m == 1:
            d3 = [np.diff(p, 3) for p in parts]
            want = np.sqrt(sum(float(d @ d) for d in d3) / 6.0 / sum(d.size for d in d3))
        else:
            ht = [_direct(np.diff(p), m) for p in parts if p.size - 1 >= 3 * m]
            want = np.sqrt(sum(s for s, _ in ht) / 6.0 / sum(k for _, k in ht))
        assert res["htotdev"][i] == pytest.approx(want, rel=1e-11)
    assert max(round(t) for t in res["tau_s"]) >= 64  # the fast kernel's factors


def test_total_sums_report_progress_and_reuse_a_series_sums() -> None:
    """Several factors at once: the same sums as one at a time, the :func:`total.reporting`
    callback receives operations adding up to the work estimate of every factor, and a
    second call on the same series (TTOT after MTOT) returns the same numbers."""
    z = np.cumsum(np.random.default_rng(3).standard_normal(2001))
    ms = [1, 2, 3, 8, 64, 666, 667, 668]
    seen: list[float] = []
    with total.reporting(seen.append):
        got = total.tot_sums(z, ms)
    assert got[-1] == (0.0, 0)  # 3m > N: no subsequence
    for (s, k), m in zip(got[:-1], ms, strict=False):
        want, kk = _direct(z, m)
        assert k == kk and s == pytest.approx(want, rel=1e-10)
    assert sum(seen) == pytest.approx(sum(total.cost(2001, m) for m in ms), rel=1e-12)
    assert total.tot_sums(z, ms) == got


def test_ctrl_c_during_the_total_family_exits_130(tmp_path: Path) -> None:
    """SIGINT while ``allan --deviation mtotdev,htotdev`` runs on 2e5 points: exit 130, one
    line on stderr and no traceback (the factors running in threads stop at their next
    chunk)."""
    import os
    import signal
    import subprocess
    import sys
    import time

    path = tmp_path / "phase.csv"
    x = np.cumsum(np.random.default_rng(9).standard_normal(200_000))
    np.savetxt(path, np.c_[np.arange(x.size), x], delimiter=",", header="time,x", comments="")
    code = "import sys; from thermocal.cli import main; sys.exit(main(sys.argv[1:]))"
    argv = [sys.executable, "-c", code, "allan", str(path), "--signal", "x", "--data-type",
            "phase", "--time-unit", "s", "--deviation", "mtotdev,htotdev", "--taus", "all",
            "--max-work", "1e15"]  # fmt: skip
    env = {**os.environ, "PYTHONPATH": str(Path(total.__file__).parents[2])}
    proc = subprocess.Popen(
        argv,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        env=env,
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),  # as from a shell
    )
    try:
        time.sleep(6.0)  # read, and well into the factors (every τ: hours of work)
        assert proc.poll() is None
        os.kill(proc.pid, signal.SIGINT)
        out, err = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 130, err
    assert b"Traceback" not in err and out == b""
    assert err.decode().splitlines()[-1] == "interrupted: nothing written"


def test_the_work_estimate_counts_subsequences_and_points() -> None:
    """The estimate behind ``--max-work``: at m ≤ 2 ten operations per point of the
    N − 3m + 1 subsequences of 9m points; above, 400 per point of the series; nothing when
    3m exceeds N + 1."""
    assert total.cost(61, 2) == 10.0 * 9 * 2 * (61 - 6 + 1)
    assert total.cost(61, 1) == 10.0 * 9 * 1 * (61 - 3 + 1)
    assert total.cost(2001, 667) == 400.0 * 2001  # one subsequence
    assert total.cost(2001, 668) == 0.0
