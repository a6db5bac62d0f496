"""``--sensor ID`` on the commands that read a recording (issue 31; INTERFACE.md, test
station: "every command reads DIR as one recording (--sensor ID when there are several)").

The station folder is built here by hand the way the recorder lays it out (``station.json``,
closed parts ``ID-NNNN.parquet`` with the thermocal metadata), two sensors with opposite
thermal slopes, so reading the wrong sensor cannot pass unseen."""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from thermocal.cli import main
from thermocal.recording import META_KEY

NOISE_DEG_H = 0.5
SLOPES = {"a": 0.5, "b": -1.0}  # deg/h per °C


def _station(tmp: Path) -> Path:
    d = tmp / "rec"
    d.mkdir()
    doc = {
        "format": "thermocal-station",
        "version": 1,
        "config": {"sensors": [{"id": "a"}, {"id": "b"}]},
    }
    (d / "station.json").write_text(json.dumps(doc), encoding="utf-8")
    rng = np.random.default_rng(7)
    t = np.arange(0.0, 4 * 3600.0, 1.0)
    temp = 25 + 35 * np.sin(2 * np.pi * t / 7200)
    for sid, slope in SLOPES.items():
        g = 10 + slope * (temp - 25) + rng.normal(0, NOISE_DEG_H, t.size)
        for i, sl in enumerate((slice(0, 7200), slice(7200, None))):
            table = pa.table({"time_s": t[sl], "gx_deg_h": g[sl], "temp_c": temp[sl]})
            meta = {"time": "time_s", "sensor_id": sid}
            table = table.replace_schema_metadata({META_KEY: json.dumps(meta)})
            pq.write_table(table, d / f"{sid}-{i:04d}.parquet")
    return d


def _listing(d: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in sorted(d.iterdir())}


def test_inspect_names_the_sensor_or_asks_for_one(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    d = _station(tmp_path)
    assert main(["inspect", str(d)]) == 2
    assert "--sensor ID" in capsys.readouterr().err
    assert main(["inspect", str(d), "--sensor", "b", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["n_samples"] == 4 * 3600
    assert main(["inspect", str(d), "--sensor", "zz"]) == 2
    assert "no sensor 'zz'" in capsys.readouterr().err
    assert main(["inspect", str(d / "a"), "--sensor", "b"]) == 2
    assert "'a'" in capsys.readouterr().err
    csv = tmp_path / "x.csv"
    csv.write_text("time_s,gx_deg_h,temp_c\n0,1,20\n1,1,20\n2,1,20\n")
    assert main(["inspect", str(csv), "--sensor", "a"]) == 2
    assert "station recordings" in capsys.readouterr().err


def test_fit_and_compensate_read_the_named_sensor(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    d = _station(tmp_path)
    before = _listing(d)
    model = tmp_path / "m.json"
    argv = ["fit", str(d), "--sensor", "b", "--signal", "gx_deg_h", "--temps", "temp_c"]
    assert main([*argv, "--model", "poly", "-o", str(model)]) == 0
    capsys.readouterr()
    (prov,) = json.loads(model.read_text())["data"]
    assert Path(prov["path"]) == d / "b" and prov["n_samples"] == 4 * 3600
    h = hashlib.sha256()  # the provenance hashes sensor b's closed parts, in order
    for name in ("b-0000.parquet", "b-0001.parquet"):
        h.update((d / name).read_bytes())
    assert prov["sha256"] == h.hexdigest()

    out = tmp_path / "c.parquet"
    argv = ["compensate", str(model), str(d), "--sensor", "b", "-o", str(out)]
    assert main([*argv, "--chunk-rows", "5000"]) == 0  # chunks straddle the two parts
    capsys.readouterr()
    table = pq.read_table(out).to_pandas()
    assert len(table) == 4 * 3600
    # the named sensor's slope removed: the residual is the simulated white noise; sensor
    # a's data (slope +0.5) under b's model would leave 1.5 deg/h/°C × 25 °C rms
    assert np.std(table["gx_deg_h_comp"]) == pytest.approx(NOISE_DEG_H, rel=0.05)
    same = tmp_path / "c2.parquet"
    assert main(["compensate", str(model), str(d / "b"), "-o", str(same)]) == 0
    np.testing.assert_array_equal(
        pq.read_table(same)["gx_deg_h_comp"].to_numpy(), table["gx_deg_h_comp"].to_numpy()
    )
    capsys.readouterr()
    inside = d / "b-0002.parquet"  # would become a part of the recording
    assert main(["compensate", str(model), str(d), "--sensor", "b", "-o", str(inside)]) == 2
    assert "inside the input station recording" in capsys.readouterr().err
    assert _listing(d) == before


def test_report_sensor_labels_and_picks_the_station_sensor(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``report`` has its own ``--sensor`` (the report's label): on a station folder of
    several sensors it also picks the sensor read."""
    d = _station(tmp_path)
    model = tmp_path / "m.json"
    argv = ["fit", str(d / "b"), "--signal", "gx_deg_h", "--temps", "temp_c", "--model", "poly"]
    assert main([*argv, "-o", str(model)]) == 0
    out = tmp_path / "r.html"
    argv = ["report", "--model", str(model), "--recording", str(d), "--sensor", "b"]
    assert main([*argv, "-o", str(out)]) == 0, capsys.readouterr().err
    capsys.readouterr()
    argv = ["report", "--model", str(model), "--recording", str(d)]
    assert main([*argv, "-o", str(tmp_path / "r1.html")]) == 2  # which of the two?
    assert "--sensor ID" in capsys.readouterr().err
    argv = ["report", "--model", str(model), "--recording", str(d), "--sensor", "zz"]
    assert main([*argv, "-o", str(tmp_path / "r2.html")]) == 2
    assert "no sensor 'zz'" in capsys.readouterr().err
