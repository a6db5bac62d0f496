"""Command line: ``thermocal profile ...`` and ``thermocal simulate ...``."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose

from thermocal.cli import main
from thermocal.profiles import builtin_profile, correlate
from thermocal.readers.dispatch import read_recording
from thermocal.readers.program import read_program
from thermocal.writers import write_program


def run(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, str, str]:
    code = main([str(a) for a in args])
    out, err = capsys.readouterr()
    return code, out, err


def test_profile_builtin_writes_program(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "m.csv"
    code, stdout, _ = run(capsys, "profile", "rlg-modelling", "-o", out, "--json", "--dt", "30")
    assert code == 0
    summary = json.loads(stdout)
    t, c = read_program(out)
    ref_t, ref_c = builtin_profile("rlg-modelling").program(30.0)
    assert_allclose(t, ref_t)
    assert_allclose(c, ref_c, atol=1e-9)
    assert summary["n_points"] == t.size
    assert summary["min_c"] == -20.0 and summary["max_c"] == 50.0
    assert out.read_text().splitlines()[0] == "time_s,setpoint_c"


@pytest.mark.parametrize(
    ("name", "args"),
    [
        ("rlg-validation", ["--holds", "0,40,-10", "--hold-s", "3600"]),
        ("fog-slow", ["--rate", "0.2"]),
        ("mems-warmup", ["--starts", "-40,25,85", "--record-s", "600"]),
        ("accel-full-range", ["--repeats", "2", "--step", "10"]),
    ],
)
def test_profile_options(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], name: str, args: list[str]
) -> None:
    out = tmp_path / f"{name}.csv"
    code, stdout, err = run(capsys, "profile", name, "-o", out, "--dt", "0", "--json", *args)
    assert code == 0, err
    t, c = read_program(out)
    assert json.loads(stdout)["duration_s"] == pytest.approx(t[-1])
    if name == "rlg-validation":
        assert sorted(set(np.round(c, 6))) == [-10.0, 0.0, 20.0, 40.0]
    if name == "accel-full-range":
        prof = builtin_profile("accel-full-range", repeats=2, step_c=10.0)
        assert t[-1] == pytest.approx(prof.duration_s)


def test_profile_correlate_json(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    a, b = tmp_path / "a.csv", tmp_path / "b.csv"
    assert run(capsys, "profile", "rlg-modelling", "-o", a)[0] == 0
    assert run(capsys, "profile", "rlg-validation", "-o", b)[0] == 0
    code, stdout, _ = run(capsys, "profile", "correlate", a, b, "--json")
    assert code == 0
    obj = json.loads(stdout)
    ref = correlate(*read_program(a), *read_program(b))
    assert obj["r"] == pytest.approx(ref.r, abs=1e-12)
    assert obj["weakly_correlated"] is True
    code, stdout, _ = run(capsys, "profile", "correlate", a, a, "--json")
    assert json.loads(stdout)["r"] == pytest.approx(1.0)
    assert json.loads(stdout)["weakly_correlated"] is False


def test_profile_design_validation(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    model = tmp_path / "model.csv"
    t, c = builtin_profile("rlg-modelling", rates_c_per_min=(2.0, 1.0)).program(60.0)
    write_program(model, t, c)
    val = tmp_path / "val.csv"
    code, stdout, err = run(
        capsys, "profile", "design-validation", model, "-o", val, "--seed", "4", "--json"
    )
    assert code == 0, err
    obj = json.loads(stdout)
    r = correlate(t, c, *read_program(val)).r
    assert abs(r) < 0.4 and obj["weakly_correlated"] is True
    assert obj["r"] == pytest.approx(r, abs=1e-3)
    val2 = tmp_path / "val2.csv"
    code, _, err = run(
        capsys, "profile", "rlg-validation", "--against", model, "--seed", "4", "-o", val2
    )
    assert code == 0, err
    assert val2.read_bytes() == val.read_bytes()


def test_profile_correlate_recording_column(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    prog = tmp_path / "p.csv"
    t, c = builtin_profile("fog-slow", hold_s=600.0, rate_c_per_min=1.0).program(60.0)
    write_program(prog, t, c)
    rec = tmp_path / "rec.csv"
    assert run(capsys, "simulate", "fog-slow", "--profile", prog, "-o", rec)[0] == 0
    code, stdout, _ = run(
        capsys, "profile", "correlate", rec, prog, "--column", "T_chamber", "--json"
    )
    assert code == 0
    obj = json.loads(stdout)
    assert obj["column_a"] == "T_chamber" and obj["column_b"] == "setpoint_c"
    assert obj["r"] > 0.95  # the chamber air follows its own program


def test_profile_bad_input(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, _, err = run(capsys, "profile", "correlate", tmp_path / "no.csv", tmp_path / "no.csv")
    assert code == 2 and err.startswith("error:") and len(err.strip().splitlines()) == 1
    bad = tmp_path / "bad.csv"
    bad.write_text("time,b\n1,2\n3,4\n")
    code, _, err = run(capsys, "profile", "correlate", bad, bad)
    assert code == 2 and "temperature column" in err
    code, _, err = run(
        capsys, "profile", "rlg-validation", "-o", tmp_path / "x.csv", "--holds", "a,b"
    )
    assert code == 2 and "--holds" in err
    code, _, err = run(
        capsys, "profile", "mems-warmup", "-o", tmp_path / "x.csv", "--record-s", "10"
    )
    assert code == 2 and "360" in err


def _short_program(tmp_path: Path) -> Path:
    prog = tmp_path / "short.csv"
    write_program(prog, [0.0, 600.0, 1500.0, 2400.0], [20.0, 20.0, 35.0, 35.0])
    return prog


def test_simulate_same_seed_same_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    prog = _short_program(tmp_path)
    files = []
    for name, seed in (("a.csv", 5), ("b.csv", 5), ("c.csv", 6)):
        out = tmp_path / name
        code, _, err = run(capsys, "simulate", "rlg-modelling", "-o", out, "--seed", seed,
                           "--profile", prog)  # fmt: skip
        assert code == 0, err
        files.append(out.read_bytes())
    assert files[0] == files[1]
    assert files[0] != files[2]


def test_simulate_roundtrip_roles_and_truth(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    prog = _short_program(tmp_path)
    out = tmp_path / "r.parquet"
    truth = tmp_path / "truth.json"
    code, stdout, err = run(capsys, "simulate", "rlg-validation", "-o", out, "--profile", prog,
                            "--truth", truth, "--rate-hz", "2", "--json")  # fmt: skip
    assert code == 0, err
    assert json.loads(stdout)["files"] == [str(out)]
    rec = read_recording(out)
    assert rec.signals == ("gyro",) and rec.temperatures == ("T1", "T2", "T3", "T4")
    rate, unit = rec.signal("gyro")
    assert unit == "deg/h"
    assert rec.sample_interval_s == pytest.approx(0.5)
    assert abs(np.mean(rate - rec.columns["truth_rate"])) < 0.05
    obj = json.loads(truth.read_text())
    assert obj["format"] == "thermocal-truth" and obj["scenario"] == "rlg-validation"
    entry = obj["files"][0]
    assert entry["file"] == str(out)
    assert {"bias_constant", "turn_on_offset", "earth_rate_on_axis_deg_h", "preset"} <= set(entry)


def test_simulate_multi_file_naming(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    d = tmp_path / "warm"
    truth = tmp_path / "w.json"
    code, _, err = run(capsys, "simulate", "mems-warmup", "-o", d, "--truth", truth,
                       "--record-s", "400", "--rate-hz", "2")  # fmt: skip
    assert code == 0, err
    names = sorted(p.name for p in d.glob("*.csv"))
    assert "mems-warmup_T+20.csv" in names and len(names) == 7
    listed = [e["file"] for e in json.loads(truth.read_text())["files"]]
    assert sorted(Path(f).name for f in listed) == names
    stem = tmp_path / "acc" / "a.csv"
    prog = _short_program(tmp_path)
    code, _, err = run(capsys, "simulate", "accel-full-range", "-o", stem, "--runs", "2",
                       "--profile", prog)  # fmt: skip
    assert code == 0, err
    assert sorted(p.name for p in stem.parent.glob("*.csv")) == ["a_run1.csv", "a_run2.csv"]


def test_simulate_bad_input(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, _, err = run(capsys, "simulate", "nope", "-o", tmp_path / "x.csv")
    assert code == 2 and "unknown scenario" in err
    prog = _short_program(tmp_path)
    code, _, err = run(capsys, "simulate", "fog-slow", "-o", prog, "--profile", prog)
    assert code == 2 and "refusing" in err
    code, _, err = run(capsys, "simulate", "accel-full-range", "-o", tmp_path / "y.csv",
                       "--latitude", "10")  # fmt: skip
    assert code == 2 and "latitude" in err
    assert not (tmp_path / "y.csv").exists()
