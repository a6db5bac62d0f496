"""What a unit was made from: ``unit.json``'s ``inputs`` holds the SHA-256 of each input
file, taken where the unit ran (a worker hashes its own unit's files, in parallel with the
others) or by the driver for a unit it had to judge stale first; a rerun judges them
against the files.  The digests are computed here with hashlib from the files' bytes."""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

from fleet_data import config_text, write_run
from thermocal.fleet import batch
from thermocal.fleet.config import load_config


def _sha(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _batch(tmp_path: Path) -> Path:
    write_run(tmp_path / "a.csv", 1)
    write_run(tmp_path / "a_val.csv", 2, validation=True)
    write_run(tmp_path / "b.csv", 3)
    cfg = tmp_path / "batch.toml"
    cfg.write_text(config_text({"A": ("a.csv", "a_val.csv"), "B": ("b.csv", None)}))
    return cfg


def test_a_unit_hashes_its_inputs_where_it_runs(tmp_path: Path) -> None:
    config = load_config(_batch(tmp_path))
    unit = config.units[0]
    outcome = batch.run_unit(batch.UnitTask(unit, batch._fit_options(config), config.validate))
    assert outcome.status == "ok"
    assert outcome.inputs == {
        str(tmp_path / "a.csv"): _sha(tmp_path / "a.csv"),
        str(tmp_path / "a_val.csv"): _sha(tmp_path / "a_val.csv"),
    }


def _recorded(out: Path, uid: str) -> dict[str, str]:
    rec = json.loads((out / "units" / uid / "unit.json").read_text(encoding="utf-8"))
    return dict(rec["inputs"])


def test_unit_json_records_the_digests_first_run_and_rerun(tmp_path: Path) -> None:
    config = load_config(_batch(tmp_path))
    out = tmp_path / "out"
    first = batch.run_fleet(config, out)
    assert sorted(first.ran) == ["A", "B"]
    expected_b = {str(tmp_path / "b.csv"): _sha(tmp_path / "b.csv")}
    assert _recorded(out, "B") == expected_b
    # a first run on an executor whose outcomes carry no digests (a unit function of the
    # caller's): the driver hashes the files itself
    plain = batch.local_executor(1, unit_fn=_without_digests)
    batch.run_fleet(config, tmp_path / "out2", executor=plain)
    assert _recorded(tmp_path / "out2", "B") == expected_b
    write_run(tmp_path / "b.csv", 4)  # B's file changes: the rerun redoes B only
    again = batch.run_fleet(config, out)
    assert again.ran == ("B",)
    assert again.redone == {"B": f"input {tmp_path / 'b.csv'} changed"}
    assert _recorded(out, "B") == {str(tmp_path / "b.csv"): _sha(tmp_path / "b.csv")}


def _without_digests(task: batch.UnitTask) -> batch.UnitOutcome:
    outcome = batch.run_unit(task)
    outcome.inputs = {}
    return outcome
