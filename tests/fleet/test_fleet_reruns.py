"""Fleet reruns that are right (issue 26 item 2): a unit is redone when its inputs' content,
its options ([fit], [validate] where it has a validation run, [limits]) or thermocal's
version differ from what its ``unit.json`` records, or when its folder does not verify; the
command's JSON (``redone``), ``summary.csv`` and ``fleet.html`` say which and why.  A
corrupted ``calibration.json`` is never reported ok."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pytest

from fleet_data import TEMP, config_text, write_run
from thermocal.cli import main
from thermocal.fleet import batch as fleet

GX = "gx [deg/s]"


@pytest.fixture
def batch(tmp_path: Path) -> Path:
    """U1 (modelling and validation), U2 and U3 (modelling only); the configuration."""
    data = tmp_path / "data"
    data.mkdir()
    write_run(data / "U1_mod.csv", 1)
    write_run(data / "U1_val.csv", 2, validation=True)
    write_run(data / "U2_mod.csv", 3)
    write_run(data / "U3_mod.csv", 4)
    cfg = tmp_path / "batch.toml"
    units = {
        "U1": ("data/U1_mod.csv", "data/U1_val.csv"),
        "U2": ("data/U2_mod.csv", None),
        "U3": ("data/U3_mod.csv", None),
    }
    cfg.write_text(config_text(units), encoding="utf-8")
    return cfg


def _fleet(cfg: Path, out: Path, capsys: pytest.CaptureFixture[str]) -> dict[str, Any]:
    capsys.readouterr()
    code = main(["fleet", str(cfg), "-o", str(out), "--workers", "1", "--json"])
    res: dict[str, Any] = json.loads(capsys.readouterr().out)
    assert code == 0, res
    return res


def _slope(out: Path, uid: str) -> float:
    rec = json.loads((out / "units" / uid / "unit.json").read_text(encoding="utf-8"))
    return float(rec["channels"][GX]["coefficients"]["T1"])


def test_changed_data_options_and_version_redo_exactly_the_units_concerned(
    batch: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    out = tmp_path / "out"
    data = tmp_path / "data"
    res = _fleet(batch, out, capsys)
    assert res["ran"] == ["U1", "U2", "U3"] and res["redone"] == {}

    res = _fleet(batch, out, capsys)  # nothing changed
    assert res["ran"] == [] and res["skipped"] == ["U1", "U2", "U3"] and res["redone"] == {}

    # U2's data re-recorded: a steeper gyro (slope 0.004 °/s/°C instead of 0.002)
    frame = pd.read_csv(data / "U2_mod.csv")
    frame[GX] += 0.002 * (frame[TEMP] - 25.0)
    frame.to_csv(data / "U2_mod.csv", index=False, float_format="%.12g")
    res = _fleet(batch, out, capsys)
    assert res["ran"] == ["U2"] and set(res["skipped"]) == {"U1", "U3"}
    assert list(res["redone"]) == ["U2"] and "U2_mod.csv changed" in res["redone"]["U2"]
    T, x = frame[TEMP].to_numpy(), frame[GX].to_numpy()
    assert _slope(out, "U2") == pytest.approx(np.polyfit(T, x, 1)[0], rel=1e-7)
    summary = pd.read_csv(out / "summary.csv", keep_default_na=False).set_index("id")
    assert "U2_mod.csv changed" in str(summary.loc["U2", "redone"])
    assert summary.loc["U1", "redone"] == "" and summary.loc["U3", "redone"] == ""
    html = (out / "fleet.html").read_text(encoding="utf-8")
    assert "U2_mod.csv changed" in html.split('id="redone"')[1].split("</table>")[0]

    # a sidecar appears beside U3's data: it sets units, so U3 depends on it
    (data / "U3_mod.csv.meta.json").write_text("{}", encoding="utf-8")
    res = _fleet(batch, out, capsys)
    assert res["ran"] == ["U3"] and "U3_mod.csv.meta.json is new" in res["redone"]["U3"]

    # [validate] applies to U1 only (the only unit with a validation run)
    batch.write_text(batch.read_text().replace("averaging = 10", "averaging = 20"))
    res = _fleet(batch, out, capsys)
    assert res["ran"] == ["U1"] and "[validate] options changed" in res["redone"]["U1"]

    # [fit] and [limits] apply to every unit
    batch.write_text(batch.read_text().replace("order = 1", "order = 2"))
    res = _fleet(batch, out, capsys)
    assert sorted(res["ran"]) == ["U1", "U2", "U3"]
    assert all("[fit] options changed" in why for why in res["redone"].values())
    batch.write_text(batch.read_text() + "\n[limits]\nrms_residual_max = 1e9\n")
    res = _fleet(batch, out, capsys)
    assert sorted(res["ran"]) == ["U1", "U2", "U3"]
    assert all("[limits] options changed" in why for why in res["redone"].values())

    # a new thermocal
    import thermocal

    monkeypatch.setattr(thermocal, "__version__", "99.0.0")
    res = _fleet(batch, out, capsys)
    assert sorted(res["ran"]) == ["U1", "U2", "U3"]
    assert all("thermocal version changed" in why for why in res["redone"].values())
    rec = json.loads((out / "units" / "U1" / "unit.json").read_text(encoding="utf-8"))
    assert rec["thermocal_version"] == "99.0.0"
    res = _fleet(batch, out, capsys)
    assert res["ran"] == []


def _edit_coefficient(cal_path: Path, fix_checksums: bool) -> None:
    """Change the first channel's constant in a calibration file by 1 (a corruption), and
    with ``fix_checksums`` recompute the model's and the calibration's checksums (an edit
    that the file's own check cannot see)."""
    from thermocal.models.format import checksum

    d = json.loads(cal_path.read_text(encoding="utf-8"))
    model = d["channels"][0]["model"]
    state = model["state"]
    key = "constant" if "constant" in state else next(iter(state))
    state[key] = float(state[key]) + 1.0
    if fix_checksums:
        model["checksum"] = checksum(model)
        d["checksum"] = checksum(d)
    cal_path.write_text(json.dumps(d), encoding="utf-8")


@pytest.mark.parametrize(
    ("damage", "words"),
    [
        (lambda f: _edit_coefficient(f, fix_checksums=False), "checksum mismatch"),
        (lambda f: _edit_coefficient(f, fix_checksums=True), "changed since it was written"),
        (lambda f: f.write_text("{", encoding="utf-8"), "does not verify"),
        (lambda f: f.unlink(), "calibration.json is missing"),
        (lambda f: (f.parent / "unit.json").unlink(), "no readable unit.json"),
        (lambda f: (f.parent / "validation.json").write_text("{}"), "validation.json changed"),
    ],
    ids=["edited", "edited-checksums-redone", "truncated", "missing", "no-unit-json", "val"],
)
def test_a_damaged_unit_folder_is_redone_never_reported_ok(
    batch: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    damage: Any,
    words: str,
) -> None:
    out = tmp_path / "out"
    _fleet(batch, out, capsys)
    good = _slope(out, "U1")
    damage(out / "units" / "U1" / "calibration.json")
    res = _fleet(batch, out, capsys)
    assert res["ran"] == ["U1"] and words in res["redone"]["U1"], res["redone"]
    assert _slope(out, "U1") == good  # the same data, the same numbers
    rec = fleet.read_unit(out, "U1")
    assert rec is not None
    assert fleet.verify_unit_folder(out / "units" / "U1", rec) == []


def test_an_interrupted_rerun_leaves_stale_units_pending(
    batch: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Units found stale but not redone before a Ctrl-C are ``pending`` in the summary
    (with why), never shown with their old figures as ok."""
    out = tmp_path / "out"
    _fleet(batch, out, capsys)
    batch.write_text(batch.read_text().replace("order = 1", "order = 2"))
    cfg = fleet.load_config(batch)
    inner = fleet.local_executor(1)

    def interrupted(tasks: list[fleet.UnitTask]) -> Any:
        for i, outcome in enumerate(inner(tasks)):
            if i == 1:
                raise KeyboardInterrupt
            yield outcome

    with pytest.raises(KeyboardInterrupt):
        fleet.run_fleet(cfg, out, executor=interrupted)
    rows = pd.read_csv(out / "summary.csv").set_index("id")
    assert rows.loc["U1", "status"] == "ok"
    for uid in ("U2", "U3"):
        assert rows.loc[uid, "status"] == "pending"
        error = str(rows.loc[uid, "error"])
        assert "to be redone" in error and "[fit]" in error
    res = fleet.run_fleet(cfg, out)
    assert sorted(res.ran) == ["U2", "U3"] and res.skipped == ("U1",)
