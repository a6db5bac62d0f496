"""``thermocal.pipeline.simulate``: the library call behind ``thermocal simulate``; its
``to_dict()`` is what ``--json`` prints."""

from __future__ import annotations

import gzip
import json
import shutil
from pathlib import Path

import pytest

from thermocal.cli import main
from thermocal.errors import ParameterError
from thermocal.pipeline.simulate import simulate_files, simulation_paths
from thermocal.readers.dispatch import read_recording
from thermocal.simulate import SimulateOptions


def test_to_dict_is_what_the_cli_prints(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out, truth = tmp_path / "runs", tmp_path / "truth.json"
    args = ["simulate", "accel-full-range", "-o", str(out), "--runs", "2", "--seed", "3"]
    assert main([*args, "--truth", str(truth), "--json"]) == 0
    printed = json.loads(capsys.readouterr().out)
    shutil.rmtree(out)
    truth.unlink()
    res = simulate_files(
        "accel-full-range", out, seed=3, truth=truth, options=SimulateOptions(runs=2)
    )
    assert res.to_dict() == printed
    # the counts are the files' rows, read back by the reader
    # what was asked, independently of the code under test
    assert printed["scenario"] == "accel-full-range"
    assert printed["seed"] == 3
    assert printed["truth"] == str(truth)
    assert len(printed["files"]) == 2
    assert all(Path(f).parent == out and f.endswith(".csv") for f in printed["files"])
    for f, n in zip(printed["files"], printed["n_samples"], strict=True):
        assert read_recording(f).n_samples == n
    assert json.loads(truth.read_text())["seed"] == 3


def test_bad_format_names_the_parameter_and_the_option(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    with pytest.raises(ParameterError, match=r"^file_format must be csv or parquet"):
        simulation_paths(tmp_path / "d", "fog-slow", ["a", "b"], "xml")
    code = main(["simulate", "mems-warmup", "-o", str(tmp_path / "d"), "--format", "xml"])
    err = capsys.readouterr().err
    assert code == 2
    assert err.strip() == "error: --format must be csv or parquet, got 'xml'"


@pytest.mark.parametrize(
    ("kw", "lib", "opts", "cli"),
    [
        ({"rate_hz": 0.0}, "rate_hz must be a positive number, got 0.0",
         ["--rate-hz", "0"], "--rate-hz must be a positive number, got 0.0"),
        ({"latitude_deg": 100.0}, "latitude_deg must be within ±90°, got 100.0",
         ["--latitude", "100"], "--latitude must be within ±90°, got 100.0"),
    ],
)  # fmt: skip
def test_options_name_the_parameter_and_the_cli_the_option(
    kw: dict[str, float], lib: str, opts: list[str], cli: str, tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:  # fmt: skip
    with pytest.raises(ParameterError) as e:
        SimulateOptions(**kw)
    assert str(e.value) == lib
    code = main(["simulate", "fog-slow", "-o", str(tmp_path / "x.csv"), *opts])
    assert code == 2
    assert capsys.readouterr().err.strip() == f"error: {cli}"


@pytest.mark.parametrize("ending", [".log", ".tsv", ".csv.gz"])
def test_a_stem_with_any_registered_csv_suffix_names_several_files(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], ending: str
) -> None:
    """``-o out/warm.log`` for a scenario of several runs: the suffix is the file-format
    registry's (a CSV ending it lists), kept after each run's label, as ``-o out/warm.csv``
    names them; each file reads back with the rows the command printed."""
    args = ["simulate", "accel-full-range", "--runs", "2", "--seed", "1", "--json"]
    assert main([*args, "-o", str(tmp_path / "ref" / "warm.csv")]) == 0
    ref = [Path(f).name for f in json.loads(capsys.readouterr().out)["files"]]
    assert main([*args, "-o", str(tmp_path / "got" / f"warm{ending}")]) == 0
    printed = json.loads(capsys.readouterr().out)
    assert [Path(f).name for f in printed["files"]] == [
        n.removesuffix(".csv") + ending for n in ref
    ]
    for f, n in zip(printed["files"], printed["n_samples"], strict=True):
        assert read_recording(f).n_samples == n
    if ending == ".csv.gz":  # gzip, holding the text -o warm.csv holds
        for got, name in zip(printed["files"], ref, strict=True):
            assert Path(got).read_bytes()[:2] == b"\x1f\x8b"
            assert gzip.decompress(Path(got).read_bytes()) == (tmp_path / "ref" / name).read_bytes()


def test_a_csv_gz_that_is_not_gzip_is_refused_in_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A plain CSV named ``.csv.gz`` (what thermocal wrote before it compressed them)."""
    bad = tmp_path / "run.csv.gz"
    bad.write_text("time,gx,T\n0,1,20\n1,2,21\n", encoding="utf-8")
    assert main(["inspect", str(bad)]) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(
        f"error: {bad}: named .gz but not a readable gzip"
    )


@pytest.mark.parametrize(
    ("name", "what"), [("warm.ulg", "a PX4 log"), ("warm.bin", "an ArduPilot log")]
)
def test_a_log_format_thermocal_only_reads_is_refused_before_simulating(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], name: str, what: str
) -> None:
    out = tmp_path / name
    code = main(["simulate", "accel-full-range", "--runs", "2", "-o", str(out)])
    lines = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(lines) == 1, lines
    assert lines[0] == (
        f"error: {out}: thermocal reads {what} but writes recordings as CSV or Parquet; name "
        "the output *.csv or *.parquet"
    )
    assert list(tmp_path.iterdir()) == []
