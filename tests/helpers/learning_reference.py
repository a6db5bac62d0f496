"""Independent restatements, for tests, of the firmware's own temperature learning, written
from the published sources sample by sample (not from thermocal's code):
ArduPilot ``AP_InertialSensor_tempcal.cpp`` ``Learn::add_sample`` / ``save_calibration``,
``AP_Math/polyfit.cpp``, ``Filter/LowPassFilter2p.cpp``; PX4
``temperature_calibration/gyro.cpp``, ``accel.cpp``, ``polyfit.hpp``.  And the chamber
sweeps the tests feed them."""

from __future__ import annotations

import math

import numpy as np

f32 = np.float32


def _biquad(fs: float, fc: float) -> tuple[np.float32, ...]:
    """LowPassFilter2p::compute_params in float."""
    ohm = f32(np.tan(f32(math.pi) / f32(f32(fs) / f32(fc))))
    k = f32(2.0) * f32(np.cos(f32(math.pi) / f32(4.0)))
    c = f32(1.0) + k * ohm + ohm * ohm
    b0 = ohm * ohm / c
    return (
        b0,
        f32(2.0) * b0,
        b0,
        f32(2.0) * (ohm * ohm - f32(1.0)) / c,
        (f32(1.0) - k * ohm + ohm * ohm) / c,
    )


class _Fit:
    """PolyFit<4, double, Vector3f>, written from polyfit.cpp's description: the normal
    equations of a cubic with its highest power first."""

    def __init__(self) -> None:
        self.a = np.zeros((4, 4))
        self.b = np.zeros((4, 3), np.float32)

    def add(self, x: float, y: np.ndarray) -> None:
        for r in range(4):
            for c in range(4):
                self.a[r, c] += x ** (6 - r - c)
            self.b[r] = self.b[r] + y * f32(x ** (3 - r))

    def solve(self) -> np.ndarray:
        return (np.linalg.solve(self.a, self.b.astype(np.float64))).astype(np.float32)


def reference_learning(t, temp, acc, gyr, tmax, spc=1.0):
    """Learn::add_sample for every sample, accelerometer then gyro; returns (stored params
    at the end, outcome, accel points, gyro points)."""
    b0, b1, b2, a1, a2 = _biquad(1000.0, 0.5 * spc)
    t0 = f32(temp[0])
    init = f32(float(t0) / float(f32(1.0) + a1 + a2))
    st = [dict(d1=init, d2=init, last=t0, ms=0, s=np.zeros(3, np.float32), n=0, fit=_Fit(),
               pts=[], pts_i=[]) for _ in range(2)]  # fmt: skip
    g = dict(start=t0, acc0=None, save_ms=0, stored={}, outcome=None)
    min_n = math.ceil(100 / spc)

    def save(temperature):
        out = {}
        for tag, s in (("ACC", st[0]), ("GYR", st[1])):
            p = s["fit"].solve()
            for k in range(3):
                for ax, v in zip("XYZ", p[2 - k] * f32(1e6), strict=True):
                    out[f"INS_TCAL1_{tag}{k + 1}_{ax}"] = float(v)
        out["INS_TCAL1_TMIN"], out["INS_TCAL1_TMAX"] = float(g["start"]), float(temperature)
        g["stored"] = out

    for i in range(t.size):
        now = math.floor(t[i] * 1000.0)
        for si, v in ((0, acc[i]), (1, gyr[i])):
            s = st[si]
            x = f32(temp[i])
            d0 = x - s["d1"] * a1 - s["d2"] * a2
            tf = d0 * b0 + s["d1"] * b1 + s["d2"] * b2
            s["d2"], s["d1"] = s["d1"], d0
            s["s"] = s["s"] + v.astype(np.float32)
            s["n"] += 1
            if s["n"] < min_n or tf - s["last"] < 0.5:
                if s["ms"] and tf - g["start"] >= 10 and now - s["ms"] > 600_000:
                    save(s["last"])
                    g["outcome"] = "timed out"
                    return g, st
                continue
            mean = s["s"] / f32(s["n"])
            mid = f32((tf + s["last"]) * f32(0.5))
            if si == 0:
                if g["acc0"] is None:
                    g["acc0"], g["start"] = mean, mid
                mean = mean - g["acc0"]
            s["fit"].add(float(f32(float(mid) - 35.0)), mean)
            s["pts"].append((float(mid), *map(float, mean), s["n"]))
            s["pts_i"].append((float(mid), *map(float, mean), s["n"], i))
            s["s"], s["n"], s["last"], s["ms"] = np.zeros(3, np.float32), 0, tf, now
            if tf - g["start"] >= 10:
                if tf >= f32(tmax):
                    save(tf)
                    g["outcome"] = "completed"
                    return g, st
                if now - g["save_ms"] > 15000:
                    g["save_ms"] = now
                    save(s["last"])
    return g, st


def sweep(n: int, rate_hz: float, t0_c: float, slope_c_s: float, seed: int = 0):
    """A chamber ramp logged at ``rate_hz``: a cubic gyro bias in T − 35 and an accelerometer
    line, white noise, a thermometer quantised to 1/128 °C."""
    rng = np.random.default_rng(seed)
    t = 5.0 + np.arange(n) / rate_hz
    temp = np.round((t0_c + slope_c_s * (t - t[0])) * 128.0) / 128.0
    u = temp - 35.0
    gyr = np.column_stack([2e-4 * u + 3e-6 * u**2 - 5e-8 * u**3, -1e-4 * u, 0.01 + 0 * u])
    acc = np.column_stack([0.002 * u, 0 * u, -9.80665 + 1e-3 * u])
    gyr = gyr + 1e-4 * rng.standard_normal(gyr.shape)
    acc = acc + 2e-3 * rng.standard_normal(acc.shape)
    return t, temp, acc, gyr


def reference_px4(t, temp, v, tdel, tmin, tmax, accel=False):
    low = high = ref = None
    xs, ys, hot = [], [], False
    for i in range(t.size):
        x = f32(temp[i])
        if x < f32(tmin):
            continue
        if low is None:
            if t[i] <= 10.0:
                continue
            if x > f32(tmax):
                return "too hot", None
            low = high = x
            ref = f32(x + f32(0.5) * f32(tdel))
            continue
        if hot or not x > high:
            continue
        high = x
        hot = bool(high - low > f32(tdel))
        xs.append(float(x) - float(ref))
        ys.append(v[i])
    if not hot:
        return "not completed", (low, high)
    vand = np.vander(np.array(xs), 4)  # highest power first
    p = np.linalg.solve(vand.T @ vand, vand.T @ np.array(ys))
    if accel:
        p[3] = 0.0
    return "completed", (low, high, ref, p)
