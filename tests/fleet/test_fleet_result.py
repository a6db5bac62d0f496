"""A batch's outcome (:class:`thermocal.fleet.batch.FleetResult`): the counts are those of
the rows given here, counted by hand; the workers' checks name the parameters and the
command line shows its options."""

from __future__ import annotations

from pathlib import Path

import pytest

from thermocal.errors import ParameterError
from thermocal.fleet.batch import FleetResult, check_workers
from thermocal.pipeline.messages import error_text


def _result() -> FleetResult:
    rows = (
        {"id": "a", "status": "ok", "pass": True, "error": None},
        {"id": "b", "status": "ok", "pass": False, "error": None},
        {"id": "c", "status": "failed", "error": "c.csv: no column 'gx'"},
        {"id": "d", "status": "pending", "error": None},
    )
    out = Path("out")
    files = (out / "summary.csv", out / "summary.parquet", out / "fleet.html")
    return FleetResult(("a", "c"), ("b",), ("c",), rows, *files, None, {"a": "inputs changed"})


def test_summary_counts_the_rows() -> None:
    d = _result().summary(Path("out"))
    # 4 rows: a, b calibrated (a within the limits), c failed, d neither
    assert (d["units"], d["ok"], d["failed"], d["pending"], d["passed"]) == (4, 2, 1, 1, 1)
    assert d["failed_units"] == {"c": "c.csv: no column 'gx'"}
    assert (
        d["ran"] == ["a", "c"] and d["skipped"] == ["b"] and d["redone"] == {"a": "inputs changed"}
    )
    assert d["output"] == "out" and d["report"] == str(Path("out/fleet.html"))


def test_text_says_the_counts_and_the_redone_units() -> None:
    assert _result().text() == [
        "4 units: 2 calibrated (2 now, 1 done before), 1 failed, 1 passed",
        "redone a: inputs changed",
        f"summary: {Path('out/summary.csv')}, {Path('out/summary.parquet')}",
        f"report: {Path('out/fleet.html')}",
    ]


def test_check_workers_names_the_parameters() -> None:
    check_workers(None, None)
    check_workers(2, None)
    with pytest.raises(ParameterError) as info:
        check_workers(0, None)
    assert str(info.value) == "workers must be at least 1, got 0"
    assert error_text(info.value) == ("--workers must be at least 1, got 0", True)
    with pytest.raises(ParameterError) as info:
        check_workers(2, "tcp://h:8786")
    assert str(info.value) == "give workers or scheduler, not both"
    assert error_text(info.value)[0] == "give --workers or --scheduler, not both"
