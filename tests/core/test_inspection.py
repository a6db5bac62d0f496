"""``inspect_recording(rec, skipped)`` is what ``thermocal inspect --json`` prints: the
columns the reader skipped as non-numeric are warnings of the library's result, not added
by the command line."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from thermocal.cli import main
from thermocal.inspection import inspect_recording
from thermocal.pipeline.messages import jsonable
from thermocal.readers import read_recording
from thermocal.readers.options import ReadOptions


def test_skipped_columns_are_warnings_of_the_result(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    t = np.arange(200) * 0.1  # 10 Hz
    rows = [f"{ti:.1f},{np.sin(ti):.6f},{25 + 0.05 * ti:.3f},ok" for ti in t]
    path = tmp_path / "run.csv"
    path.write_text("time [s],gyro [deg/h],T1 [degC],note\n" + "\n".join(rows) + "\n")
    code = main(["inspect", str(path), "--json"])
    printed = json.loads(capsys.readouterr().out)
    assert code == 0

    skipped: list[str] = []
    rec = read_recording(path, ReadOptions(), skipped=skipped, guess_temperatures=True)
    ins = inspect_recording(rec, skipped)
    assert json.loads(json.dumps(jsonable(ins.to_dict()), allow_nan=False)) == printed
    assert skipped == ["note"]
    assert [(p.kind, p.column, p.severity) for p in ins.problems] == [
        ("non_numeric", "note", "warning")
    ]
    assert ins.n_samples == 200 and ins.sample_rate_hz == pytest.approx(10.0)
    assert inspect_recording(rec).problems == []  # nothing skipped: no warning
