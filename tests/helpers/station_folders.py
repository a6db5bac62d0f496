"""A station recording folder as ``thermocal station run`` lays it out, and the CLI helpers
the station-folder tests share (run a command, expect one ``error:`` line, list a folder)."""

from __future__ import annotations

import contextlib
import io
import json
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from thermocal.cli import main
from thermocal.recording import META_KEY


def run_cli(argv: list[str]) -> tuple[int, str, str]:
    o, e = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(o), contextlib.redirect_stderr(e):
        code = main(argv)
    return code, o.getvalue(), e.getvalue()


def refused(argv: list[str], *words: str) -> str:
    """Exit 2, exactly one ``error:`` line holding every word, no traceback."""
    code, _o, err = run_cli(argv)
    errors = [ln for ln in err.splitlines() if ln.startswith("error:")]
    assert code == 2, (code, err)
    assert len(errors) == 1 and "Traceback" not in err, err
    for w in words:
        assert w in errors[0], (w, errors[0])
    return errors[0]


STATION_DOC = {"format": "thermocal-station", "version": 1}


SLOPE = {"a": 0.5, "b": -1.0}  # deg/h per °C


def station_folder(
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


def listing(d: Path) -> dict[str, bytes]:
    return {str(p.relative_to(d)): p.read_bytes() for p in sorted(d.rglob("*")) if p.is_file()}
