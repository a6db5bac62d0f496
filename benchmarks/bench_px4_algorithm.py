"""Benchmark: ``thermocal px4-tempcal`` against PX4's own offboard thermal calibration, on a
hard simulated PX4 ULog (issue 28, item 4).

**PX4's algorithm** (:func:`px4_algorithm`), restated from PX4-Autopilot
``Tools/process_sensor_caldata.py`` (github.com/PX4/PX4-Autopilot) and the PX4 user guide,
"Thermal Compensation" (docs.px4.io, "Offboard calibration"), for every ``sensor_gyro`` and
``sensor_accel`` instance:

1. TMIN, TMAX = the extremes of the instance's temperature; TREF = (TMIN + TMAX)/2;
2. each axis through a running median of 31 samples (scipy ``medfilt``, zero-padded ends);
3. accelerometers: the axis minus its median (gravity is in the data); gyros as they are;
4. the span TMIN…TMAX cut into 2000 equal bins; per occupied bin the *mean* of T − TREF and
   the mean of the filtered axis (the script's ``resampleWithDeltaX``, a per-sample Python
   loop there, ``np.bincount`` here: this restatement is faster than the script);
5. ``np.polyfit`` of order 3 of the bin means → TC_G/TC_A ``X3…X0``;
6. (``--plots``) one PDF page per instance with every filtered sample and the cubic, as the
   script writes ``<log>.pdf``; (``--as-script``) that and the bins filled one sample at a
   time as the script does: PX4's algorithm timed as its users run it.

**Judged with the firmware's formula** (PX4 ``TemperatureCompensation.cpp``):
``offset = X0 + X1·dT + X2·dT² + X3·dT³``, ``dT = clamp(T, TMIN, TMAX) − TREF``, against the
TRUE bias on a grid of 400 temperatures over the calibrated range (the common part of both
parameter sets' TMIN…TMAX): rms of ``offset − bias`` per axis; accelerometers after removing
the mean over the range (both programs write relative accelerometer offsets: gravity is in
the data; the offset that remains is taken by the ordinary accelerometer calibration).

**The log** (:func:`hard_log`): two IMUs (gyro and accelerometer instances 0 and 1), a
power-on self-heating sweep ``T = T0 + ΔT·(1 − e^{−t/τ})`` (fast at the start, slow at the
end), biases that are a cubic plus a tanh step (not cubic), white noise, isolated spikes and
bursts of spikes, handling bumps during the first minutes (the board picked up and turned:
seconds of rotation rate and of gravity on other axes), one logging drop-out of 90 s.

Usage::

    PYTHONPATH=src .venv/bin/python benchmarks/bench_px4_algorithm.py [--size small|large]
        [--plots | --as-script | --parse] [--keep DIR] [--repeat N | --quick]
        [--before OLD/src]

``small`` ≈ 5 MB (seconds), ``large`` ≈ 50 MB (the issue's size).  Timed (wall and peak
resident memory of each a fresh process as a user runs it, ``_harness.measure_cpu``), best of
``--repeat`` (3) runs interleaved: ``thermocal px4-tempcal LOG -o DIR`` (reports included),
with ``--before`` the same command from another source tree (the code before a change), and
this file's ``--px4-only LOG`` (PX4's algorithm; with ``--plots`` its PDF too, with
``--as-script`` as the script runs it).  Printed: the ratio thermocal/PX4 and the speed-up,
before → after, and the memory of the command above that of the same command on a tiny log
(≈ 1 MB) against the log's size (issue 41, item 1: at most 1/1.5 of the script's time, at
most 2× the log's size).  The load average is printed at the start, after each run and at
the end.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _harness import THERMOCAL, compiled, measure_cpu, memory_above, race, residual_table

F64 = npt.NDArray[np.float64]
G0 = 9.80665
MEDIAN_SAMPLES = 31
"""PX4's running-median length (``medfilt(data, 31)``)."""
PX4_BINS = 2000
"""PX4's number of equal temperature bins (``resampleWithDeltaX``: ``nbInterval``)."""
SIZES = {"tiny": 8_000, "small": 40_000, "large": 380_000}
"""Samples per topic instance: 4 instances × 33 bytes a message → ≈ 1, 5 and 50 MB (the
tiny log: the memory baseline of the command)."""

_REC = np.dtype(
    [("size", "<u2"), ("kind", "u1"), ("msg_id", "<u2"), ("timestamp", "<u8"),
     ("device_id", "<u4"), ("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("temperature", "<f4")]
)  # fmt: skip
"""One ULog data message of a ``sensor_gyro``/``sensor_accel`` instance (ULog file format,
docs.px4.io: message header ``uint16 size, uint8 'D'``, then ``uint16 msg_id`` and the
packed fields)."""
_FIELDS = "uint64_t timestamp;uint32_t device_id;float x;float y;float z;float temperature;"


def _ulog(topics: list[tuple[str, int, np.ndarray]]) -> bytes:
    """(name, instance, records of :data:`_REC`) → a ULog file: header, flag bits, format,
    add-logged and data messages (the layout of tests/helpers/ulog_writer.py, vectorised)."""
    import struct

    out = bytearray(b"ULog\x01\x12\x35\x01" + struct.pack("<Q", 0))

    def msg(kind: str, payload: bytes) -> None:
        out.extend(struct.pack("<HB", len(payload), ord(kind)) + payload)

    msg("B", bytes(16) + struct.pack("<3Q", 0, 0, 0))
    for name in dict.fromkeys(n for n, _i, _r in topics):
        msg("F", f"{name}:{_FIELDS}".encode())
    for msg_id, (name, inst, _r) in enumerate(topics):
        msg("A", struct.pack("<BH", inst, msg_id) + name.encode())
    for msg_id, (_n, _i, rec) in enumerate(topics):
        rec["size"], rec["kind"], rec["msg_id"] = _REC.itemsize - 3, ord("D"), msg_id
        out.extend(rec.tobytes())
    return bytes(out)


def true_bias(kind: str, inst: int, temp_c: F64) -> F64:
    """The true thermal bias (n, 3) [rad/s or m/s²] of an instance: a cubic in
    x = (T − 20)/30 plus a tanh step of 3 °C width (at 12 °C on instance 0, 31 °C on 1)."""
    x = (temp_c - 20.0) / 30.0
    step = np.tanh((temp_c - (12.0 if inst == 0 else 31.0)) / 3.0)
    s = 1.0 if inst == 0 else -0.7
    if kind == "gyro":
        cols = [0.002 + 0.004 * x - 0.0015 * x**2 + 0.001 * x**3 + 0.0012 * step,
                s * (-0.001 + 0.003 * x) + 0.0008 * x**2 - 0.0007 * step,
                0.003 * x**2 - 0.001 * x**3 + s * 0.0010 * step]  # fmt: skip
    else:
        cols = [0.05 + 0.08 * x + 0.03 * x**3 + 0.025 * step,
                s * -0.04 * x + 0.02 * x**2 - 0.02 * step,
                0.1 * x - 0.04 * x**2 + s * 0.03 * step]  # fmt: skip
    return np.column_stack(cols)


def hard_log(n: int, seed: int = 28) -> tuple[bytes, dict[str, Any]]:
    """The hard log's bytes and its truth (the sweep of each instance)."""
    rng = np.random.default_rng(seed)
    dur = 2700.0
    t = np.linspace(0.0, dur, n)
    keep = ~((t > 1500.0) & (t < 1590.0))  # a logging drop-out of 90 s
    topics: list[tuple[str, int, np.ndarray]] = []
    for inst in (0, 1):
        temp = -8.0 + 2.0 * inst + 56.0 * (1.0 - np.exp(-t / 700.0))
        temp += rng.normal(0.0, 0.02, n)
        bumps = np.zeros((n, 3))
        for start in (40.0, 95.0, 170.0, 230.0):  # handling in the first minutes (same board)
            w = (t >= start) & (t < start + 6.0)
            bumps[w] = np.sin(np.pi * (t[w, None] - start) / 6.0) * [0.6, -0.4, 0.3]
        for kind, name, noise, spike in (("gyro", "sensor_gyro", 0.003, 0.8),
                                         ("accel", "sensor_accel", 0.05, 6.0)):  # fmt: skip
            v = true_bias(kind, inst, temp) + rng.normal(0.0, noise, (n, 3))
            if kind == "accel":
                v[:, 2] -= G0
                v += G0 * bumps[:, [1, 0, 2]] * [1.0, 1.0, 0.3]  # gravity onto other axes
            else:
                v += bumps
            hit = rng.integers(0, n, n // 400)
            v[hit] += rng.choice([-1.0, 1.0], (hit.size, 3)) * spike  # isolated spikes
            for b in rng.integers(0, n - 40, 12):  # bursts of 20 spikes: longer than 31/2
                v[b : b + 20] += spike
            rec = np.zeros(int(keep.sum()), _REC)
            rec["timestamp"] = (1e6 + t[keep] * 1e6).astype(np.uint64)
            rec["device_id"] = (2293768 if kind == "gyro" else 2293776) + 256 * inst
            rec["x"], rec["y"], rec["z"] = v[keep].T
            rec["temperature"] = temp[keep]
            topics.append((name, inst, rec))
    topics.sort(key=lambda r: (r[0], r[1]))
    return _ulog(topics), {"n": n}


# --- PX4's algorithm, restated --------------------------------------------------------------


def _bin_means(x: F64, y: F64) -> tuple[F64, F64]:
    """PX4's ``resampleWithDeltaX``: 2000 equal bins over min…max of ``x``; the mean x and
    mean y of every occupied bin (the top end in the last bin)."""
    lo, hi = float(np.min(x)), float(np.max(x))
    width = (hi - lo) / PX4_BINS
    k = np.clip(((x - lo) / width).astype(np.int64), 0, PX4_BINS - 1)
    cnt = np.bincount(k, minlength=PX4_BINS)
    occ = cnt > 0
    xs = np.bincount(k, x, PX4_BINS)[occ] / cnt[occ]
    ys = np.bincount(k, y, PX4_BINS)[occ] / cnt[occ]
    return xs, ys


def _bin_means_per_sample(x: F64, y: F64) -> tuple[F64, F64]:
    """:func:`_bin_means` the way the script computes it: one Python step per sample
    (same result; for timing the script as users run it)."""
    lo, hi = float(np.min(x)), float(np.max(x))
    width = (hi - lo) / PX4_BINS
    sx, sy, cnt = np.zeros(PX4_BINS), np.zeros(PX4_BINS), np.zeros(PX4_BINS)
    for xi, yi in zip(x.tolist(), y.tolist(), strict=True):
        k = 0 if xi < lo else (int((xi - lo) / width) if xi < hi else PX4_BINS - 1)
        sx[k] += xi
        sy[k] += yi
        cnt[k] += 1
    occ = cnt > 0
    return sx[occ] / cnt[occ], sy[occ] / cnt[occ]


def px4_algorithm(
    log: Path, pdf: Path | None = None, *, per_sample: bool = False
) -> dict[str, float]:
    """PX4's offboard thermal calibration of every gyro and accelerometer instance of
    ``log`` (module docstring), as the parameters ``TC_G<n>_*``/``TC_A<n>_*``; ``pdf``: its
    plots written there; ``per_sample``: the bins filled one sample at a time, as the
    script does (:func:`_bin_means_per_sample`)."""
    binning = _bin_means_per_sample if per_sample else _bin_means
    from pyulog import ULog
    from scipy.signal import medfilt

    ulog = ULog(str(log), ["sensor_gyro", "sensor_accel"])
    params: dict[str, float] = {}
    pages: list[tuple[str, F64, F64, F64, float]] = []
    for d in sorted(ulog.data_list, key=lambda d: (d.name, d.multi_id)):
        letter = "G" if d.name == "sensor_gyro" else "A"
        pre = f"TC_{letter}{d.multi_id}_"
        temp = np.asarray(d.data["temperature"], dtype=np.float64)
        tmin, tmax = float(np.min(temp)), float(np.max(temp))
        tref = 0.5 * (tmin + tmax)
        params.update({pre + "ID": float(np.median(d.data["device_id"])),
                       pre + "TMIN": tmin, pre + "TMAX": tmax, pre + "TREF": tref})  # fmt: skip
        ys = []
        for i, axis in enumerate("xyz"):
            y = medfilt(np.asarray(d.data[axis], dtype=np.float64), MEDIAN_SAMPLES)
            if letter == "A":
                y = y - np.median(y)
            xb, yb = binning(temp - tref, y)
            c = np.polyfit(xb, yb, 3)  # highest power first
            for k in range(4):
                params[f"{pre}X{k}_{i}"] = float(c[3 - k])
            ys.append(y)
        pages.append((pre, temp, np.column_stack(ys), np.array([tmin, tmax]), tref))
    if pdf is not None:
        _plots(pdf, pages, params)
    return params


def _plots(pdf: Path, pages: list[tuple[str, F64, F64, F64, float]], p: dict[str, float]) -> None:
    """The script's PDF: per instance three panels, every filtered sample and the cubic."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.backends.backend_pdf import PdfPages

    with PdfPages(pdf) as pp:
        for pre, temp, ys, ends, tref in pages:
            fig, axs = plt.subplots(3, 1, figsize=(20, 13))
            grid = np.linspace(ends[0], ends[1], 100)
            for i, ax in enumerate(axs):
                c = [p[f"{pre}X{k}_{i}"] for k in range(4)]
                ax.plot(temp, ys[:, i], "b")
                ax.plot(grid, np.polyval(c[::-1], grid - tref), "r")
                ax.grid()
            pp.savefig(fig)
            plt.close(fig)


# --- judging ----------------------------------------------------------------------------------


def read_params(path: Path) -> dict[str, float]:
    """A QGroundControl parameter file (``vehicle component name value type``)."""
    out = {}
    for line in path.read_text().splitlines():
        if line.strip() and not line.startswith("#"):
            f = line.split("\t")
            out[f[2]] = float(f[3])
    return out


def firmware_offset(p: dict[str, float], pre: str, axis: int, temp_c: F64) -> F64:
    """PX4's correction offset of one axis at ``temp_c`` (TemperatureCompensation.cpp):
    ``X0 + X1·dT + X2·dT² + X3·dT³``, ``dT = clamp(T, TMIN, TMAX) − TREF``."""
    dt = np.clip(temp_c, p[pre + "TMIN"], p[pre + "TMAX"]) - p[pre + "TREF"]
    x = [p[f"{pre}X{k}_{axis}"] for k in range(4)]
    return x[0] + dt * (x[1] + dt * (x[2] + dt * x[3]))


def residuals(ours: dict[str, float], px4: dict[str, float]) -> list[tuple[str, float, float]]:
    """(name, rms thermocal, rms PX4) per instance and axis: the firmware's offset against the
    true bias over the common calibrated range (accelerometers: mean over the range
    removed)."""
    rows = []
    for letter, kind in (("G", "gyro"), ("A", "accel")):
        for inst in (0, 1):
            pre = f"TC_{letter}{inst}_"
            if pre + "TREF" not in ours or pre + "TREF" not in px4:
                continue
            lo = max(ours[pre + "TMIN"], px4[pre + "TMIN"])
            hi = min(ours[pre + "TMAX"], px4[pre + "TMAX"])
            grid = np.linspace(lo, hi, 400)
            truth = true_bias(kind, inst, grid)
            for i, axis in enumerate("xyz"):
                got = []
                for p in (ours, px4):
                    err = firmware_offset(p, pre, i, grid) - truth[:, i]
                    if kind == "accel":
                        err = err - err.mean()
                    got.append(float(np.sqrt(np.mean(err**2))))
                rows.append((f"{kind}{inst}.{axis}", got[0], got[1]))
    return rows


def _ours(tree: Path | None, log: Path, out: Path, *extra: str) -> list[str]:
    """``thermocal px4-tempcal LOG -o OUT`` as a user runs it, from this tree or ``tree``
    (the code before a change: its ``src``)."""
    env = [] if tree is None else ["env", f"PYTHONPATH={tree}"]
    return [*env, *THERMOCAL, "px4-tempcal", str(log), "-o", str(out), "--allow-motion",
            "--json", *extra]  # fmt: skip


def _time_parse(log: Path) -> None:
    """pyulog's parse of the four sensor topics against :func:`fast_ulog`'s (the same
    object, asserted), best of 3 each after a warm-up read of the file."""
    from pyulog import ULog

    from thermocal.readers.ulog_fast import fast_ulog

    names = ["sensor_gyro", "sensor_accel", "sensor_baro", "sensor_mag"]
    log.read_bytes()  # warm: the file in the page cache
    best: dict[str, float] = {}
    got: dict[str, Any] = {}
    for _ in range(3):
        for how, parse in (
            ("pyulog", lambda: ULog(str(log), message_name_filter_list=names)),
            ("fast", lambda: fast_ulog(log, names)),
        ):
            t0 = time.perf_counter()
            got[how] = parse()
            best[how] = min(best.get(how, math.inf), time.perf_counter() - t0)
    assert got["fast"] is not None and got["fast"] == got["pyulog"]
    print(f"parse: pyulog {best['pyulog']:.3f} s, fast {best['fast']:.3f} s, "
          f"ratio {best['fast'] / best['pyulog']:.2f}")  # fmt: skip
    print(f"load average after: {os.getloadavg()[0]:.2f}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", choices=sorted(SIZES), default="small")
    ap.add_argument("--plots", action="store_true", help="PX4's algorithm writes its PDF too")
    ap.add_argument(
        "--as-script",
        action="store_true",
        help="PX4's algorithm as the script runs it: its PDF and its per-sample binning loop",
    )
    ap.add_argument("--keep", type=Path, help="write the log and outputs here")
    ap.add_argument(
        "--parse",
        action="store_true",
        help="only time the ULog parse of the log's four sensor topics: pyulog against "
        "thermocal's fast reader (readers.ulog_fast), same process, best of 3 each, warm",
    )
    ap.add_argument("--repeat", type=int, default=3, help="runs of each program (best of)")
    ap.add_argument("--quick", action="store_true", help="one run of each")
    ap.add_argument(
        "--before",
        type=Path,
        help="also time thermocal from this src folder (the code before a change: "
        "git archive BASE src | tar -x -C DIR, then DIR/src), interleaved",
    )
    ap.add_argument("--px4-only", type=Path, help=argparse.SUPPRESS)
    ap.add_argument("--out", type=Path, help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.px4_only is not None:  # the timed child: PX4's algorithm on a log
        pdf = a.px4_only.with_suffix(".pdf") if a.plots or a.as_script else None
        p = px4_algorithm(a.px4_only, pdf, per_sample=a.as_script)
        assert a.out is not None
        a.out.write_text("".join(f"1\t1\t{k}\t{v!r}\t9\n" for k, v in p.items()))
        return
    work = a.keep or Path(tempfile.mkdtemp(prefix="px4bench"))
    work.mkdir(parents=True, exist_ok=True)
    log = work / f"hard_{a.size}.ulg"
    data, _truth = hard_log(SIZES[a.size])
    log.write_bytes(data)
    mb_log = log.stat().st_size / 1e6
    print(f"log {log}: {mb_log:.1f} MB, {SIZES[a.size]} samples per instance")
    print(f"load average before: {os.getloadavg()[0]:.2f}")
    if a.parse:
        _time_parse(log)
        return
    os.environ["PYTHONPATH"] = str(Path(__file__).resolve().parents[1] / "src")
    compiled([Path(os.environ["PYTHONPATH"]), *([a.before] if a.before else [])])
    px4_params = work / "px4_algorithm.params"
    px4 = [sys.executable, __file__, "--px4-only", str(log), "--out", str(px4_params)]
    px4 += (["--plots"] if a.plots else []) + (["--as-script"] if a.as_script else [])
    cmds = {"thermocal": _ours(None, log, work / "out")}
    if a.before is not None:
        cmds["thermocal before"] = _ours(a.before, log, work / "out_before")
    cmds["PX4 algorithm"] = px4
    best = race(cmds, 1 if a.quick else a.repeat)
    rows = residuals(read_params(work / "out" / "px4.params"), read_params(px4_params))
    geo, worst = residual_table(rows, "PX4 algo")
    print(f"ratio thermocal/PX4: geometric mean over the axes {geo:.2f}, worst axis "
          f"{worst:.2f} (targets: <= 0.8, every axis <= 1)")  # fmt: skip
    _speed_table(a, best, log, work, mb_log)
    print(f"load average after: {os.getloadavg()[0]:.2f}")


def _speed_table(
    a: argparse.Namespace, best: dict[str, tuple[float, float, float]], log: Path, work: Path,
    mb_log: float,
) -> None:  # fmt: skip
    """The times and memories side by side, the ratios, the targets (issue 41, item 1)."""
    how = "as the script runs it" if a.as_script else "with its PDF" if a.plots else "bare"
    t_px4, _mb_px4, cpu_px4 = best["PX4 algorithm"]
    print(
        f"{'program':<38} {'best s':>8} {'peak MB':>8} {'CPU s':>7} {'ratio':>6} {'CPU ratio':>9}"
    )
    for name, (t, mb, cpu) in best.items():
        label = f"PX4 algorithm ({how})" if name == "PX4 algorithm" else name
        print(f"{label:<38} {t:8.2f} {mb:8.0f} {cpu:7.2f} {t / t_px4:6.2f} {cpu / cpu_px4:9.2f}")
    t_ours, mb_ours, cpu_ours = best["thermocal"]
    print(f"time: thermocal px4-tempcal {t_ours:.2f} s, PX4 algorithm {how} {t_px4:.2f} s, "
          f"ratio {t_ours / t_px4:.2f} (speed-up {t_px4 / t_ours:.2f}x); CPU {cpu_ours:.2f} s "
          f"against {cpu_px4:.2f} s, ratio {cpu_ours / cpu_px4:.2f}")  # fmt: skip
    if "thermocal before" in best:
        t_old, mb_old, cpu_old = best["thermocal before"]
        print(f"before -> after: {t_old:.2f} s -> {t_ours:.2f} s ({t_old / t_ours:.2f}x), "
              f"CPU {cpu_old:.2f} -> {cpu_ours:.2f} s, "
              f"peak {mb_old:.0f} -> {mb_ours:.0f} MB")  # fmt: skip
    tiny = work / "hard_tiny.ulg"
    tiny.write_bytes(hard_log(SIZES["tiny"])[0])
    base = min(measure_cpu(_ours(None, tiny, work / f"out_tiny{i}"))[1] for i in range(2))
    memory_above(mb_ours, log, base, tiny)
    if a.as_script:
        ok = t_ours / t_px4 <= 1 / 1.5
        print(f"target (<= 0.667 of PX4's script's time): {'met' if ok else 'NOT met'}")


if __name__ == "__main__":
    main()
