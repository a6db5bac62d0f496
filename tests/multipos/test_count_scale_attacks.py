"""Hostile count scales of a multipos calibration made on raw counts: tampered, NaN or
edited by hand, overflowing the counts; a triad's columns in conflicting units; a hostile
triad name in the generated C.  Through every command that reads the calibration."""

from __future__ import annotations

import contextlib
import io
import json
from pathlib import Path
from typing import Any

import pytest

from thermocal.cli import main


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
