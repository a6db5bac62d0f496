"""An independent audit of the command line: attacks on the surfaces no other attack file
holds (``fit`` of every family, ``compensate``, ``export-c``,
``inspect``, ``report``, ``simulate``/``profile``, ``demo``, ``px4-tempcal``,
``ardupilot-tempcal``), through the CLI, every input hashed before and after.

One row per attack: the files are generated here, the command runs in-process, and the
row says what must happen -- ``refuse`` (exit 2, one ``error:`` line holding the row's
words, no output file, no temporary left), ``warn`` (exit 0 and a ``warning:`` line
holding the words) or ``valid`` (exit 0; where the row has a check, the numbers are
compared with an independent computation written here).  ``before`` records what the
command did on ``main`` before this audit's fixes (the audit's "before" column; run this
file with ``PYTHONPATH`` on an older tree to see those rows fail).  The table's counts are
asserted so that nobody drops a row."""

from __future__ import annotations

import contextlib
import csv
import hashlib
import io
import json
import signal
import warnings
from collections import Counter
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from types import FrameType
from typing import Any

import numpy as np
import pytest

from dataflash_writer import imu_log
from thermocal.cli import main
from thermocal.models.format import checksum
from thermocal.outputs import TEMP_SUFFIX
from ulog_writer import SENSOR_FIELDS, ulog_bytes

N = 1200


"""Rows of the good recording: 1200 s at 1 Hz, a temperature ramp 10 → 50 °C."""


def _frame() -> dict[str, np.ndarray]:
    rng = np.random.default_rng(39)
    t = np.arange(N, dtype=float)
    temp = 10.0 + 40.0 * t / (N - 1)
    gyro = 0.5 + 0.02 * (temp - 25.0) + 1e-4 * (temp - 25.0) ** 2 + rng.normal(0, 0.002, N)
    return {"time": t, "gyro": gyro, "T1": temp}


def _csv(cols: dict[str, np.ndarray], eol: str = "\n") -> bytes:
    lines = [",".join(cols)]
    lines += [",".join(repr(float(v)) for v in row) for row in zip(*cols.values(), strict=True)]
    return (eol.join(lines) + eol).encode()


FRAME = _frame()


GOOD = _csv(FRAME)


UNITS = ("--signal-unit", "deg/h", "--time-unit", "s", "--temp-unit", "degC")


FIT = ("fit", "{d}/d.csv", "-o", "{d}/m.json", "--signal", "gyro", "--temps", "T1", *UNITS)


CU = ("--time-unit", "s", "--temp-unit", "degC")


COMP = ("compensate", "{d}/m.json", "{d}/d.csv", "-o", "{d}/o.csv", *CU)


EXC = ("export-c", "{d}/m.json", "-o", "{d}/out")


def _with(**cols: np.ndarray) -> bytes:
    return _csv({**FRAME, **cols})


def _model_dict() -> dict[str, Any]:
    """The good model: ``fit --model poly --order 2`` on :data:`GOOD` (made once)."""
    return json.loads(_good_model())


_MODEL: list[bytes] = []


def _good_model() -> bytes:
    if not _MODEL:
        import tempfile

        with tempfile.TemporaryDirectory() as d, _quiet():
            Path(d, "d.csv").write_bytes(GOOD)
            argv = [a.format(d=d) for a in FIT] + ["--model", "poly", "--order", "2"]
            assert main(argv) == 0
            _MODEL.append(Path(d, "m.json").read_bytes())
    return _MODEL[0]


def _edited(edit: Callable[[dict[str, Any]], None]) -> Callable[[], bytes]:
    """The good model edited by hand, its checksum recomputed (as anyone can)."""

    def make() -> bytes:
        m = _model_dict()
        edit(m)
        m.pop("checksum")
        m["checksum"] = checksum(m)
        return json.dumps(m).encode()

    return make


def _coef(value: float) -> Callable[[dict[str, Any]], None]:
    def edit(m: dict[str, Any]) -> None:
        m["state"]["coef"][0] = value

    return edit


def _set(path: tuple[Any, ...], value: object) -> Callable[[dict[str, Any]], None]:
    def edit(m: dict[str, Any]) -> None:
        d = m
        for k in path[:-1]:
            d = d[k]
        d[path[-1]] = value

    return edit


def _sweep(n: int = 3000) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(time [µs], temperature [°C], gyro [rad/s] (n, 3), accel [m/s²] (n, 3)) at 10 Hz."""
    rng = np.random.default_rng(7)
    t_s = np.arange(n) * 0.1
    temp = 10.0 + 40.0 * t_s / t_s[-1]
    x = (temp - 30.0) / 20.0
    gyro = np.column_stack([0.002 * x, -0.001 * x, 0.0005 * x**2]) + rng.normal(0, 2e-4, (n, 3))
    accel = np.column_stack([0.05 * x, -0.03 * x, -9.80665 + 0.1 * x]) + rng.normal(0, 0.01, (n, 3))
    return (1e6 + t_s * 1e6).astype(np.int64), temp, gyro, accel


def _ulog(time_us: Any = None, temp: Any = None, n: int | None = None) -> Callable[[], bytes]:
    def make() -> bytes:
        ts, tc, gyro, accel = _sweep()
        ts = ts if time_us is None else time_us(ts)
        tc = tc if temp is None else temp(tc)
        s = slice(None, n)

        def rows(v: np.ndarray, dev: int) -> list[tuple[float, ...]]:
            return [
                (int(a), dev, *map(float, r), float(b))
                for a, r, b in zip(ts[s], v[s], tc[s], strict=True)
            ]

        return ulog_bytes(
            [
                ("sensor_gyro", 0, SENSOR_FIELDS, rows(gyro, 2293768)),
                ("sensor_accel", 0, SENSOR_FIELDS, rows(accel, 2293776)),
            ]
        )

    return make


def _dataflash(edit: Callable[[list[tuple[float, ...]]], list[tuple[float, ...]]]) -> bytes:
    ts, tc, gyro, accel = _sweep()
    rows = [
        (int(s), 0, *map(float, g), *map(float, a), 0, 0, float(t))
        for s, g, a, t in zip(ts, gyro, accel, tc, strict=True)
    ]
    return imu_log(edit(rows))


def _profile(rows: list[tuple[float, float]]) -> bytes:
    return ("time_s,setpoint_c\n" + "".join(f"{a!r},{b!r}\n" for a, b in rows)).encode()


def _poly_matches_numpy(d: Path, _err: str) -> None:
    """The model written equals numpy's own least-squares quadratic of the good data."""
    m = json.loads((d / "m.json").read_text())
    got = {c["name"]: c["value"] for c in m["coefficients"]}
    c2, c1, c0 = np.polyfit(FRAME["T1"], FRAME["gyro"], 2)
    assert got["T1^2"] == pytest.approx(c2, rel=1e-6)
    assert got["T1"] == pytest.approx(c1, rel=1e-6)
    assert got["const"] == pytest.approx(c0, rel=1e-6, abs=1e-9)


def _breakpoints_sorted(d: Path, _err: str) -> None:
    """``--breakpoints 40,20`` is the same program as ``20,40``."""
    m = json.loads((d / "m.json").read_text())
    assert m["state"]["initial_breakpoints"] == [20.0, 40.0]


def _compensated_by_numpy(d: Path, _err: str) -> None:
    """gyro_comp = gyro − model, the model numpy's quadratic of the same data."""
    with (d / "o.csv").open() as f:
        rows = list(csv.DictReader(f))
    comp = np.array([float(r["gyro_comp"]) for r in rows])
    ref = FRAME["gyro"] - np.polyval(np.polyfit(FRAME["T1"], FRAME["gyro"], 2), FRAME["T1"])
    assert np.max(np.abs(comp - ref)) < 1e-9


def _c_names_clean(d: Path, _err: str) -> None:
    """The C prefix is an identifier: nothing of ``a*/evil();/*`` reaches code."""
    for p in (d / "out").iterdir():
        text = p.read_text()
        assert "evil();" not in text and "*/evil" not in text


def _tiny_written_as_float_zero(d: Path, _err: str) -> None:
    """A constant below FLT_MIN is what a float holds of it, 0 (numpy's binary32), not a
    literal the compiler truncates with a warning."""
    text = (d / "out" / "m.c").read_text()
    assert np.float32(1e-50) == 0.0
    assert "1e-50" not in text and "0.0f," in text


def _html_escaped(d: Path, _err: str) -> None:
    html = (d / "r.html").read_text()
    assert "<script>alert(1)</script>" not in html
    assert "&lt;script&gt;alert(1)" in html


@dataclass(frozen=True)
class Attack:
    id: str
    """``surface/name``."""
    argv: tuple[str, ...]
    """``{d}`` stands for the attack's folder."""
    files: dict[str, bytes | Callable[[], bytes]]
    expect: str
    """refuse | warn | valid"""
    words: str = ""
    before: str = ""
    """What ``main`` did before the audit's fixes: the expected outcome's name, or vague (a
    refusal that does not name the option at fault), silent, exit1, hang, partial (output
    left beside an exit 1)."""
    check: Callable[[Path, str], None] | None = None


def _r(
    id_: str, argv: tuple[str, ...], files: dict[str, Any], words: str, before: str = "refuse"
) -> Attack:
    return Attack(id_, argv, files, "refuse", words, before)


M: dict[str, Any] = {"m.json": _good_model}


D: dict[str, Any] = {"d.csv": GOOD}


DM: dict[str, Any] = {**D, **M}


# fmt: off
ATTACKS: list[Attack] = [
    # fit: every family, option and file oddity
    Attack("fit/ok", (*FIT, "--model", "poly", "--order", "2"), D, "valid", before="valid",
           check=_poly_matches_numpy),
    _r("fit/order-negative", (*FIT, "--model", "poly", "--order", "-1"), D, "--order"),
    _r("fit/order-1e9", (*FIT, "--model", "poly", "--order", "1000000000"), D, "--order"),
    _r("fit/time-backwards", (*FIT, "--model", "poly", "--order", "2"),
       {"d.csv": _with(time=FRAME["time"][::-1].copy())}, "backwards"),
    _r("fit/time-duplicated", (*FIT, "--model", "poly", "--order", "2"),
       {"d.csv": _with(time=np.r_[FRAME["time"][:500], 499.0, FRAME["time"][501:]])},
       "duplicate timestamp 499"),
    _r("fit/temperature-constant", (*FIT, "--model", "poly", "--order", "2"),
       {"d.csv": _with(T1=np.full(N, 25.0))}, "constant"),
    _r("fit/temperature-all-nan", (*FIT, "--model", "poly", "--order", "2"),
       {"d.csv": _with(T1=np.full(N, np.nan))}, "'T1'"),
    Attack("fit/kelvin-declared-degC", (*FIT, "--model", "poly", "--order", "2"),
           {"d.csv": _with(T1=FRAME["T1"] + 273.15)}, "warn", "kelvin?", "warn"),
    _r("fit/duplicate-column-names", ("fit", "{d}/d.csv", "-o", "{d}/m.json", "--model", "poly",
       "--signal", "gyro", "--temps", "gyro", "--order", "2"),
       {"d.csv": GOOD.replace(b"time,gyro,T1", b"time,gyro,gyro", 1)}, "appears twice"),
    Attack("fit/bom", (*FIT, "--model", "poly", "--order", "2"), {"d.csv": b"\xef\xbb\xbf" + GOOD},
           "valid", before="valid", check=_poly_matches_numpy),
    Attack("fit/mixed-line-endings", (*FIT, "--model", "poly", "--order", "2"),
           {"d.csv": GOOD.replace(b"\n", b"\r\n", 300)}, "valid", before="valid",
           check=_poly_matches_numpy),
    _r("fit/latin1-column-name", (*FIT, "--model", "poly", "--order", "2"),
       {"d.csv": GOOD.replace(b"gyro", b"gyr\xe9", 1)}, "no column 'gyro'"),
    _r("fit/kelvin-unit", ("fit", "{d}/d.csv", "-o", "{d}/m.json", "--model", "poly", "--signal",
       "gyro", "--temps", "T1", "--temp-unit", "K", "--order", "2"), D, "'K'"),
    _r("fit/piecewise-breakpoint-outside", (*FIT, "--model", "piecewise", "--breakpoints",
       "100,200"), D, "breakpoint 100"),
    Attack("fit/piecewise-breakpoints-unsorted", (*FIT, "--model", "piecewise",
           "--breakpoints", "40,20"), D, "valid", before="valid",
           check=_breakpoints_sorted),
    _r("fit/piecewise-breakpoints-repeated", (*FIT, "--model", "piecewise", "--breakpoints",
       "30,30"), D, "distinct"),
    _r("fit/piecewise-breakpoint-nan", (*FIT, "--model", "piecewise", "--breakpoints", "nan"),
       D, "breakpoint nan"),
    _r("fit/piecewise-breakpoints-empty", (*FIT, "--model", "piecewise", "--breakpoints", ","),
       D, "--breakpoints ','", "silent"),
    _r("fit/piecewise-breakpoint-at-the-edge", (*FIT, "--model", "piecewise", "--breakpoints",
       "10"), D, "breakpoint 10"),
    _r("fit/piecewise-segments-1e6", (*FIT, "--model", "piecewise", "--segments", "1000000"), D,
       "--segments"),
    _r("fit/rate-interval-0", (*FIT, "--model", "poly", "--terms", "T1,dT1", "--rate-interval",
       "0"), D, "--rate-interval", "vague"),
    _r("fit/rate-interval-inf", (*FIT, "--model", "poly", "--terms", "T1,dT1", "--rate-interval",
       "inf"), D, "--rate-interval", "vague"),
    _r("fit/terms-negative-power", (*FIT, "--model", "poly", "--terms", "T1^-1,T1"), D,
       "T1^-1"),
    _r("fit/terms-power-99", (*FIT, "--model", "poly", "--terms", "T1^99"), D, "power 99"),
    _r("fit/terms-sensor-9", (*FIT, "--model", "poly", "--terms", "T9"), D, "T9"),
    _r("fit/ridge-nan", (*FIT, "--model", "poly", "--order", "2", "--ridge", "nan"), D,
       "--ridge", "vague"),
    _r("fit/rcond-nan", (*FIT, "--model", "poly", "--order", "2", "--rcond", "nan"), D,
       "--rcond", "silent"),
    _r("fit/rcond-negative", (*FIT, "--model", "poly", "--order", "2", "--rcond", "-1"), D,
       "--rcond", "silent"),
    _r("fit/noise-threshold-nan", (*FIT, "--model", "poly", "--order", "2", "--noise-threshold",
       "nan"), D, "--noise-threshold", "silent"),
    _r("fit/known-input-nan", (*FIT, "--model", "poly", "--order", "2", "--known-input", "nan"),
       D, "--known-input", "vague"),
    _r("fit/latitude-200", (*FIT, "--model", "poly", "--order", "2", "--latitude", "200",
       "--axis", "up"), D, "--latitude", "silent"),
    _r("fit/latitude-nan", (*FIT, "--model", "poly", "--order", "2", "--latitude", "nan",
       "--axis", "up"), D, "--latitude", "vague"),
    _r("fit/tref-inf", (*FIT, "--model", "poly", "--order", "2", "--tref", "inf"), D, "TREF"),
    _r("fit/warmup-start-window-nan", (*FIT, "--model", "warmup", "--start-window", "nan"), D,
       "--start-window"),  # the option, no longer the constructor's parameter name
    _r("fit/bank-tolerance-nan", (*FIT, "--model", "bank", "--tolerance", "nan"), D,
       "tolerance"),
    _r("fit/gravity-nan", ("fit", "{d}/d.csv", "-o", "{d}/m.json", "--model", "poly", "--signal",
       "gyro", "--temps", "T1", "--signal-unit", "mg", "--time-unit", "s", "--temp-unit", "degC",
       "--order", "2", "--gravity-axis", "+z", "--gravity", "nan"), D, "--gravity"),
    _r("fit/same-file-twice", ("fit", "{d}/d.csv", "{d}/d.csv", *FIT[2:], "--model", "poly",
       "--order", "2"), D, "given twice", "silent"),
    _r("fit/a-copy-of-a-run", ("fit", "{d}/d.csv", "{d}/e.csv", *FIT[2:], "--model", "poly",
       "--order", "2"), {**D, "e.csv": GOOD}, "the same bytes as", "silent"),
    _r("fit/model-spline", (*FIT, "--model", "spline"), D, "spline"),
    _r("fit/output-over-input", ("fit", "{d}/d.csv", "-o", "{d}/d.csv", "--model", "poly",
       "--signal", "gyro", "--temps", "T1", *UNITS, "--order", "2"), D, "over the input"),
    # compensate: a model and a recording that do not belong together, odd outputs
    Attack("compensate/ok", COMP, DM, "valid", before="valid", check=_compensated_by_numpy),
    _r("compensate/accelerometer-unit", (*COMP, "--signal-unit", "mg"), DM, "(accel)"),
    _r("compensate/other-channel-name", COMP,
       {**M, "d.csv": GOOD.replace(b"time,gyro,T1", b"time,gx,T1", 1)}, "'gyro'"),
    _r("compensate/other-temperature-name", COMP,
       {**M, "d.csv": GOOD.replace(b"time,gyro,T1", b"time,gyro,Tboard", 1)}, "'T1'"),
    _r("compensate/signal-is-the-temperature", (*COMP, "--signal", "T1"), DM, "'degC'"),
    _r("compensate/output-over-input", ("compensate", "{d}/m.json", "{d}/d.csv", "-o",
       "{d}/d.csv", *CU), DM, "over the input"),
    _r("compensate/output-over-model", ("compensate", "{d}/m.json", "{d}/d.csv", "-o",
       "{d}/m.json", *CU), DM, "over the input"),
    _r("compensate/stdout-dash", ("compensate", "{d}/m.json", "{d}/d.csv", "-o", "-", *CU), DM,
       "-: not a CSV"),
    _r("compensate/stdin-dash", ("compensate", "{d}/m.json", "-", "-o", "{d}/o.csv", *CU), M,
       "-: not a CSV"),
    _r("compensate/model-dash", ("compensate", "-", "{d}/d.csv", "-o", "{d}/o.csv", *CU), D,
       "-: no such model"),
    _r("compensate/output-xlsx", ("compensate", "{d}/m.json", "{d}/d.csv", "-o", "{d}/o.xlsx",
       *CU), DM, "o.xlsx"),
    _r("compensate/chunk-rows-1", (*COMP, "--chunk-rows", "1"), DM, "chunk size"),
    _r("compensate/model-t-scale-0", COMP,
       {**D, "m.json": _edited(_set(("state", "base", 0, "t_scale"), 0.0))}, "t_scale"),
    _r("compensate/model-coefficients-short", COMP,
       {**D, "m.json": _edited(_set(("state", "coef"), [0.1]))}, "state.coef"),
    _r("compensate/model-unit-furlong", COMP,
       {**D, "m.json": _edited(_set(("signal", "unit"), "furlong"))}, "furlong"),
    _r("compensate/model-power-50", COMP,
       {**D, "m.json": _edited(_set(("state", "terms", 1, "t_power"), 50))}, "t_power"),
    _r("compensate/model-temperatures-repeat", COMP,
       {**D, "m.json": _edited(_set(("temperatures",), ["T1", "T1"]))}, "repeat"),
    _r("compensate/model-family-swapped", COMP,
       {**D, "m.json": _edited(_set(("family",), "bank"))}, "bank"),
    _r("compensate/model-edited-without-checksum", COMP,
       {**D, "m.json": lambda: _good_model().replace(b'"order": 2', b'"order": 3')},
       "checksum"),
    _r("compensate/model-truncated", COMP, {**D, "m.json": lambda: _good_model()[:500]},
       "corrupted"),
    _r("compensate/model-nested-1e5", COMP, {**D, "m.json": b"[" * 100000 + b"]" * 100000},
       "nested"),
    _r("compensate/model-is-the-csv", ("compensate", "{d}/d.csv", "{d}/d.csv", "-o", "{d}/o.csv",
       *CU), D, "corrupted"),
    Attack("compensate/outside-the-range", COMP, {**M, "d.csv": _with(T1=FRAME["T1"] + 40.0)},
           "warn", "outside its calibrated range", "warn"),
    _r("compensate/header-only", COMP, {**M, "d.csv": b"time,gyro,T1\n"}, "no data rows"),
    Attack("compensate/one-row", COMP, {**M, "d.csv": b"time,gyro,T1\n0,1,20\n"}, "warn",
           "only 1 samples", "warn"),
    # export-c: names, edited models, float range
    Attack("export-c/name-injection", (*EXC, "--name", "a*/evil();/*"), M, "valid",
           before="valid", check=_c_names_clean),
    _r("export-c/sample-interval-nan", (*EXC, "--sample-interval", "nan"), M, "sample interval"),
    _r("export-c/unit-of-another-kind", (*EXC, "--unit", "mg"), M, "'mg'"),
    _r("export-c/output-is-the-model", ("export-c", "{d}/m.json", "-o", "{d}/m.json"), M,
       "not a directory"),
    _r("export-c/float-coefficient-1e300", (*EXC, "--float"), {"m.json": _edited(_coef(1e300))},
       "FLT_MAX", "partial"),
    _r("export-c/float-coefficient-minus-1e39", (*EXC, "--float"),
       {"m.json": _edited(_coef(-1e39))}, "FLT_MAX", "partial"),
    Attack("export-c/float-coefficient-1e-50", (*EXC, "--float"),
           {"m.json": _edited(_coef(1e-50))}, "valid", before="partial",
           check=_tiny_written_as_float_zero),
    Attack("export-c/float-build-overflows", (*EXC, "--float"),
           {"m.json": _edited(_coef(3e38))}, "warn", "not finite", "silent"),
    _r("export-c/edited-without-checksum", EXC,
       {"m.json": lambda: _good_model().replace(b'"order": 2', b'"order": 3')}, "checksum"),
    # inspect
    _r("inspect/empty", ("inspect", "{d}/d.csv"), {"d.csv": b""}, "empty"),
    _r("inspect/one-row", ("inspect", "{d}/d.csv", *CU), {"d.csv": b"time,gyro,T1\n0,1,20\n"},
       "fewer than 2"),
    _r("inspect/nul-bytes", ("inspect", "{d}/d.csv"), {"d.csv": GOOD[:200] + b"\0" * 50},
       "NUL"),
    _r("inspect/parquet-magic-only", ("inspect", "{d}/d.parquet"),
       {"d.parquet": b"PAR1" + b"\0" * 100 + b"PAR1"}, "Parquet"),
    _r("inspect/a-directory", ("inspect", "{d}"), {}, "{d}"),
    _r("inspect/every-value-nan", ("inspect", "{d}/d.csv", *CU),
       {"d.csv": b"time,gyro,T1\n" + b"".join(b"%d,nan,nan\n" % i for i in range(50))},
       "NaN"),
    # report
    _r("report/empty-recording", ("report", "--model", "{d}/m.json", "--recording", "{d}/d.csv",
       "-o", "{d}/r.html"), {**M, "d.csv": b""}, "empty"),
    _r("report/validation-not-a-result", ("report", "--model", "{d}/m.json", "--recording",
       "{d}/d.csv", "--validation", "{d}/v.json", "-o", "{d}/r.html", *CU),
       {**DM, "v.json": b"{}"}, "not a validation result"),
    _r("report/average-nan", ("report", "--model", "{d}/m.json", "--recording", "{d}/d.csv",
       "-o", "{d}/r.html", "--average", "nan", *CU), DM, "averaging time"),
    Attack("report/title-script", ("report", "--model", "{d}/m.json", "--recording",
           "{d}/d.csv", "-o", "{d}/r.html", "--title", "<script>alert(1)</script>", *CU), DM,
           "valid", before="valid", check=_html_escaped),
    # simulate, profile: absurd durations and rates
    _r("simulate/rate-1e9", ("simulate", "rlg-modelling", "-o", "{d}/s.parquet", "--rate-hz",
       "1e9"), {}, "--rate-hz", "exit1"),
    _r("simulate/mems-imu-rate-1e9", ("simulate", "mems-imu", "-o", "{d}/s", "--rate-hz", "1e9"),
       {}, "--rate-hz", "exit1"),
    _r("simulate/program-1e12-s", ("simulate", "fog-slow", "-o", "{d}/s.parquet", "--profile",
       "{d}/p.csv"), {"p.csv": _profile([(0, 20), (1e12, 30)])}, "1e+12 samples", "exit1"),
    _r("simulate/record-s-1e12", ("simulate", "mems-warmup", "-o", "{d}/s", "--record-s",
       "1e12"), {}, "--record-s", "exit1"),
    _r("simulate/runs-1e6", ("simulate", "accel-full-range", "-o", "{d}/s", "--runs",
       "1000000"), {}, "1000000 runs", "hang"),
    _r("simulate/set-point-below-absolute-zero", ("simulate", "fog-slow", "-o", "{d}/s.parquet",
       "--profile", "{d}/p.csv"), {"p.csv": _profile([(0, 20), (3600, -300), (7200, 20)])},
       "below absolute zero", "silent"),
    _r("simulate/program-backwards", ("simulate", "fog-slow", "-o", "{d}/s.parquet", "--profile",
       "{d}/p.csv"), {"p.csv": _profile([(0, 20), (100, 30), (50, 20)])}, "increase"),
    _r("simulate/rate-tiny", ("simulate", "rlg-modelling", "-o", "{d}/s.parquet", "--rate-hz",
       "1e-300"), {}, "two samples"),
    _r("simulate/output-over-truth", ("simulate", "fog-slow", "-o", "{d}/s.csv", "--truth",
       "{d}/s.csv"), {}, "s.csv"),
    _r("profile/correlate-constant", ("profile", "correlate", "{d}/p.csv", "{d}/q.csv"),
       {"p.csv": _profile([(0, 20), (100, 30), (200, 20)]),
        "q.csv": _profile([(0, 20), (100, 20), (200, 20)])}, "constant"),
    _r("profile/correlate-empty", ("profile", "correlate", "{d}/p.csv", "{d}/q.csv"),
       {"p.csv": b"", "q.csv": b""}, "p.csv"),
    # demo
    _r("demo/output-is-a-file", ("demo", "-o", "{d}/x"), {"x": b"hi"}, "not a directory"),
    _r("demo/time-scale-0", ("demo", "-o", "{d}/o", "--station", "--time-scale", "0"), {},
       "--time-scale"),
    _r("demo/seed-negative", ("demo", "-o", "{d}/o", "--seed", "-5", "--quick"), {}, "--seed",
       "partial"),
    _r("demo/imu-seed-negative", ("demo", "-o", "{d}/o", "--seed", "-5", "--imu", "--quick"), {},
       "--seed", "vague"),
    # flight-controller logs
    _r("px4-tempcal/zero-bytes", ("px4-tempcal", "{d}/l.ulg", "-o", "{d}/out"), {"l.ulg": b""},
       "empty"),
    _r("px4-tempcal/header-only", ("px4-tempcal", "{d}/l.ulg", "-o", "{d}/out"),
       {"l.ulg": b"ULog\x01\x12\x35\x01" + b"\0" * 8}, "no sensor_gyro"),
    _r("px4-tempcal/one-sample", ("px4-tempcal", "{d}/l.ulg", "-o", "{d}/out"),
       {"l.ulg": _ulog(n=1)}, "fewer than 2"),
    _r("px4-tempcal/time-backwards", ("px4-tempcal", "{d}/l.ulg", "-o", "{d}/out"),
       {"l.ulg": _ulog(time_us=lambda t: t[::-1].copy())}, "backwards"),
    _r("px4-tempcal/temperature-nan", ("px4-tempcal", "{d}/l.ulg", "-o", "{d}/out"),
       {"l.ulg": _ulog(temp=lambda t: np.full_like(t, np.nan))}, "no sensor_gyro"),
    _r("px4-tempcal/output-is-the-log", ("px4-tempcal", "{d}/l.ulg", "-o", "{d}/l.ulg"),
       {"l.ulg": _ulog()}, "not a directory"),
    _r("ardupilot-tempcal/zero-bytes", ("ardupilot-tempcal", "{d}/l.bin", "-o", "{d}/out"),
       {"l.bin": b""}, "l.bin"),
    _r("ardupilot-tempcal/one-sample", ("ardupilot-tempcal", "{d}/l.bin", "-o", "{d}/out"),
       {"l.bin": lambda: _dataflash(lambda r: r[:1])}, "fewer than 2"),
    _r("ardupilot-tempcal/time-backwards", ("ardupilot-tempcal", "{d}/l.bin", "-o", "{d}/out"),
       {"l.bin": lambda: _dataflash(lambda r: r[::-1])}, "backwards"),
    _r("ardupilot-tempcal/temperature-nan", ("ardupilot-tempcal", "{d}/l.bin", "-o", "{d}/out"),
       {"l.bin": lambda: _dataflash(lambda r: [(*x[:-1], float("nan")) for x in r])},
       "usable temperature"),
    _r("ardupilot-tempcal/instance-5-only", ("ardupilot-tempcal", "{d}/l.bin", "-o", "{d}/out"),
       {"l.bin": lambda: _dataflash(lambda r: [(x[0], 5, *x[2:]) for x in r])},
       "instance 0"),
    _r("px4-tempcal/temps-from-missing", ("px4-tempcal", "{d}/l.ulg", "-o", "{d}/out",
       "--temps-from", "3"), {"l.ulg": _ulog()}, "--temps-from names sensor_gyro"),
    _r("px4-tempcal/temperature-unknown", ("px4-tempcal", "{d}/l.ulg", "-o", "{d}/out",
       "--temperature", "smooth"), {"l.ulg": _ulog()}, "give reconstructed or raw"),
    _r("ardupilot-tempcal/temps-from-missing", ("ardupilot-tempcal", "{d}/l.bin", "-o",
       "{d}/out", "--temps-from", "baro"), {"l.bin": lambda: _dataflash(lambda r: r)},
       "--temps-from names BARO.0"),
]


def test_the_table_keeps_every_row() -> None:
    """The audit's counts (this file's rows; the report of issue 39 quotes them)."""
    assert len({a.id for a in ATTACKS}) == len(ATTACKS) == 113
    assert Counter(a.expect for a in ATTACKS) == {"refuse": 101, "warn": 4, "valid": 8}
    assert Counter(a.before for a in ATTACKS) == {
        "refuse": 79,
        "valid": 7,
        "warn": 3,
        "vague": 6,
        "silent": 9,
        "exit1": 4,
        "partial": 4,
        "hang": 1,
    }
    surfaces = Counter(a.id.split("/")[0] for a in ATTACKS)
    assert surfaces == {
        "fit": 40,
        "compensate": 25,
        "export-c": 9,
        "inspect": 6,
        "report": 4,
        "simulate": 9,
        "profile": 2,
        "demo": 4,
        "px4-tempcal": 8,
        "ardupilot-tempcal": 6,
    }


@contextlib.contextmanager
def _quiet() -> Iterator[None]:
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        yield


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


@contextlib.contextmanager
def _memory_cap(extra: int = 4 << 30) -> Iterator[None]:
    """At most ``extra`` bytes of address space more than now (Linux): a regression that
    allocates without bound (``--runs 1e6`` took 11 GB before the budget) fails the row
    with a MemoryError instead of taking the machine."""
    try:
        import resource

        now = int(Path("/proc/self/statm").read_text().split()[0]) * resource.getpagesize()
        old = resource.getrlimit(resource.RLIMIT_AS)
        cap = now + extra if old[1] == resource.RLIM_INFINITY else min(now + extra, old[1])
        resource.setrlimit(resource.RLIMIT_AS, (cap, old[1]))
    except (ImportError, OSError, ValueError):
        yield
        return
    try:
        yield
    finally:
        resource.setrlimit(resource.RLIMIT_AS, old)


def _digest(p: Path) -> str:
    return hashlib.sha256(p.read_bytes()).hexdigest()


@pytest.mark.parametrize("attack", ATTACKS, ids=[a.id for a in ATTACKS])
def test_attack(attack: Attack, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    for name, content in attack.files.items():
        (tmp_path / name).write_bytes(content() if callable(content) else content)
    before = {p: _digest(p) for p in tmp_path.iterdir()}
    capsys.readouterr()
    with warnings.catch_warnings(), _alarm(), _memory_cap():
        warnings.simplefilter("ignore")
        code = main([a.format(d=tmp_path) for a in attack.argv])
    _out, err = capsys.readouterr()
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert "Traceback" not in err
    assert code in (0, 2), f"exit {code}: {err[-2000:]}"
    assert {p: _digest(p) for p in before} == before, "an input file changed"
    assert not list(tmp_path.rglob(f"*{TEMP_SUFFIX}")), "a temporary output is left"
    if attack.expect == "refuse":
        assert code == 2, f"exit {code}; stderr: {err[-2000:]}"
        assert lines and lines[-1].startswith("error: "), err
        assert sum(ln.startswith("error: ") for ln in lines) == 1, err
        assert attack.words.format(d=tmp_path) in lines[-1], lines[-1]
        assert "internal" not in lines[-1]
        assert sorted(tmp_path.iterdir()) == sorted(before), "an output was left"
        return
    assert code == 0, err[-2000:]
    if attack.expect == "warn":
        assert any(ln.startswith("warning: ") and attack.words in ln for ln in lines), err
    if attack.check is not None:
        attack.check(tmp_path, err)
