"""The fleet reads what it needs once: each input's bytes for its digests (the SHA-256 the
fleet records in ``unit.json`` and the one in the model file's provenance are the same
digest of the same file, taken once per process: the bytes hashed equal the inputs' sizes,
not a multiple), and each unit's ``unit.json`` for the summary and the report."""

from __future__ import annotations

import hashlib
import json
from pathlib import Path
from typing import Any

import pytest

from fleet_data import config_text, write_run
from thermocal.fleet import batch
from thermocal.fleet.config import load_config
from thermocal.readers import common


class _Counted:
    """A SHA-256 object that counts the bytes given to ``update``."""

    seen: list[int] = []  # noqa: RUF012 - one list for the test

    def __init__(self, data: bytes = b"") -> None:
        self._h = hashlib.new("sha256", data)

    def update(self, block: bytes) -> None:
        _Counted.seen.append(len(block))
        self._h.update(block)

    def hexdigest(self) -> str:
        return self._h.hexdigest()


def test_each_input_hashed_once(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    runs = {uid: write_run(tmp_path / f"{uid}.csv", seed) for seed, uid in enumerate("ab")}
    val = write_run(tmp_path / "val.csv", 9, validation=True)
    units = {"a": ("a.csv", None), "b": ("b.csv", "val.csv")}
    (tmp_path / "batch.toml").write_text(config_text(units))
    common._SHA256_SEEN.clear()
    _Counted.seen.clear()
    monkeypatch.setattr(hashlib, "sha256", _Counted)
    res = batch.run_fleet(load_config(tmp_path / "batch.toml"), tmp_path / "out")
    assert res.failed == ()
    # every input once: a's and b's modelling files and b's validation file
    sizes = [r.path.stat().st_size for r in runs.values()] + [val.path.stat().st_size]
    assert sum(_Counted.seen) == sum(sizes)
    # and the digests recorded are the files' (computed here, by hashlib directly)
    unit: dict[str, Any] = json.loads((tmp_path / "out/units/b/unit.json").read_text())
    for path in (runs["b"].path, val.path):
        want = hashlib.new("sha256", path.read_bytes()).hexdigest()
        assert unit["inputs"][str(path)] == want


def test_each_unit_json_read_once_at_the_end(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    for seed, uid in enumerate("abc"):
        write_run(tmp_path / f"{uid}.csv", seed)
    units = {uid: (f"{uid}.csv", None) for uid in "abc"}
    (tmp_path / "batch.toml").write_text(config_text(units))
    reads: list[str] = []
    real = batch.read_unit

    def counted(out_dir: Path, uid: str) -> dict[str, Any] | None:
        reads.append(uid)
        return real(out_dir, uid)

    monkeypatch.setattr(batch, "read_unit", counted)
    res = batch.run_fleet(load_config(tmp_path / "batch.toml"), tmp_path / "out")
    assert sorted(reads) == ["a", "b", "c"]  # a first run: the summary's and report's reads
    assert [r["id"] for r in res.rows] == ["a", "b", "c"]
    assert [r["status"] for r in res.rows] == ["ok", "ok", "ok"]


def test_every_unit_runs_its_thread_pools_on_one_thread(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """While a unit is fitted every BLAS/OpenMP pool loaded holds one thread (the fits are
    one unit per core), unit after unit — the scan for the pools made once while no module
    is imported between units — and the process's own threads are given back after."""
    import threadpoolctl

    from thermocal.pipeline import fit

    for seed, uid in enumerate("abc"):
        write_run(tmp_path / f"{uid}.csv", seed)
    (tmp_path / "batch.toml").write_text(config_text({u: (f"{u}.csv", None) for u in "abc"}))
    seen: list[set[int]] = []
    real = fit.fit_files

    def counted(*args: Any, **kwargs: Any) -> Any:
        seen.append({p["num_threads"] for p in threadpoolctl.threadpool_info()})
        return real(*args, **kwargs)

    monkeypatch.setattr(fit, "fit_files", counted)
    with threadpoolctl.threadpool_limits(limits=2):
        before = [p["num_threads"] for p in threadpoolctl.threadpool_info()]
        if max(before) < 2:
            pytest.skip("no thread pool of more than one thread on this machine")
        res = batch.run_fleet(load_config(tmp_path / "batch.toml"), tmp_path / "out")
        after = [p["num_threads"] for p in threadpoolctl.threadpool_info()]
    assert res.failed == ()
    assert seen == [{1}, {1}, {1}]
    assert after == before
