"""``program_summary`` and ``CorrelationResult.to_dict()`` are what ``thermocal profile
NAME --json`` and ``profile correlate --json`` print; the program's numbers are the CSV's
as pandas reads it, and a mirrored history correlates with r = −1."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from thermocal.cli import main
from thermocal.profiles import builtin_profile, correlate, program_summary


def _json(capsys: pytest.CaptureFixture[str], *args: str) -> dict[str, object]:
    code = main(list(args))
    out = capsys.readouterr().out
    assert code == 0, out
    obj = json.loads(out)
    assert isinstance(obj, dict)
    return obj


def test_program_summary_is_the_cli_json(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "m.csv"
    printed = _json(capsys, "profile", "fog-slow", "-o", str(out), "--dt", "120", "--json")
    prof = builtin_profile("fog-slow")
    t, c = prof.program(120.0)
    d = program_summary(prof, t, c, str(out))
    assert d == printed
    written = pd.read_csv(out)
    assert d["n_points"] == len(written)
    assert d["duration_s"] == pytest.approx(written["time_s"].iloc[-1])
    assert d["min_c"] == written["setpoint_c"].min() and d["max_c"] == written["setpoint_c"].max()
    assert (d["min_c"], d["max_c"]) == (15.0, 42.0)  # the profile's stated range


def test_correlation_to_dict_is_the_cli_json(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    t, c = builtin_profile("fog-slow").program(60.0)
    a, b = tmp_path / "a.csv", tmp_path / "b.csv"
    pd.DataFrame({"time_s": t, "setpoint_c": c}).to_csv(a, index=False)
    mirrored = 2.0 * np.mean(c) - c  # an exact mirror image: r = −1
    pd.DataFrame({"time_s": t, "setpoint_c": mirrored}).to_csv(b, index=False)
    printed = _json(capsys, "profile", "correlate", str(a), str(b), "--json")
    d = correlate(t, c, t, mirrored).to_dict()
    assert {**d, "column_a": "setpoint_c", "column_b": "setpoint_c"} == printed
    assert list(d) == ["r", "weakly_correlated", "r_limit", "n", "duration_s"]
    assert d["r"] == pytest.approx(-1.0, abs=1e-9) and d["weakly_correlated"] is True
    assert d["duration_s"] == pytest.approx(t[-1])
