"""Hostile station recording folders (:mod:`thermocal.readers.station`), generated here and run
through the command line where a user meets them: path tricks in ``--sensor ID``, parts
with other columns, float32 parts, a part that is not Parquet, a malformed or empty
``station.json``, corrupt metadata, and ``validate`` reading the named sensor."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow.parquet as pq
import pytest

from station_folders import STATION_DOC
from station_folders import refused as _refused
from station_folders import run_cli as _run
from station_folders import station_folder as _station
from thermocal.recording import META_KEY


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
