"""Hostile layouts for ``thermocal fleet`` (issue 26 items 1, 2 and 9), generated here and
run through the command line.

Inputs are sacred: a path the fleet writes, replaces or deletes that is, or holds, one of its
inputs (the configuration, a modelling or validation file; by resolved path and by inode),
and a special file where it writes (FIFO, device, ``/proc``, ``/dev``), end in exit 2 with
one ``error:`` line naming the output and the input, before anything is written.  Reruns
that must redo a unit (changed data, a corrupted calibration) do, and never report the old
calibration.  Every input file is hashed before and after: none changes.
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import pytest

from fleet_data import config_text, write_run
from thermocal.cli import main


@dataclass(frozen=True)
class Layout:
    """What an attack built: the command's arguments after ``fleet``, the inputs to hash
    and the words the error must hold (the output's and the input's names)."""

    argv: list[str]
    inputs: list[Path]
    words: tuple[str, ...]


def _batch(root: Path, modeling: str, *, config: str = "batch.toml") -> Path:
    """A configuration at ``root/config`` with one unit U1 whose modelling file is
    ``modeling`` (relative to the configuration)."""
    cfg = root / config
    cfg.parent.mkdir(parents=True, exist_ok=True)
    cfg.write_text(config_text({"U1": (modeling, None)}), encoding="utf-8")
    return cfg


def _data(root: Path, rel: str = "data/U1.csv") -> Path:
    p = root / rel
    p.parent.mkdir(parents=True, exist_ok=True)
    write_run(p, 7)
    return p


def modeling_under_the_unit_folder(tmp: Path) -> Layout:
    run = _data(tmp, "out/units/U1/run1.csv")
    cfg = _batch(tmp, "out/units/U1/run1.csv")
    return Layout([str(cfg), "-o", str(tmp / "out")], [cfg, run], ("units/U1", "run1.csv"))


def modeling_under_the_unit_folder_forced(tmp: Path) -> Layout:
    lay = modeling_under_the_unit_folder(tmp)
    return Layout([*lay.argv, "--force"], lay.inputs, lay.words)


def output_folder_holds_summary_csv_input(tmp: Path) -> Layout:
    run = _data(tmp, "data/summary.csv")
    cfg = _batch(tmp, "data/summary.csv")
    return Layout([str(cfg), "-o", str(tmp / "data")], [cfg, run], ("summary.csv",))


def output_folder_holds_summary_parquet_input(tmp: Path) -> Layout:
    import pandas as pd

    src = _data(tmp, "data/U1.csv")
    run = tmp / "data" / "summary.parquet"
    pd.read_csv(src).to_parquet(run, index=False)
    cfg = _batch(tmp, "data/summary.parquet")
    return Layout([str(cfg), "-o", str(tmp / "data")], [cfg, run, src], ("summary.parquet",))


def config_named_like_the_report(tmp: Path) -> Layout:
    run = _data(tmp)
    cfg = _batch(tmp, "data/U1.csv", config="fleet.html")
    return Layout([str(cfg), "-o", str(tmp)], [cfg, run], ("fleet.html",))


def config_inside_the_unit_folder(tmp: Path) -> Layout:
    run = _data(tmp)
    cfg = _batch(tmp, "../../../data/U1.csv", config="out/units/U1/batch.toml")
    return Layout([str(cfg), "-o", str(tmp / "out")], [cfg, run], ("units/U1", "batch.toml"))


def summary_symlinked_to_an_input(tmp: Path) -> Layout:
    run = _data(tmp)
    cfg = _batch(tmp, "data/U1.csv")
    (tmp / "out").mkdir()
    (tmp / "out" / "summary.csv").symlink_to(run)
    return Layout([str(cfg), "-o", str(tmp / "out")], [cfg, run], ("summary.csv", "U1.csv"))


def summary_hard_linked_to_an_input(tmp: Path) -> Layout:
    run = _data(tmp)
    cfg = _batch(tmp, "data/U1.csv")
    (tmp / "out").mkdir()
    os.link(run, tmp / "out" / "summary.csv")
    return Layout([str(cfg), "-o", str(tmp / "out")], [cfg, run], ("summary.csv", "U1.csv"))


def unit_folder_symlinked_to_the_data(tmp: Path) -> Layout:
    run = _data(tmp)
    cfg = _batch(tmp, "data/U1.csv")
    (tmp / "out" / "units").mkdir(parents=True)
    (tmp / "out" / "units" / "U1").symlink_to(tmp / "data", target_is_directory=True)
    return Layout([str(cfg), "-o", str(tmp / "out")], [cfg, run], ("units/U1", "U1.csv"))


def hard_link_of_an_input_in_the_unit_folder(tmp: Path) -> Layout:
    run = _data(tmp)
    cfg = _batch(tmp, "data/U1.csv")
    (tmp / "out" / "units" / "U1").mkdir(parents=True)
    os.link(run, tmp / "out" / "units" / "U1" / "copy.csv")
    return Layout([str(cfg), "-o", str(tmp / "out")], [cfg, run], ("units/U1", "U1.csv"))


def input_in_a_stale_temporary_unit_folder(tmp: Path) -> Layout:
    run = _data(tmp, "out/units/.U1.tmp-deadbeef/run.csv")
    cfg = _batch(tmp, "out/units/.U1.tmp-deadbeef/run.csv")
    return Layout([str(cfg), "-o", str(tmp / "out")], [cfg, run], (".U1.tmp-deadbeef", "run.csv"))


def output_is_an_input_file(tmp: Path) -> Layout:
    run = _data(tmp)
    cfg = _batch(tmp, "data/U1.csv")
    return Layout([str(cfg), "-o", str(run)], [cfg, run], ("U1.csv", "not a directory"))


def output_is_a_fifo(tmp: Path) -> Layout:
    run = _data(tmp)
    cfg = _batch(tmp, "data/U1.csv")
    os.mkfifo(tmp / "out")
    return Layout([str(cfg), "-o", str(tmp / "out")], [cfg, run], ("out",))


def output_is_dev_null(tmp: Path) -> Layout:
    run = _data(tmp)
    cfg = _batch(tmp, "data/U1.csv")
    return Layout([str(cfg), "-o", "/dev/null"], [cfg, run], ("/dev/null",))


def output_under_proc(tmp: Path) -> Layout:
    run = _data(tmp)
    cfg = _batch(tmp, "data/U1.csv")
    return Layout([str(cfg), "-o", "/proc/self"], [cfg, run], ("/proc",))


def output_symlinked_into_dev(tmp: Path) -> Layout:
    run = _data(tmp)
    cfg = _batch(tmp, "data/U1.csv")
    (tmp / "out").symlink_to("/dev/shm", target_is_directory=True)
    return Layout([str(cfg), "-o", str(tmp / "out")], [cfg, run], ("/dev",))


def summary_is_a_fifo(tmp: Path) -> Layout:
    run = _data(tmp)
    cfg = _batch(tmp, "data/U1.csv")
    (tmp / "out").mkdir()
    os.mkfifo(tmp / "out" / "summary.csv")
    return Layout([str(cfg), "-o", str(tmp / "out")], [cfg, run], ("summary.csv", "FIFO"))


def report_symlinked_to_stdout(tmp: Path) -> Layout:
    run = _data(tmp)
    cfg = _batch(tmp, "data/U1.csv")
    (tmp / "out").mkdir()
    (tmp / "out" / "fleet.html").symlink_to("/proc/self/fd/1")
    return Layout([str(cfg), "-o", str(tmp / "out")], [cfg, run], ("fleet.html", "/proc"))


def units_folder_is_a_fifo(tmp: Path) -> Layout:
    run = _data(tmp)
    cfg = _batch(tmp, "data/U1.csv")
    (tmp / "out").mkdir()
    os.mkfifo(tmp / "out" / "units")
    return Layout([str(cfg), "-o", str(tmp / "out")], [cfg, run], ("units", "FIFO"))


def unit_folder_is_a_fifo(tmp: Path) -> Layout:
    run = _data(tmp)
    cfg = _batch(tmp, "data/U1.csv")
    (tmp / "out" / "units").mkdir(parents=True)
    os.mkfifo(tmp / "out" / "units" / "U1")
    return Layout([str(cfg), "-o", str(tmp / "out")], [cfg, run], ("units/U1", "FIFO"))


REFUSED: list[Callable[[Path], Layout]] = [
    modeling_under_the_unit_folder,
    modeling_under_the_unit_folder_forced,
    output_folder_holds_summary_csv_input,
    output_folder_holds_summary_parquet_input,
    config_named_like_the_report,
    config_inside_the_unit_folder,
    summary_symlinked_to_an_input,
    summary_hard_linked_to_an_input,
    unit_folder_symlinked_to_the_data,
    hard_link_of_an_input_in_the_unit_folder,
    input_in_a_stale_temporary_unit_folder,
    output_is_an_input_file,
    output_is_a_fifo,
    output_is_dev_null,
    output_under_proc,
    output_symlinked_into_dev,
    summary_is_a_fifo,
    report_symlinked_to_stdout,
    units_folder_is_a_fifo,
    unit_folder_is_a_fifo,
]


def _sha(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _tree(root: Path) -> dict[str, str]:
    """Every path under ``root`` (links not followed) with its kind and, for a regular
    file, its SHA-256: what was written, replaced or deleted shows as a difference."""
    out: dict[str, str] = {}
    for dirpath, dirs, files in os.walk(root):
        for name in (*dirs, *files):
            p = Path(dirpath) / name
            st = p.lstat()
            if p.is_symlink():
                out[str(p)] = f"link {os.readlink(p)}"
            elif p.is_file():
                out[str(p)] = f"file {_sha(p)}"
            else:
                out[str(p)] = f"mode {st.st_mode:o}"
    return out


@pytest.mark.parametrize("attack", REFUSED, ids=[f.__name__ for f in REFUSED])
def test_refused_before_anything_is_written(
    attack: Callable[[Path], Layout], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    lay = attack(tmp_path)
    before = {p: _sha(p) for p in lay.inputs}
    tree = _tree(tmp_path)
    capsys.readouterr()
    code = main(["fleet", *lay.argv, "--workers", "1"])
    err = capsys.readouterr().err
    assert code == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), err
    for w in lay.words:
        assert w in lines[0], (w, lines[0])
    assert {p: _sha(p) for p in lay.inputs} == before  # no input changed
    assert _tree(tmp_path) == tree  # nothing written, replaced or deleted


def test_the_same_layouts_resolved_run_and_keep_the_inputs(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Beside the refused layouts, the allowed neighbours: the output folder holding the
    data (but no file of fleet's own name), a unit folder of another batch beside the
    units: the batch runs and no input changes."""
    run = _data(tmp_path, "shared/U1.csv")
    other = _data(tmp_path, "shared/units/other/run.csv")
    cfg = _batch(tmp_path, "shared/U1.csv")
    inputs = [cfg, run, other]
    before = {p: _sha(p) for p in inputs}
    code = main(["fleet", str(cfg), "-o", str(tmp_path / "shared"), "--workers", "1"])
    assert code == 0, capsys.readouterr().err
    assert (tmp_path / "shared" / "units" / "U1" / "calibration.json").is_file()
    assert {p: _sha(p) for p in inputs} == before


def _corrupt_calibration(out: Path) -> None:
    cal = out / "units" / "U1" / "calibration.json"
    d = json.loads(cal.read_text(encoding="utf-8"))
    d["channels"][0]["model"]["state"]["constant"] += 1000.0
    cal.write_text(json.dumps(d), encoding="utf-8")


def _change_data(root: Path) -> None:
    src = root / "data" / "U1.csv"
    text = src.read_text(encoding="utf-8").splitlines()
    # a different recording of the unit: every gyro value 0.1 °/s higher
    head = text[0].split(",")
    i = head.index("gx [deg/s]")
    rows = [head]
    for line in text[1:]:
        cells = line.split(",")
        cells[i] = repr(float(cells[i]) + 0.1)
        rows.append(cells)
    src.write_text("\n".join(",".join(r) for r in rows) + "\n", encoding="utf-8")


@pytest.mark.parametrize(
    ("damage", "words"),
    [
        (lambda root: _corrupt_calibration(root / "out"), "checksum mismatch"),
        (lambda root: (root / "out/units/U1/calibration.json").write_bytes(b"\0" * 10), "verify"),
        (_change_data, "U1.csv changed"),
    ],
    ids=["calibration-edited", "calibration-zeroed", "data-re-recorded"],
)
def test_a_stale_unit_is_redone_and_never_reported_ok(
    damage: Callable[[Path], None],
    words: str,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:
    run = _data(tmp_path)
    cfg = _batch(tmp_path, "data/U1.csv")
    out = tmp_path / "out"
    assert main(["fleet", str(cfg), "-o", str(out), "--workers", "1"]) == 0
    damage(tmp_path)
    before = {p: _sha(p) for p in (cfg, run)}
    capsys.readouterr()
    code = main(["fleet", str(cfg), "-o", str(out), "--workers", "1", "--json"])
    res = json.loads(capsys.readouterr().out)
    assert code == 0 and res["ran"] == ["U1"] and words in res["redone"]["U1"]
    assert {p: _sha(p) for p in (cfg, run)} == before
    # the calibration now is the fit of the data the unit has now (numpy's least squares)
    import numpy as np
    import pandas as pd

    frame = pd.read_csv(run)
    slope, const = np.polyfit(frame["T1 [degC]"], frame["gx [deg/s]"], 1)
    rec = json.loads((out / "units/U1/unit.json").read_text(encoding="utf-8"))
    coefs = rec["channels"]["gx [deg/s]"]["coefficients"]
    assert coefs["const"] == pytest.approx(const, rel=1e-7)
    assert coefs["T1"] == pytest.approx(slope, rel=1e-7)
    assert rec["status"] == "ok" and rec["redone_because"] == res["redone"]["U1"]
    shutil.rmtree(out)


def test_names_in_the_report_are_text_not_markup(tmp_path: Path) -> None:
    """A file name or a column name is the user's text: in ``fleet.html`` it is escaped
    (the error naming a missing file ``<img src=x onerror=alert(1)>.csv``, a channel whose
    column is named with markup), never markup the browser runs."""
    import pandas as pd

    data = _data(tmp_path)
    frame = pd.read_csv(data)
    frame = frame.rename(columns={"gx [deg/s]": "gx <b>x</b> [deg/s]"})
    frame[["time [s]", "gx <b>x</b> [deg/s]", "T1 [degC]"]].to_csv(data, index=False)
    bad = "<img src=x onerror=alert(1)>.csv"
    cfg = tmp_path / "batch.toml"
    cfg.write_text(
        '[fit]\nmodel = "poly"\norder = 1\nsignal = "gx <b>x</b> [deg/s]"\n'
        'temps = "T1 [degC]"\n\n[[unit]]\nid = "U1"\nmodeling = ["data/U1.csv"]\n\n'
        f'[[unit]]\nid = "U2"\nmodeling = ["data/{bad}"]\n',
        encoding="utf-8",
    )
    main(["fleet", str(cfg), "-o", str(tmp_path / "out"), "--workers", "1", "--json"])
    html = (tmp_path / "out" / "fleet.html").read_text(encoding="utf-8")
    assert "gx &lt;b&gt;x&lt;/b&gt; [deg/s]" in html and "<b>x</b>" not in html
    assert "&lt;img src=x onerror=alert(1)&gt;.csv" in html and "<img src=x" not in html
