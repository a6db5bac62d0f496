"""Benchmark: ``thermocal ardupilot-tempcal`` against ArduPilot's own IMU temperature
calibration script, on a hard simulated ArduPilot DataFlash log (issue 41, item 1).

**ArduPilot's script** (:func:`ardupilot_algorithm`), restated (not copied: the script is
GPLv3) from ArduPilot ``Tools/scripts/tempcal_IMU.py`` (github.com/ArduPilot/ardupilot,
commit d420971136c6db2430273e91d117ad8c9044bcee), run as its users run it
(``tempcal_IMU.py LOG``: no ``--tclr``, no ``--online``, graphs on):

1. the log opened with pymavlink (``mavutil.mavlink_connection``, its DataFlash reader
   ``DFReader``) and read message by message with ``recv_match(type=['PARM', 'IMU'])``;
2. ``PARM``: the log's ``INS_TCAL<n>_ENABLE``, ``INS_TCAL<n>_{ACC,GYR}<k>_{X,Y,Z}``,
   ``INS_TCAL<n>_TMIN/TMAX``, ``INS_{ACC,GYR}<n>_CALTEMP``, ``INS_{ACC,GYR}<n>OFFS_*`` and
   ``AHRS_ORIENTATION`` (an active calibration whose ``ENABLE`` changes during the log stops
   the capture of that IMU);
3. ``IMU`` (field ``I`` the instance, ``T`` the temperature [°C], ``GyrX…`` [rad/s],
   ``AccX…`` [m/s²]): each sample as a pymavlink ``Vector3``, rotated back by the inverse
   board rotation when ``AHRS_ORIENTATION`` ≠ 0, the log's active correction removed
   (``ENABLE`` = 1), appended to the IMU's arrays (the script grows numpy arrays with
   ``np.append`` per sample, quadratic in the length: :func:`ardupilot_algorithm` appends to
   lists unless ``as_script``, which keeps ``np.append``; the list version is the faster
   one, so the anchor timed by default is generous to the script);
4. every array (X, Y, Z, T and time) through a moving average of 2 s
   (``window = int(n / duration)·2`` samples, ``cumsum``, only the full windows kept);
5. per IMU: TMIN, TMAX = the extremes of the filtered temperature; per axis ``np.polyfit``
   of order 3 in ``T − 35 °C`` (``TEMP_REF``: the firmware's fixed reference) of the gyro
   and of the accelerometer minus its mean (no ``INS_ACC<n>_CALTEMP`` in the log);
6. the ``.parm`` file: ``INS_TCAL<n>_ENABLE 1``, ``_TMIN``/``_TMAX`` (``%.1f``) and the
   coefficients of orders 1…3 scaled ×1e6 (``%.9f``) as ``INS_TCAL<n>_ACC<k>_<X|Y|Z>`` and
   ``_GYR<k>_<X|Y|Z>`` (the constant is not saved: the offsets take it);
7. the graphs (on by default; ``--no-graph`` off): two figures (gyro in °/s, accelerometer),
   one panel per IMU, every filtered sample of each axis uncorrected and corrected, and the
   temperature on a twin axis; the script shows them on screen (``pyplot.show``), this
   restatement draws them with Agg and saves PNG files (the same drawing, no window).

**Judged with the firmware's formula** (ArduPilot ``AP_InertialSensor_tempcal.cpp``):
``correction(T) = poly(clamp(T, TMIN, TMAX) − 35)``, ``poly(t) = (c1 + (c2 + c3·t)·t)·t·1e-6``
(the firmware subtracts ``poly(T) − poly(T_cal)``: a constant, taken by the ordinary
offsets), against the TRUE bias on a grid of 400 temperatures over the common calibrated
range: rms of ``correction − bias`` per axis after removing its mean over the range.

**The log** (:func:`hard_log`): the hard features of ``bench_px4_algorithm.py`` (its true
biases: a cubic plus a tanh step), in a DataFlash log as ArduPilot writes it
(``LogStructure.h``: ``FMT`` self-description, ``PARM`` dump at start, today's ``IMU``
message "QBffffffIIfBBHH" with the instance in ``I``, an ``ATT`` message at 10 Hz besides):
two IMUs, a power-on self-heating sweep, white noise, isolated spikes and bursts of spikes,
handling bumps in the first minutes, one logging drop-out of 90 s.

Usage::

    PYTHONPATH=src .venv/bin/python benchmarks/bench_ardupilot_algorithm.py
        [--size small|large] [--repeat N] [--as-script] [--no-graph]
        [--old-src DIR [--before-repeat N]] [--keep DIR]

``small`` ≈ 5 MB (seconds), ``large`` ≈ 50 MB (the issue's size).  Timed, interleaved
(thermocal, script, [old thermocal], thermocal, …), best of ``--repeat``, each a fresh
process with its peak resident memory and CPU time (user + system, children included: on a
loaded machine the wall time is mostly waiting for a core), the trees byte-compiled first
(``_harness.measure_cpu``, ``compiled``):
``thermocal ardupilot-tempcal LOG -o DIR --allow-motion --json`` (every report) and this
file's ``--script-only LOG`` (the script restated); ``--old-src DIR``: thermocal of another
tree too (``git archive BASE src | tar -x -C DIR``), for before/after.
"""

from __future__ import annotations

import argparse
import math
import os
import re
import struct
import sys
import tempfile
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _harness import compiled, measure, measure_cpu, memory_above, race, residual_table
from bench_px4_algorithm import G0, true_bias

F64 = npt.NDArray[np.float64]
TEMP_REF = 35.0
"""The script's (and firmware's) reference temperature [°C]."""
POLY_ORDER = 3
SCALE = 1.0e6
"""The script's scale of the stored coefficients."""
FILTER_S = 2
"""The script's moving-average width [s]."""
SIZES = {"tiny": 9_000, "small": 45_000, "large": 450_000}
"""IMU samples per instance: 2 instances × 54 bytes a message (+ ATT) → ≈ 5 MB and ≈ 50 MB."""

# --- the log --------------------------------------------------------------------------------

_HEAD = b"\xa3\x95"
_FMT, _PARM, _IMU, _ATT = 128, 129, 130, 131
_IMU_REC = np.dtype(
    [("h0", "u1"), ("h1", "u1"), ("type", "u1"), ("TimeUS", "<u8"), ("I", "u1"),
     ("GyrX", "<f4"), ("GyrY", "<f4"), ("GyrZ", "<f4"), ("AccX", "<f4"), ("AccY", "<f4"),
     ("AccZ", "<f4"), ("EG", "<u4"), ("EA", "<u4"), ("T", "<f4"), ("GH", "u1"), ("AH", "u1"),
     ("GHz", "<u2"), ("AHz", "<u2")]
)  # fmt: skip
"""ArduPilot's ``IMU`` message (AP_InertialSensor/LogStructure.h "QBffffffIIfBBHH"), header
``A3 95 <type>`` included."""
_ATT_REC = np.dtype(
    [("h0", "u1"), ("h1", "u1"), ("type", "u1"), ("TimeUS", "<u8"), ("DesRoll", "<i2"),
     ("Roll", "<i2"), ("DesPitch", "<i2"), ("Pitch", "<i2"), ("DesYaw", "<u2"), ("Yaw", "<u2"),
     ("ErrRP", "<u2"), ("ErrYaw", "<u2"), ("AEKF", "u1")]
)  # fmt: skip
"""ArduPilot's ``ATT`` message ("QccccCCCCB", angles ×100): traffic the reader must skip."""
_FORMATS = (
    (_FMT, "FMT", "BBnNZ", "Type,Length,Name,Format,Columns", 89),
    (_PARM, "PARM", "QNf", "TimeUS,Name,Value", 31),
    (_IMU, "IMU", "QBffffffIIfBBHH", "TimeUS,I,GyrX,GyrY,GyrZ,AccX,AccY,AccZ,EG,EA,T,GH,AH,"
     "GHz,AHz", _IMU_REC.itemsize),
    (_ATT, "ATT", "QccccCCCCB", "TimeUS,DesRoll,Roll,DesPitch,Pitch,DesYaw,Yaw,ErrRP,ErrYaw,"
     "AEKF", _ATT_REC.itemsize),
)  # fmt: skip
_PARAMS = {"AHRS_ORIENTATION": 0.0, "INS_TCAL1_ENABLE": 0.0, "INS_TCAL2_ENABLE": 0.0,
           "INS_ACCOFFS_X": 0.0, "INS_ACC2OFFS_X": 0.0, "INS_GYROFFS_X": 0.0,
           "LOG_BITMASK": 176126.0}  # fmt: skip


def _header(time0_us: int) -> bytes:
    """The FMT self-description, the four formats and the parameter dump."""
    out = bytearray()
    for t, name, fmt, cols, length in _FORMATS:
        out += (
            _HEAD
            + bytes([_FMT])
            + struct.pack("<BB4s16s64s", t, length, name.encode(), fmt.encode(), cols.encode())
        )
    for name, value in _PARAMS.items():
        out += _HEAD + bytes([_PARM]) + struct.pack("<Q16sf", time0_us, name.encode(), value)
    return bytes(out)


def hard_log(n: int, seed: int = 41) -> bytes:
    """The hard log's bytes: ``n`` IMU samples per instance over 2700 s (module docstring)."""
    rng = np.random.default_rng(seed)
    t = np.linspace(0.0, 2700.0, n)
    keep = ~((t > 1500.0) & (t < 1590.0))  # a logging drop-out of 90 s
    recs = []
    for inst in (0, 1):
        temp = -8.0 + 2.0 * inst + 56.0 * (1.0 - np.exp(-t / 700.0))
        temp += rng.normal(0.0, 0.02, n)
        bumps = np.zeros((n, 3))
        for start in (40.0, 95.0, 170.0, 230.0):  # handling in the first minutes
            w = (t >= start) & (t < start + 6.0)
            bumps[w] = np.sin(np.pi * (t[w, None] - start) / 6.0) * [0.6, -0.4, 0.3]
        rec = np.zeros(int(keep.sum()), _IMU_REC)
        for kind, prefix, noise, spike in (("gyro", "Gyr", 0.003, 0.8),
                                           ("accel", "Acc", 0.05, 6.0)):  # fmt: skip
            v = true_bias(kind, inst, temp) + rng.normal(0.0, noise, (n, 3))
            if kind == "accel":
                v[:, 2] -= G0
                v += G0 * bumps[:, [1, 0, 2]] * [1.0, 1.0, 0.3]  # gravity onto other axes
            else:
                v += bumps
            hit = rng.integers(0, n, n // 400)
            v[hit] += rng.choice([-1.0, 1.0], (hit.size, 3)) * spike  # isolated spikes
            for b in rng.integers(0, n - 40, 12):  # bursts of 20 spikes
                v[b : b + 20] += spike
            for i, axis in enumerate("XYZ"):
                rec[prefix + axis] = v[keep, i]
        rec["TimeUS"] = (1e6 + t[keep] * 1e6).astype(np.uint64) + inst * 150
        rec["I"], rec["T"] = inst, temp[keep]
        rec["GHz"], rec["AHz"] = 1000, 1000
        recs.append(rec)
    imu = np.empty(recs[0].size * 2, _IMU_REC)
    imu[0::2], imu[1::2] = recs
    imu["h0"], imu["h1"], imu["type"] = 0xA3, 0x95, _IMU
    att_t = np.arange(1e6, 1e6 + 2700e6, 1e5)
    att_t = att_t[~((att_t > 1501e6) & (att_t < 1590e6))]
    att = np.zeros(att_t.size, _ATT_REC)
    att["h0"], att["h1"], att["type"], att["TimeUS"] = 0xA3, 0x95, _ATT, att_t.astype(np.uint64)
    att["Yaw"] = 9000
    # interleave: each ATT before the first IMU message not earlier than it
    at = np.searchsorted(imu["TimeUS"], att["TimeUS"])
    out = bytearray(_header(1_000_000))
    start = 0
    for a, idx in enumerate(at.tolist()):
        out += imu[start:idx].tobytes()
        out += att[a : a + 1].tobytes()
        start = idx
    out += imu[start:].tobytes()
    return bytes(out)


# --- ArduPilot's script, restated -----------------------------------------------------------

_TCAL_ENABLE = re.compile(r"^INS_TCAL(\d)_ENABLE$")
_TCAL_COEF = re.compile(r"^INS_TCAL(\d)_(ACC|GYR)([1-3])_([XYZ])$")
_TCAL_RANGE = re.compile(r"^INS_TCAL(\d)_(TMIN|TMAX)$")
_CALTEMP = re.compile(r"^INS_(ACC|GYR)(\d)_CALTEMP")


class _LogCal:
    """The calibration active in the log (the script's ``Coefficients`` of the log)."""

    def __init__(self) -> None:
        self.enable = [0.0] * 3
        self.tmin = [-100.0] * 3
        self.tmax = [-100.0] * 3
        self.coef: dict[tuple[int, str, str], list[float]] = {}
        self.caltemp: dict[tuple[int, str], float] = {}
        self.stop = [False] * 3
        self.orientation = 0

    def parm(self, name: str, value: float) -> None:
        """One PARM message, as the script takes it."""
        if m := _TCAL_ENABLE.match(name):
            imu = int(m.group(1)) - 1
            if self.stop[imu]:
                return
            if (value == 1 and self.enable[imu] == 2) or (value == 0 and self.enable[imu] == 1):
                self.stop[imu] = True  # the calibration changed during the log
                return
            self.enable[imu] = value
        elif m := _TCAL_COEF.match(name):
            imu = int(m.group(1)) - 1
            if not self.stop[imu]:
                c = self.coef.setdefault((imu, m.group(2), m.group(4)), [0.0] * 4)
                c[POLY_ORDER - int(m.group(3))] = value / SCALE
        elif m := _TCAL_RANGE.match(name):
            imu = int(m.group(1)) - 1
            if not self.stop[imu]:
                (self.tmin if m.group(2) == "TMIN" else self.tmax)[imu] = value
        elif m := _CALTEMP.match(name):
            imu = int(m.group(2)) - 1
            if not self.stop[imu]:
                self.caltemp[(imu, m.group(1))] = value
        elif name == "AHRS_ORIENTATION":
            self.orientation = int(value)

    def correction(self, imu: int, kind: str, temp: float) -> list[float]:
        """What the active calibration of the log adds back (the script's ``correction``)."""
        cal = self.caltemp.get((imu, kind), TEMP_REF)
        if self.enable[imu] != 1.0 or cal < -80:
            return [0.0, 0.0, 0.0]
        lo, hi = self.tmin[imu], self.tmax[imu]
        tc, cc = min(max(temp, lo), hi), min(max(cal, lo), hi)
        out = []
        for axis in "XYZ":
            c = self.coef.get((imu, kind, axis))
            out.append(0.0 if c is None else float(np.polyval(c, cc - TEMP_REF)
                                                   - np.polyval(c, tc - TEMP_REF)))  # fmt: skip
        return out


def _moving_average(x: F64, w: int) -> F64:
    """The script's ``moving_average``: cumulative sum, full windows of ``w`` only."""
    s = np.cumsum(x)
    s[w:] = s[w:] - s[:-w]
    return s[w - 1 :] / w


def _read(log: Path, as_script: bool) -> tuple[dict[int, dict[str, Any]], _LogCal]:
    """The script's read loop: per IMU the arrays X/Y/Z/T/time of accel and of gyro."""
    from pymavlink import mavutil
    from pymavlink.rotmat import Vector3

    mlog = mavutil.mavlink_connection(str(log))
    cal = _LogCal()
    data: dict[int, dict[str, Any]] = {}
    keys = [(k, f) for k in ("acc", "gyr") for f in ("X", "Y", "Z", "T", "time")]
    while True:
        msg = mlog.recv_match(type=["PARM", "IMU"])
        if msg is None:
            break
        if msg.get_type() == "PARM":
            cal.parm(msg.Name, msg.Value)
            continue
        imu = msg.I
        if cal.stop[imu]:
            continue
        temp = msg.T
        acc = Vector3(msg.AccX, msg.AccY, msg.AccZ)
        gyr = Vector3(msg.GyrX, msg.GyrY, msg.GyrZ)
        if cal.orientation != 0:
            acc = acc.rotate_by_inverse_id(cal.orientation)
            gyr = gyr.rotate_by_inverse_id(cal.orientation)
        if cal.enable[imu] == 1:
            acc -= Vector3(*cal.correction(imu, "ACC", temp))
            gyr -= Vector3(*cal.correction(imu, "GYR", temp))
        time_s = msg.TimeUS * 1.0e-6
        d = data.get(imu)
        if d is None:
            d = data[imu] = {k: np.zeros(0) if as_script else [] for k in keys}
        for kind, v in (("acc", acc), ("gyr", gyr)):
            for f, x in (("T", temp), ("X", v.x), ("Y", v.y), ("Z", v.z), ("time", time_s)):
                if as_script:
                    d[(kind, f)] = np.append(d[(kind, f)], x)
                else:
                    d[(kind, f)].append(x)
    return {i: {k: np.asarray(v, dtype=float) for k, v in d.items()} for i, d in data.items()}, cal


def ardupilot_algorithm(
    log: Path, graphs: Path | None = None, *, as_script: bool = False
) -> dict[str, float]:
    """ArduPilot's ``tempcal_IMU.py`` on ``log`` (module docstring) as its parameters
    ``INS_TCAL<n>_*`` (values as the script writes them, ×1e6); ``graphs``: its two figures
    saved there (``<graphs>_gyro.png``, ``<graphs>_accel.png``); ``as_script``: the arrays
    grown with ``np.append`` per sample, as the script does."""
    data, _cal = _read(log, as_script)
    for d in data.values():  # the 2 s moving average of every array
        for kind in ("acc", "gyr"):
            tt = d[(kind, "time")]
            w = int(tt.size / (tt[-1] - tt[0])) * FILTER_S
            if w > 1:
                for f in ("X", "Y", "Z", "T", "time"):
                    d[(kind, f)] = _moving_average(d[(kind, f)], w)
    params: dict[str, float] = {}
    polys: dict[tuple[int, str, str], F64] = {}
    for imu in sorted(data):
        d = data[imu]
        pre = f"INS_TCAL{imu + 1}_"
        params[pre + "ENABLE"] = 1.0
        params[pre + "TMIN"] = float(f"{np.amin(d[('acc', 'T')]):.1f}")
        params[pre + "TMAX"] = float(f"{np.amax(d[('acc', 'T')]):.1f}")
        for axis in "XYZ":
            a = d[("acc", axis)]
            polys[(imu, "acc", axis)] = np.polyfit(
                d[("acc", "T")] - TEMP_REF, a - np.mean(a), POLY_ORDER
            )
            polys[(imu, "gyr", axis)] = np.polyfit(
                d[("gyr", "T")] - TEMP_REF, d[("gyr", axis)], POLY_ORDER
            )
        for kind, tag in (("acc", "ACC"), ("gyr", "GYR")):
            for p in range(1, POLY_ORDER + 1):
                for axis in "XYZ":
                    v = polys[(imu, kind, axis)][POLY_ORDER - p] * SCALE
                    params[f"{pre}{tag}{p}_{axis}"] = float(f"{v:.9f}")
    if graphs is not None:
        _graphs(graphs, data, polys)
    return params


def _graphs(stem: Path, data: dict[int, dict[str, Any]], polys: dict[Any, F64]) -> None:
    """The script's two figures (gyro °/s, accel m/s²), every filtered sample, Agg."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    for kind, scale, title in (("gyr", math.degrees(1), "Gyro (deg/s)"),
                               ("acc", 1.0, "Accel (m/s^2)")):  # fmt: skip
        fig, axs = plt.subplots(len(data), 1, sharex=True, squeeze=False)
        for row, imu in enumerate(sorted(data)):
            d, ax = data[imu], axs[row][0]
            time_s, trel = d[(kind, "time")], d[(kind, "T")] - TEMP_REF
            for axis in "XYZ":
                y = d[(kind, axis)]
                y = y - np.mean(y) if kind == "acc" else y
                ax.plot(time_s, y * scale, label=f"Uncorrected {axis}")
            for axis in "XYZ":
                y = d[(kind, axis)]
                y = y - np.mean(y) if kind == "acc" else y
                corr = np.polyval(polys[(imu, kind, axis)], trel)
                ax.plot(time_s, (y - corr) * scale, label=f"Corrected {axis}")
            ax2 = ax.twinx()
            ax2.plot(time_s, d[(kind, "T")], label="Temperature(C)", color="black")
            ax2.legend(loc="upper right")
            ax.legend(loc="upper left")
            ax.set_title(f"IMU[{imu}] {title}")
        fig.savefig(f"{stem}_{'gyro' if kind == 'gyr' else 'accel'}.png")
        plt.close(fig)


# --- judging ----------------------------------------------------------------------------------


def read_parm(path: Path) -> dict[str, float]:
    """An ArduPilot ``.parm`` file (``NAME VALUE`` lines, ``#`` comments)."""
    out = {}
    for line in path.read_text().splitlines():
        f = line.split()
        if len(f) >= 2 and not line.startswith("#"):
            out[f[0]] = float(f[1])
    return out


def firmware_correction(p: dict[str, float], imu: int, tag: str, axis: str, temp_c: F64) -> F64:
    """ArduPilot's correction curve of one axis (AP_InertialSensor_tempcal.cpp):
    ``poly(clamp(T, TMIN, TMAX) − 35)``, ``poly(t) = (c1 + (c2 + c3·t)·t)·t·1e-6``."""
    pre = f"INS_TCAL{imu + 1}_"
    t = np.clip(temp_c, p[pre + "TMIN"], p[pre + "TMAX"]) - TEMP_REF
    c = [p[f"{pre}{tag}{k}_{axis}"] for k in (1, 2, 3)]
    return (c[0] + (c[1] + c[2] * t) * t) * t * 1e-6


def residuals(ours: dict[str, float], theirs: dict[str, float]) -> list[tuple[str, float, float]]:
    """(name, rms thermocal, rms script) per IMU and axis: the firmware's correction against
    the true bias over the common calibrated range, each after removing its mean."""
    rows = []
    for kind, tag in (("gyro", "GYR"), ("accel", "ACC")):
        for imu in (0, 1):
            pre = f"INS_TCAL{imu + 1}_"
            if pre + "TMIN" not in ours or pre + "TMIN" not in theirs:
                continue
            lo = max(ours[pre + "TMIN"], theirs[pre + "TMIN"])
            hi = min(ours[pre + "TMAX"], theirs[pre + "TMAX"])
            grid = np.linspace(lo, hi, 400)
            truth = true_bias(kind, imu, grid)
            for i, axis in enumerate("XYZ"):
                got = []
                for p in (ours, theirs):
                    err = firmware_correction(p, imu, tag, axis, grid) - truth[:, i]
                    err = err - err.mean()
                    got.append(float(np.sqrt(np.mean(err**2))))
                rows.append((f"{kind}{imu}.{axis.lower()}", got[0], got[1]))
    return rows


def _script_child(a: argparse.Namespace) -> None:
    """The timed child: the script restated on ``a.script_only``, its .parm to ``a.out``."""
    graphs = None if a.no_graph else a.out.with_suffix("")
    p = ardupilot_algorithm(a.script_only, graphs, as_script=a.as_script)
    a.out.write_text("".join(f"{k} {v!r}\n" for k, v in p.items()))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", choices=["small", "large"], default="small")
    ap.add_argument("--repeat", type=int, default=3, help="best of N, interleaved")
    ap.add_argument(
        "--as-script",
        action="store_true",
        help="the script's np.append per sample (quadratic: small logs only)",
    )
    ap.add_argument("--no-graph", action="store_true", help="the script without its graphs")
    ap.add_argument("--old-src", type=Path, help="a tree's src/ to time as 'before'")
    ap.add_argument(
        "--before-repeat",
        type=int,
        default=1,
        help="runs of 'before' (the first rounds; it is the slow one)",
    )
    ap.add_argument("--keep", type=Path, help="write the log and outputs here")
    ap.add_argument("--script-only", type=Path, help=argparse.SUPPRESS)
    ap.add_argument("--out", type=Path, help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.script_only is not None:
        _script_child(a)
        return
    work = a.keep or Path(tempfile.mkdtemp(prefix="apbench"))
    work.mkdir(parents=True, exist_ok=True)
    log = work / f"hard_{a.size}.bin"
    log.write_bytes(hard_log(SIZES[a.size]))
    size_mb = log.stat().st_size / 1e6
    print(f"log {log}: {size_mb:.1f} MB, {SIZES[a.size]} samples per IMU")
    load0 = os.getloadavg()[0]
    src = str(Path(__file__).resolve().parents[1] / "src")
    base_mb = measure([sys.executable, "-c", "import numpy"])[1]

    def ours(tree: str, tag: str) -> list[str]:
        prog = (
            f"import sys; sys.path.insert(0, {tree!r}); from thermocal.cli import main; "
            "sys.exit(main())"
        )
        return [sys.executable, "-c", prog, "ardupilot-tempcal", str(log), "-o",
                str(work / f"out_{tag}"), "--allow-motion", "--json"]  # fmt: skip

    runs = {"thermocal": ours(src, "new")}
    script_parm = work / "script.parm"
    runs["script"] = [sys.executable, __file__, "--script-only", str(log), "--out",
                      str(script_parm)] + (["--as-script"] if a.as_script else []) \
        + (["--no-graph"] if a.no_graph else [])  # fmt: skip
    if a.old_src is not None:
        runs["before"] = ours(str(a.old_src.resolve()), "old")
    compiled([Path(src)] + ([a.old_src] if a.old_src is not None else []))
    best = race(runs, a.repeat, {"before": a.before_repeat})
    load1 = os.getloadavg()[0]
    _quality(work, script_parm, a.old_src is not None)
    print(f"interpreter baseline (python -c 'import numpy'): {base_mb:.0f} MB")
    for name, (s, mb, cpu) in best.items():
        print(f"{name:<10} {s:7.2f} s  cpu {cpu:7.2f} s  peak {mb:6.0f} MB  above baseline "
              f"{(mb - base_mb) / size_mb:4.2f}× the log")  # fmt: skip
    (t_ours, _m, c_ours), (t_script, _n, c_script) = best["thermocal"], best["script"]
    how = "as the script runs it (np.append)" if a.as_script else "(list appends)"
    print(f"time ratio thermocal/script {how}{' without graphs' if a.no_graph else ''}: "
          f"wall {t_ours / t_script:.2f}, cpu {c_ours / c_script:.2f} (target <= 0.67, "
          "aim 0.5)")  # fmt: skip
    if "before" in best:
        print(f"time ratio thermocal after/before: wall {t_ours / best['before'][0]:.2f}, "
              f"cpu {c_ours / best['before'][2]:.2f}")  # fmt: skip
    # the memory figure as the PX4 benchmark states it: above the same command on a ~1 MB log
    tiny = work / "hard_tiny.bin"
    tiny.write_bytes(hard_log(SIZES["tiny"]))
    tiny_cmd = [str(tiny) if x == str(log) else x for x in ours(src, "tiny")]
    memory_above(best["thermocal"][1], log, min(measure_cpu(tiny_cmd)[1] for _ in range(2)), tiny)
    print(f"load average: start {load0:.2f}, end {load1:.2f}")


def _quality(work: Path, script_parm: Path, before: bool) -> None:
    """The residual table; with a 'before' run, its parameter file compared byte for byte."""
    ours = work / "out_new" / "ardupilot.parm"
    if before:
        old = work / "out_old" / "ardupilot.parm"
        same = ours.read_bytes() == old.read_bytes()
        print(f"parameter file byte-identical to before: {same}")
    geo, worst = residual_table(residuals(read_parm(ours), read_parm(script_parm)), "script")
    print(f"ratio thermocal/script: geometric mean over the axes {geo:.2f}, worst axis "
          f"{worst:.2f}")  # fmt: skip


if __name__ == "__main__":
    main()
