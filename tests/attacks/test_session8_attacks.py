"""Red-team pass on the surfaces added in session 8, generated here and run through the
command line where a user meets them.

1. ``--sensor ID`` and station recording folders (:mod:`thermocal.readers.station`): path
   tricks in the id, parts whose columns differ, a part that is not Parquet, a
   ``station.json`` that is not JSON or lists its sensors wrongly, ``-o`` into the folder
   through a link or ``..``, ``fleet`` on a station folder.
2. ``[chamber] preset`` (:mod:`thermocal.station.config`, :mod:`thermocal.station.chamber`):
   wrong types, a preset beside a disagreeing key, a scale of 0, negative, tiny or huge:
   a set-point the 16-bit register cannot hold, or one the scale would round far away, is
   refused before the chamber is touched.
3. Calibration files with a triad ``count_scale`` (format version 2): tampered values, a
   wrong checksum, a version-1 file carrying a count scale, conflicting column units, and
   export-c of a triad whose name is hostile C.
4. ``report --dynamic W``: windows that are not a length.
5. The output quantisation found in ``allan``/``noise`` (:func:`lattice_step`): constant
   and two-level records, huge magnitudes, float32 storage, NaN, 10 samples.
6. ``ardupilot-tempcal`` with ``PARM`` changes mid-log: a parameter set at every sample, an
   ``AHRS_ORIENTATION`` that is no rotation, a coefficient set to NaN, a change before the
   first IMU sample.

Everything a user can cause ends in exit 2 with one ``error:`` line naming the problem (no
traceback, no exit 1), or gives the right number."""

from __future__ import annotations

import contextlib
import io
import json
import os
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from station_toml import sensor_toml
from thermocal.cli import main
from thermocal.recording import META_KEY


def _run(argv: list[str]) -> tuple[int, str, str]:
    o, e = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(o), contextlib.redirect_stderr(e):
        code = main(argv)
    return code, o.getvalue(), e.getvalue()


def _refused(argv: list[str], *words: str) -> str:
    """Exit 2, exactly one ``error:`` line holding every word, no traceback."""
    code, _o, err = _run(argv)
    errors = [ln for ln in err.splitlines() if ln.startswith("error:")]
    assert code == 2, (code, err)
    assert len(errors) == 1 and "Traceback" not in err, err
    for w in words:
        assert w in errors[0], (w, errors[0])
    return errors[0]


# --- 1. station recording folders -----------------------------------------------------------

STATION_DOC = {"format": "thermocal-station", "version": 1}
SLOPE = {"a": 0.5, "b": -1.0}  # deg/h per °C


def _station(
    root: Path, *, doc: Any = None, second: Any = None, ids: tuple[str, ...] = ("a", "b")
) -> Path:
    """A recording folder as the recorder lays it out: ``station.json`` and two closed parts
    per sensor (2 h at 1 Hz, ``time_s``, ``gx_deg_h``, ``temp_c``).  ``doc`` replaces the
    station file (a string is written as it is); ``second(columns)`` changes the second
    part's columns."""
    d = root / "rec"
    d.mkdir()
    if doc is None:
        doc = {**STATION_DOC, "config": {"sensors": [{"id": i} for i in ids]}}
    (d / "station.json").write_text(doc if isinstance(doc, str) else json.dumps(doc))
    t = np.arange(0.0, 7200.0, 1.0)
    temp = 25.0 + 20.0 * np.sin(2 * np.pi * t / 7200.0)
    for sid in ids:
        g = 10.0 + SLOPE.get(sid, 0.0) * (temp - 25.0)
        for i, sl in enumerate((slice(0, 3600), slice(3600, None))):
            cols: dict[str, Any] = {"time_s": t[sl], "gx_deg_h": g[sl], "temp_c": temp[sl]}
            if second is not None and i == 1:
                cols = second(cols)
            table = pa.table(cols).replace_schema_metadata(
                {META_KEY: json.dumps({"time": "time_s"})}
            )
            pq.write_table(table, d / f"{sid}-{i:04d}.parquet")
    return d


def _listing(d: Path) -> dict[str, bytes]:
    return {str(p.relative_to(d)): p.read_bytes() for p in sorted(d.rglob("*")) if p.is_file()}


@pytest.mark.parametrize(
    "sid", ["..", "../rec", "/etc", "", "a/../b", "station.json", "a-0000.parquet"]
)
def test_station_sensor_id_path_tricks_name_no_sensor(tmp_path: Path, sid: str) -> None:
    d = _station(tmp_path)
    _refused(["inspect", str(d), "--sensor", sid], f"no sensor {sid!r}", "sensors: a, b")


def test_station_parts_with_other_columns_are_refused_naming_the_part(tmp_path: Path) -> None:
    """Seen red before the fix: pyarrow's ArrowInvalid, exit 1."""

    def renamed(c: dict[str, Any]) -> dict[str, Any]:
        return {"time_s": c["time_s"], "gy": c["gx_deg_h"], "temp_c": c["temp_c"]}

    d = _station(tmp_path, second=renamed)
    for cmd in (
        ["inspect", str(d)],
        ["metrics", str(d), "--signal", "gx_deg_h", "--temps", "temp_c"],
    ):
        _refused([*cmd, "--sensor", "a"], "a-0001.parquet", "differ from the first part's")


def test_station_part_stored_as_float32_is_widened(tmp_path: Path) -> None:
    """A part written float32 beside a float64 one is one recording (seen red before the
    fix: ArrowInvalid, exit 1); the slope of sensor a, 0.5 deg/h/°C, is recovered."""

    def single(c: dict[str, Any]) -> dict[str, Any]:
        return {**c, "gx_deg_h": c["gx_deg_h"].astype(np.float32)}

    d = _station(tmp_path, second=single)
    code, out, err = _run(["inspect", str(d), "--sensor", "a", "--json"])
    assert code == 0, err
    assert json.loads(out)["n_samples"] == 7200
    model, comp = tmp_path / "m.json", tmp_path / "c.parquet"
    argv = ["fit", str(d), "--sensor", "a", "--signal", "gx_deg_h", "--signal-unit", "deg/h",
            "--temps", "temp_c", "--model", "poly", "--order", "1", "-o", str(model)]  # fmt: skip
    code, _o, err = _run(argv)
    assert code == 0, err
    code, _o, err = _run(["compensate", str(model), str(d), "--sensor", "a", "-o", str(comp)])
    assert code == 0, err
    out = pq.read_table(comp).to_pandas()
    assert len(out) == 7200
    # the data are 10 + 0.5 (T − 25) exactly (float32 rounding in half of them: < 1e-5):
    # the line fitted and removed leaves a constant within that rounding
    assert np.ptp(out["gx_deg_h_comp"].to_numpy()) < 1e-4


def test_station_part_that_is_not_parquet(tmp_path: Path) -> None:
    d = _station(tmp_path)
    (d / "a-0001.parquet").write_text("time_s,gx_deg_h\n1,2\n")
    _refused(["inspect", str(d), "--sensor", "a"], "a-0001.parquet", "not a readable Parquet part")


@pytest.mark.parametrize(
    ("doc", "words"),
    [
        ("{nope", ("station.json", "not valid JSON")),
        ({**STATION_DOC, "version": "x", "config": {"sensors": [{"id": "a"}]}}, ("'version'",)),
        ({**STATION_DOC, "version": None, "config": {"sensors": [{"id": "a"}]}}, ("'version'",)),
        ({**STATION_DOC, "config": {"sensors": "ab"}}, ("config.sensors",)),
        ({**STATION_DOC, "config": [1]}, ("config.sensors",)),
        ({**STATION_DOC, "config": {"sensors": [{"x": 1}]}}, ("sensor id None",)),
        ({**STATION_DOC, "config": {"sensors": [{"id": "../x"}, {"id": "a"}]}}, ("'../x'",)),
        (
            {**STATION_DOC, "config": {"sensors": [{"id": "/etc/passwd"}, {"id": "a"}]}},
            ("'/etc/passwd'",),
        ),
        ({**STATION_DOC, "config": {"sensors": [{"id": "chamber"}, {"id": "a"}]}}, ("'chamber'",)),
    ],
)
def test_station_json_malformed_is_refused(
    tmp_path: Path, doc: Any, words: tuple[str, ...]
) -> None:
    """Seen red before the fix for every case but the first: TypeError, KeyError,
    AttributeError, ValueError (exit 1), or an id with ``/`` accepted and joined to the
    folder's path."""
    d = _station(tmp_path, doc=doc, ids=("a",))
    _refused(["inspect", str(d), "--sensor", "a"], "station.json", *words)


def test_station_json_listing_no_sensor(tmp_path: Path) -> None:
    d = _station(tmp_path, doc={**STATION_DOC, "config": {}}, ids=("a",))
    _refused(["inspect", str(d)], "0 sensors")
    _refused(["inspect", str(d), "--sensor", "a"], "no sensor 'a'")


def test_station_part_with_corrupt_metadata(tmp_path: Path) -> None:
    """Seen red before the fix: JSONDecodeError, exit 1."""
    d = _station(tmp_path, ids=("a",))
    p = d / "a-0001.parquet"
    pq.write_table(pq.read_table(p).replace_schema_metadata({META_KEY: "{bad"}), p)
    _refused(["inspect", str(d)], "a-0001.parquet", "corrupt thermocal metadata")


def test_outputs_into_a_station_folder_through_a_link_or_dotdot(tmp_path: Path) -> None:
    d = _station(tmp_path)
    model = tmp_path / "m.json"
    fit = ["fit", str(d), "--sensor", "a", "--signal", "gx_deg_h", "--signal-unit", "deg/h",
           "--temps", "temp_c", "--model", "poly"]  # fmt: skip
    code, _o, err = _run([*fit, "-o", str(model)])
    assert code == 0, err
    os.symlink(d, tmp_path / "link")
    before = _listing(d)
    for out in (tmp_path / "link" / "x.parquet", d / ".." / "rec" / "x.parquet",
                d / "sub" / "x.parquet", d / "b", d / "chamber-0000.parquet"):  # fmt: skip
        argv = ["compensate", str(model), str(d), "--sensor", "b", "-o", str(out)]
        _refused(argv, "inside the input station recording")
    # the input given through the link, the output named directly
    argv = ["compensate", str(model), str(tmp_path / "link"), "--sensor", "b"]
    _refused([*argv, "-o", str(d / "y.parquet")], "inside the input station recording")
    _refused([*fit, "-o", str(tmp_path / "link" / "m.json")], "inside the input station recording")
    argv = ["report", "--model", str(model), "--recording", str(d), "--sensor", "b"]
    _refused([*argv, "-o", str(tmp_path / "link" / "r.html")], "inside the input station")
    assert _listing(d) == before


def test_fleet_reads_a_station_sensor_and_asks_for_one(tmp_path: Path) -> None:
    _station(tmp_path)
    head = ('[fit]\nmodel = "poly"\norder = 1\nsignal = ["gx_deg_h"]\nsignal_unit = "deg/h"\n'
            'temps = "temp_c"\n')  # fmt: skip
    (tmp_path / "ok.toml").write_text(
        head + 'sensor = "b"\n\n[[unit]]\nid = "U1"\nmodeling = ["rec"]\n'
    )
    code, _o, err = _run(["fleet", str(tmp_path / "ok.toml"), "-o", str(tmp_path / "f1")])
    assert code == 0, err
    (tmp_path / "amb.toml").write_text(head + '\n[[unit]]\nid = "U1"\nmodeling = ["rec"]\n')
    code, _o, err = _run(["fleet", str(tmp_path / "amb.toml"), "-o", str(tmp_path / "f2")])
    assert code != 0 and "--sensor ID" in err and "Traceback" not in err, err


# --- 2. [chamber] preset and the set-point register ----------------------------------------

STATION_SENSOR = sensor_toml("/dev/null", stale_s=None)


def _station_toml(tmp: Path, chamber: str) -> Path:
    """A station whose chamber is a Modbus TCP controller at port 1 of this machine (nothing
    listens there: a run that got as far as the chamber would fail to connect)."""
    p = tmp / "STATION.toml"
    head = '[chamber]\ndriver = "modbus-tcp"\nhost = "127.0.0.1"\nport = 1\nio_timeout_s = 0.2\n'
    p.write_text(head + chamber + "\n" + STATION_SENSOR, encoding="utf-8")
    return p


def _program(tmp: Path) -> Path:
    p = tmp / "prog.csv"
    p.write_text("time_s,setpoint_c\n0,25\n600,60\n1200,-20\n", encoding="utf-8")
    return p


@pytest.mark.parametrize(
    ("chamber", "words"),
    [
        ("preset = 5\nscale = 0.1", ("preset must be str",)),
        ('preset = ["eurotherm-2000"]\nscale = 0.1', ("preset must be str",)),
        ('preset = ""\nscale = 0.1', ("unknown preset ''", "eurotherm-2000")),
        ('preset = "eurotherm-2000"', ("needs scale",)),
        ('preset = "eurotherm-2000"\nscale = "0.1"', ("scale must be float",)),
        ('preset = "eurotherm-2000"\nscale = 0', ("scale must be > 0",)),
        ('preset = "eurotherm-2000"\nscale = -0.1', ("scale must be > 0",)),
        ('preset = "eurotherm-2000"\nscale = nan', ("scale must be finite",)),
        ('preset = "eurotherm-2000"\nscale = 0.1\nsetpoint_register = 2', ("disagrees",)),
        ('preset = "eurotherm-2000"\nscale = 0.1\nsigned = false', ("disagrees",)),
        ('preset = "eurotherm-2000"\nscale = 0.1\nregister_kind = "input"', ("disagrees",)),
    ],
)
def test_preset_wrong_types_and_conflicts(
    tmp_path: Path, chamber: str, words: tuple[str, ...]
) -> None:
    toml = _station_toml(tmp_path, chamber)
    argv = ["station", "run", str(toml), "--profile", str(_program(tmp_path))]
    _refused([*argv, "-o", str(tmp_path / "out")], "[chamber]", *words)
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize(
    ("scale", "words"),
    [
        ("5e-324", ("does not fit a signed 16-bit register",)),  # was OverflowError, exit 1
        ("0.001", ("set-point 60 °C does not fit",)),  # ±32.767 °C: 60 and −20 do not fit
        ("100", ("would be written as 0 °C",)),  # 25 °C rounds to 0 counts: 0 °C written
        ("1e300", ("would be written as 0 °C",)),
    ],
)
def test_preset_scale_that_cannot_hold_the_program(
    tmp_path: Path, scale: str, words: tuple[str, ...]
) -> None:
    """Every set-point of the program (and the safe one) is checked before anything is
    written or the chamber is contacted.  Seen red before the fix: scale 5e-324 raised
    OverflowError (exit 1); scales 100 and 1e300 passed the check (25 °C → 0 counts, 60 °C
    → 1 count = 100 °C) and the run went on to the chamber, creating the folder."""
    toml = _station_toml(tmp_path, f'preset = "eurotherm-2000"\nscale = {scale}')
    argv = ["station", "run", str(toml), "--profile", str(_program(tmp_path))]
    _refused([*argv, "-o", str(tmp_path / "out")], *words)
    assert not (tmp_path / "out").exists()


def test_register_encoding_refuses_instead_of_wrapping() -> None:
    """The 16-bit boundaries written out: signed at 0.1 °C/count holds −3276.8…3276.7 °C
    (−3276.8 is 0x8000), unsigned 0…6553.5 °C; one count beyond is refused, not wrapped; a
    set-point that is not a number is refused (seen red: ValueError/OverflowError)."""
    from thermocal.errors import ThermocalInputError
    from thermocal.station.chamber import RegisterMap

    signed = RegisterMap(24, 1, "holding", 0.1, True)
    unsigned = RegisterMap(24, 1, "holding", 0.1, False)
    assert signed.encode(3276.7) == 32767
    assert signed.encode(-3276.8) == 0x8000
    assert signed.decode(0x8000) == pytest.approx(-3276.8)
    assert unsigned.encode(6553.5) == 65535
    for m, v in ((signed, 3276.8), (signed, -3276.9), (unsigned, -0.1), (unsigned, 6553.6)):
        with pytest.raises(ThermocalInputError, match="does not fit"):
            m.encode(v)
    for v in (float("nan"), float("inf"), -float("inf")):
        with pytest.raises(ThermocalInputError, match="does not fit"):
            signed.encode(v)


# --- 3. calibrations with a triad count scale (format version 2) -----------------------------


@pytest.fixture(scope="module")
def counts_cal(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A multipos calibration made on raw counts (the session of test_multipos_rawcomp:
    ``imu_raw.csv`` int16 counts, ``imu_mg.csv`` the same in mg and deg/s, ``cal.json``
    with ``count_scale`` 1000/8192 mg and 1/16.4 deg/s)."""
    from test_multipos_rawcomp import session

    made: dict[str, Any] = session.__wrapped__(tmp_path_factory)  # type: ignore[attr-defined]
    folder: Path = made["dir"]
    return folder


def _tampered(src: Path, dst: Path, change: Any, *, resum: bool = True) -> Path:
    """``src`` changed by ``change(doc)``, its checksum recomputed (a deliberate edit) unless
    ``resum`` is False (a file edited by hand)."""
    from thermocal.models.format import checksum

    doc = json.loads(src.read_text())
    change(doc)
    if resum:
        del doc["checksum"]
        doc["checksum"] = checksum(doc)
    dst.write_text(json.dumps(doc), encoding="utf-8")
    return dst


def _scale(**kw: Any) -> Any:
    return lambda doc: doc["triads"][0]["count_scale"].update(**kw)


@pytest.mark.parametrize(
    ("change", "words"),
    [
        (_scale(value=0), ("count_scale", "a positive number")),
        (_scale(value=-0.1), ("count_scale", "a positive number")),
        (_scale(value="0.12"), ("count_scale", "a positive number")),
        (_scale(unit="g"), ("count_scale", "'mg'")),
        (lambda doc: doc["triads"][0].update(count_scale=0.12), ("count_scale",)),
        # seen red before the fix: a version-1 file with a count scale was applied (a
        # thermocal of version 1 would have ignored the scale and corrected raw counts)
        (lambda doc: doc.update(format_version=1), ("count_scale", "format_version 2")),
    ],
)
def test_tampered_count_scale_is_refused_by_every_reader(
    counts_cal: Path, tmp_path: Path, change: Any, words: tuple[str, ...]
) -> None:
    cal = _tampered(counts_cal / "cal.json", tmp_path / "cal.json", change)
    raw = str(counts_cal / "imu_raw.csv")
    out = tmp_path / "o.csv"
    _refused(["compensate", str(cal), raw, "-o", str(out), "--time-unit", "s"], *words)
    _refused(["export-c", str(cal), "-o", str(tmp_path / "c")], *words)
    argv = ["export-params", str(cal), "--format", "ardupilot", "-o", str(tmp_path / "ap.parm")]
    _refused(argv, *words)
    assert not out.exists() and not (tmp_path / "c").exists()


def test_count_scale_nan_or_checksum_edited_by_hand(counts_cal: Path, tmp_path: Path) -> None:
    raw = str(counts_cal / "imu_raw.csv")
    cal = _tampered(counts_cal / "cal.json", tmp_path / "a.json", _scale(value=0.5), resum=False)
    _refused(["compensate", str(cal), raw, "-o", str(tmp_path / "o.csv")], "checksum mismatch")
    cal = _tampered(
        counts_cal / "cal.json", tmp_path / "b.json", _scale(value=float("nan")), resum=False
    )
    _refused(["export-c", str(cal), "-o", str(tmp_path / "c")], "count_scale")


def test_count_scale_overflowing_the_counts_is_one_error_line(
    counts_cal: Path, tmp_path: Path
) -> None:
    """A count scale of 1e308 mg turns the counts into ±inf: refused naming the column, in
    one line (seen red: numpy's RuntimeWarning printed as a second ``warning:`` line)."""
    cal = _tampered(counts_cal / "cal.json", tmp_path / "cal.json", _scale(value=1e308))
    argv = ["compensate", str(cal), str(counts_cal / "imu_raw.csv"), "-o", str(tmp_path / "o.csv")]
    code, _o, err = _run([*argv, "--time-unit", "s"])
    assert code == 2 and err.strip().splitlines() == [err.strip()], err
    assert "signal column 'ax'" in err and "beyond any sensor" in err


def test_columns_of_a_triad_in_conflicting_units(counts_cal: Path, tmp_path: Path) -> None:
    cal, raw = str(counts_cal / "cal.json"), str(counts_cal / "imu_raw.csv")
    argv = ["compensate", cal, raw, "-o", str(tmp_path / "o.csv"), "--time-unit", "s"]
    _refused(
        [*argv, "--signal-unit", "counts,mg,counts,counts,counts,counts"], "accel", "differ in unit"
    )
    mg = str(counts_cal / "imu_mg.csv")
    argv = ["compensate", cal, mg, "-o", str(tmp_path / "p.csv"), "--time-unit", "s"]
    _refused([*argv, "--signal-unit", "deg/s,deg/s,deg/s,deg/s,deg/s,deg/s"], "accel", "deg/s")


def test_export_c_of_a_hostile_triad_name_compiles(counts_cal: Path, tmp_path: Path) -> None:
    """A triad name holding ``*/``, a newline and an ``#include`` reaches the generated C
    only sanitised: the header and source compile, no line is the injected directive."""
    import shutil

    evil = 'acc el*/\n#include "nowhere.h"\n/*'
    cal = _tampered(counts_cal / "cal.json", tmp_path / "cal.json",
                    lambda doc: doc["triads"][0].update(name=evil))  # fmt: skip
    code, _o, err = _run(["export-c", str(cal), "-o", str(tmp_path / "c")])
    assert code == 0, err
    files = sorted((tmp_path / "c").iterdir())
    for f in files:
        assert not any(
            ln.strip().startswith('#include "nowhere') for ln in f.read_text().splitlines()
        )
    cc = shutil.which("cc")
    if cc is None:
        pytest.skip("no C compiler")
    import subprocess

    for f in files:
        if f.suffix == ".c":
            r = subprocess.run([cc, "-std=c99", "-Wall", "-Werror", "-c", str(f), "-o",
                                str(tmp_path / "x.o")], capture_output=True, text=True)  # fmt: skip
            assert r.returncode == 0, r.stderr


# --- 4. report --dynamic W -------------------------------------------------------------------


@pytest.fixture(scope="module")
def dyn_work(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """test_report_dynamic's records: 20 000 s at 1 Hz, a linear model fitted on one."""
    from test_report_dynamic import work

    made: Path = work.__wrapped__(tmp_path_factory)  # type: ignore[attr-defined]
    return made


DYN = ["--signal", "gyro [deg/h]", "--time", "time [s]"]


@pytest.mark.parametrize(
    ("window", "words"),
    [
        ("nan", ("--dynamic", "> 0")),
        ("inf", ("--dynamic", "> 0")),
        ("-5", ("--dynamic", "> 0")),
        ("0", ("--dynamic", "> 0")),
        ("1e300", ("fewer than two windows",)),
        ("10001", ("fewer than two windows",)),
        ("0.5", ("holds 0 samples",)),
        ("2000s", ("--dynamic",)),
        ("", ("--dynamic",)),
    ],
)
def test_report_dynamic_window_that_is_no_length(
    dyn_work: Path, window: str, words: tuple[str, ...]
) -> None:
    out = dyn_work / "r.html"
    argv = [
        "report",
        "--model",
        str(dyn_work / "lin.json"),
        "--recording",
        str(dyn_work / "steady.csv"),
    ]
    _refused([*argv, *DYN, "-o", str(out), "--dynamic", window], *words)
    assert not out.exists()


def test_report_dynamic_on_a_record_with_a_gap(dyn_work: Path) -> None:
    """4000 s cut out of the steady record: the report is written, the gap said; the map's
    window is the one asked for, and a stationary output draws no warning."""
    df = pd.read_csv(dyn_work / "steady.csv").drop(index=range(5000, 9000))
    df.to_csv(dyn_work / "gap.csv", index=False)
    out = dyn_work / "rg.html"
    argv = [
        "report",
        "--model",
        str(dyn_work / "lin.json"),
        "--recording",
        str(dyn_work / "gap.csv"),
    ]
    code, _o, err = _run([*argv, *DYN, "-o", str(out), "--dynamic", "2000"])
    assert code == 0, err
    assert "gaps in time" in err and "not stationary" not in err, err
    html = out.read_text()
    assert 'data-key="dynamic.window_s" data-value="2000.0"' in html


# --- 5. output quantisation found from the samples -------------------------------------------


def _lattice(v: np.ndarray) -> Any:
    from thermocal.stability.noise_model import lattice_step

    return lattice_step(v)


def test_quantisation_no_claim_on_records_that_show_no_lattice() -> None:
    rng = np.random.default_rng(8)
    n = 20_000
    assert _lattice(np.full(n, 3.3)) is None  # constant
    assert _lattice(np.where(rng.random(n) < 0.5, 0.0, 0.05)) is None  # two levels
    assert _lattice(np.round(rng.normal(0, 1, 10) / 0.05) * 0.05) is None  # 10 samples
    assert _lattice(rng.normal(0.0, 1.0, n)) is None  # ordinary floating point
    assert _lattice(rng.normal(0.0, 1.0, n) * 1e300) is None


def test_quantisation_ignores_nan_and_inf_and_finds_the_step() -> None:
    rng = np.random.default_rng(9)
    k = np.round(rng.normal(0.0, 1.0, 20_000) / 0.05)
    v = np.r_[k * 0.05, np.nan, np.inf, -np.inf]
    step, offset, levels, n = _lattice(v)
    assert step == pytest.approx(0.05, rel=1e-9)
    assert offset == pytest.approx(k.min() * 0.05)
    assert levels == np.unique(k).size and n == 20_000


def test_quantisation_integers_at_1e15_lie_on_a_step_of_one() -> None:
    """1e15 + 0…9: integers, exactly representable (float64 spacing there is 0.125): the
    lattice is real, its step 1 and its 10 levels."""
    rng = np.random.default_rng(10)
    found = _lattice(1e15 + rng.integers(0, 10, 20_000).astype(np.float64))
    assert found is not None and found[0] == 1.0 and found[2] == 10


def test_quantisation_not_claimed_for_the_storage_precision() -> None:
    """Seen red before the fix: a float64 record at 1e15 lies on float64's own 0.125
    spacing, and a float32 record (a ULog field, a float32 Parquet column) on float32's —
    the storage's rounding, reported as the sensor's output quantisation."""
    rng = np.random.default_rng(11)
    n = 20_000
    assert _lattice(1e15 + rng.normal(0.0, 1.0, n)) is None
    assert _lattice((9.8 + rng.normal(0.0, 1e-5, n)).astype(np.float32).astype(np.float64)) is None
    # a real step stored as float32 is still found (0.05 deg/s, float32-rounded)
    k = np.round(rng.normal(0.0, 1.0, n) / 0.05)
    found = _lattice((k * 0.05).astype(np.float32).astype(np.float64))
    assert found is not None and found[0] == pytest.approx(0.05, rel=1e-6)


def test_allan_on_a_float32_accelerometer_claims_no_quantisation(tmp_path: Path) -> None:
    """A still accelerometer at 9.8 m/s² (0.01 mg noise) stored float32 in Parquet, 100 Hz:
    allan's JSON gives no output quantisation (seen red before the fix: a
    9.5e-7 m/s² "rate quantization step")."""
    rng = np.random.default_rng(12)
    n = 20_000
    t = np.arange(n) * 0.01
    cols = {"time [s]": t}
    for name, g in (("ax", 0.0), ("ay", 0.0), ("az", 9.8)):
        cols[name] = (g + rng.normal(0.0, 1e-4, n)).astype(np.float32)
    pd.DataFrame(cols).to_parquet(tmp_path / "acc.parquet")
    argv = ["allan", str(tmp_path / "acc.parquet"), "--signal", "az", "--signal-unit", "m/s^2"]
    code, out, err = _run([*argv, "--time", "time [s]", "--json"])
    assert code == 0, err
    assert json.loads(out)["output_quantization"] is None


# --- 6. ardupilot-tempcal with PARM changes mid-log ------------------------------------------


def _ap_log(
    m: dict[str, np.ndarray], before: Any, *, initial: Any = None, data: Any = None
) -> bytes:
    """A DataFlash log of IMU 0 (``m`` from test_fc_log_readers.imu_truth): the initial PARM
    values (default AHRS_ORIENTATION 10, INS_TCAL1_ENABLE 1 and test_ardupilot_param_changes'
    SET_A), ``before(i)`` PARM messages written before sample ``i``; ``data`` (gyro, accel)
    replaces the measured vectors."""
    from dataflash_writer import NEW_IMU_FMT, NEW_IMU_LABELS, PARM_FORMAT, dataflash_log, parm
    from test_ardupilot_param_changes import SET_A, set_parms

    g, a = data if data is not None else (m["gyro_meas"], m["accel_meas"])
    if initial is None:
        initial = [
            parm("AHRS_ORIENTATION", 10),
            parm("INS_TCAL1_ENABLE", 1),
            *set_parms(SET_A, 1000),
        ]
    msgs = list(initial)
    for i in range(m["temp"].size):
        msgs += before(i)
        msgs.append((100, (int(m["time_us"][i]), 0, *g[i], *a[i], 0, 0, float(m["temp"][i]),
                           1, 1, 1000, 1000)))  # fmt: skip
    return dataflash_log([PARM_FORMAT, (100, "IMU", NEW_IMU_FMT, NEW_IMU_LABELS)], msgs)


def _ap(log: Path, out: Path) -> tuple[int, dict[str, Any], str]:
    code, o, err = _run(["ardupilot-tempcal", str(log), "-o", str(out), "--json"])
    return code, (json.loads(o) if code == 0 else {}), err


def test_ardupilot_parameter_set_at_every_sample(tmp_path: Path) -> None:
    """INS_TCAL1_GYR1_X set again at every one of 6000 samples: every change is in
    log_hygiene.parameter_changes, the note names the first 50 and counts the rest (seen
    red: a note of every change, 270 000 characters), and the run is linear in the changes
    (the changes were merged with a list search and each interval selected with a mask
    over the whole log: O(n²))."""
    from dataflash_writer import parm
    from test_fc_log_readers import imu_truth

    m = imu_truth(6000, 11, 1.0)
    tu = m["time_us"]
    log = tmp_path / "every.bin"
    log.write_bytes(_ap_log(m, lambda i: [parm("INS_TCAL1_GYR1_X", float(i % 7), int(tu[i]))]))
    code, res, err = _ap(log, tmp_path / "out")
    assert code == 0, err
    changes = res["log_hygiene"]["parameter_changes"]
    # sample 0 sets 0 (was 60), then 1, 2, …: one change per sample
    assert len(changes) == 6000
    assert changes[1] == {"time_s": pytest.approx(tu[1] * 1e-6), "name": "INS_TCAL1_GYR1_X",
                          "old": 0.0, "new": 1.0}  # fmt: skip
    note = next(n for n in res["notes"] if "changed during the recording" in n)
    assert len(note) < 5000 and "5950 more" in note, len(note)


@pytest.mark.parametrize(
    ("value", "words"),
    [
        (999, ("AHRS_ORIENTATION 999", "not implemented")),
        (-1, ("AHRS_ORIENTATION -1",)),
        (2.5, ("AHRS_ORIENTATION 2.5", "not a rotation code")),  # seen red: int(2.5) = YAW_90
    ],
)
def test_ardupilot_orientation_set_mid_log_to_no_rotation(
    tmp_path: Path, value: float, words: tuple[str, ...]
) -> None:
    from dataflash_writer import parm
    from test_fc_log_readers import imu_truth

    m = imu_truth(3000, 11, 1.0)
    t_mid = int(m["time_us"][1500])
    log = tmp_path / "o.bin"
    log.write_bytes(
        _ap_log(m, lambda i: [parm("AHRS_ORIENTATION", value, t_mid)] if i == 1500 else [])
    )
    _refused(["ardupilot-tempcal", str(log), "-o", str(tmp_path / "out")], *words)


def test_ardupilot_coefficient_set_to_nan_mid_log(tmp_path: Path) -> None:
    """Seen red: refused as "column 'x' has 1500 NaN values", naming no parameter."""
    from dataflash_writer import parm
    from test_fc_log_readers import imu_truth

    m = imu_truth(3000, 11, 1.0)
    t_mid = int(m["time_us"][1500])
    log = tmp_path / "n.bin"
    log.write_bytes(
        _ap_log(m, lambda i: [parm("INS_TCAL1_GYR1_X", float("nan"), t_mid)] if i == 1500 else [])
    )
    _refused(["ardupilot-tempcal", str(log), "-o", str(tmp_path / "out")], "INS_TCAL1_GYR1_X",
             f"{t_mid * 1e-6:.3f} s")  # fmt: skip


def test_ardupilot_change_before_the_first_sample_is_the_initial_value(tmp_path: Path) -> None:
    """SET_B set 0.5 ms before the first IMU sample is, for every sample, what SET_B as the
    log's initial values is: the same data give the same parameter file, value for value."""
    from dataflash_writer import parm
    from test_ardupilot_param_changes import SET_B, corrected, set_parms
    from test_fc_log_readers import imu_truth

    m = imu_truth(12000, 13, 1.0)
    temp32 = m["temp"].astype(np.float32).astype(np.float64)
    data = (corrected(m["gyro_meas"], temp32, "GYR", SET_B),
            corrected(m["accel_meas"], temp32, "ACC", SET_B))  # fmt: skip
    t_before = int(m["time_us"][0]) - 500
    changed = tmp_path / "changed.bin"
    changed.write_bytes(
        _ap_log(m, lambda i: set_parms(SET_B, t_before) if i == 0 else [], data=data)
    )
    first = tmp_path / "first.bin"
    initial = [parm("AHRS_ORIENTATION", 10), parm("INS_TCAL1_ENABLE", 1), *set_parms(SET_B, 1000)]
    first.write_bytes(_ap_log(m, lambda i: [], initial=initial, data=data))
    code, res, err = _ap(changed, tmp_path / "c")
    assert code == 0, err
    assert res["log_hygiene"]["parameter_changes"][0]["time_s"] == pytest.approx(t_before * 1e-6)
    code, _r, err = _ap(first, tmp_path / "f")
    assert code == 0, err
    assert (tmp_path / "c" / "ardupilot.parm").read_text() == (
        tmp_path / "f" / "ardupilot.parm"
    ).read_text()


def test_validate_on_a_station_folder_reads_the_named_sensor(tmp_path: Path) -> None:
    """Sensor a's model (slope +0.5) validated on sensor b (slope −1.0) leaves 1.5 deg/h/°C ×
    the temperature's excursion: the residual's rms is 1.5 × 20/√2 deg/h (a sine of
    amplitude 20 °C over whole periods), computed here; on sensor a it is ≈ 0."""
    d = _station(tmp_path)
    model = tmp_path / "m.json"
    argv = ["fit", str(d), "--sensor", "a", "--signal", "gx_deg_h", "--signal-unit", "deg/h",
            "--temps", "temp_c", "--model", "poly", "--order", "1", "-o", str(model)]  # fmt: skip
    code, _o, err = _run(argv)
    assert code == 0, err
    _refused(["validate", str(model), str(d)], "--sensor ID")
    _refused(["validate", str(model), str(d), "--sensor", "../rec"], "no sensor '../rec'")
    rms = {}
    for sid in ("a", "b"):
        code, out, err = _run(["validate", str(model), str(d), "--sensor", sid, "--json"])
        assert code == 0, err
        rms[sid] = json.loads(out)["rms_after"]
    assert rms["a"] < 1e-6
    assert rms["b"] == pytest.approx(1.5 * 20.0 / np.sqrt(2.0), rel=1e-3)
