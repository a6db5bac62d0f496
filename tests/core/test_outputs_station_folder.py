"""Outputs written into a station folder through a link or ``..`` (:mod:`thermocal.outputs`):
inputs are never overwritten."""

from __future__ import annotations

import os
from pathlib import Path

from station_folders import listing as _listing
from station_folders import refused as _refused
from station_folders import run_cli as _run
from station_folders import station_folder as _station


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
