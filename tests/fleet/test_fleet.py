"""Production batches (issue 18): ``thermocal fleet`` on units written the way a lab's
logger writes them (CSV, units in the column names), one corrupt file among them.

Checked: each unit's slope against the truth the test wrote; a corrupt unit isolated with an
error naming its file; the same coefficients bit for bit in this process, in two local worker
processes and on a real ``dask.distributed.LocalCluster``; resume after an interrupted batch
(Ctrl-C, a dead worker pool, a half-written unit directory); ``--force``; limits; the
summary's rows; the report; configuration errors (exit 2)."""

from __future__ import annotations

import json
import math
from concurrent.futures.process import BrokenProcessPool
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pytest

from thermocal.cli import main
from thermocal.fleet import batch as fleet

SLOPES = {"u01": 0.020, "u02": 0.021, "u03": 0.019, "u04": 0.0205, "u05": 0.0195, "u06": 0.2}
"""Temperature sensitivity [°/h per °C] of each unit; u06 is the outlier."""
BIASES = {u: 1.0 + 0.1 * i for i, u in enumerate(SLOPES)}


def _write_run(path: Path, slope: float, bias: float, seed: int, validation: bool) -> None:
    rng = np.random.default_rng(seed)
    n = 1500
    t = np.arange(n, dtype=np.float64)
    sine = 25.0 + 20.0 * np.sin(2 * np.pi * t / n)
    temp = sine if validation else np.linspace(-10.0, 60.0, n)
    gyro = bias + slope * (temp - 25.0) + rng.normal(0.0, 0.01, n)
    pd.DataFrame({"time [s]": t, "gyro [deg/h]": gyro, "T1 [degC]": temp}).to_csv(
        path, index=False, float_format="%.10g"
    )


@pytest.fixture
def batch(tmp_path: Path) -> Path:
    data = tmp_path / "data"
    data.mkdir()
    units = []
    for i, (uid, slope) in enumerate(SLOPES.items()):
        _write_run(data / f"{uid}_mod.csv", slope, BIASES[uid], i, validation=False)
        _write_run(data / f"{uid}_val.csv", slope, BIASES[uid], 100 + i, validation=True)
        units.append(
            f'[[unit]]\nid = "{uid}"\nmodeling = ["data/{uid}_mod.csv"]\n'
            f'validation = "data/{uid}_val.csv"\n'
        )
    (data / "bad_mod.parquet").write_bytes(b"PAR1 this is not a parquet file")
    units.append('[[unit]]\nid = "bad"\nmodeling = ["data/bad_mod.parquet"]\n')
    units.append('[[unit]]\nid = "gone"\nmodeling = ["data/missing.csv"]\n')
    cfg = tmp_path / "batch.toml"
    cfg.write_text(
        '[fit]\nmodel = "poly"\norder = 1\nsignal = "gyro [deg/h]"\ntemps = "T1 [degC]"\n\n'
        "[limits]\nrms_after_max = 0.05\n\n" + "\n".join(units),
        encoding="utf-8",
    )
    return cfg


def _coefficients(out: Path, uid: str) -> dict[str, float]:
    cal = json.loads((out / "units" / uid / "calibration.json").read_text())
    rec = json.loads((out / "units" / uid / "unit.json").read_text())
    assert cal["format"] in ("thermocal-model", "thermocal-calibration")
    return dict(rec["channels"]["gyro [deg/h]"]["coefficients"])


def test_a_batch_in_this_process(
    batch: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "out"
    code = main(["fleet", str(batch), "-o", str(out), "--workers", "1", "--json"])
    assert code == fleet.EXIT_SOME_FAILED  # two units failed, the others went on
    res = json.loads(capsys.readouterr().out)
    assert res["ok"] == 6 and res["failed"] == 2
    assert "bad_mod.parquet" in res["failed_units"]["bad"]
    assert "missing.csv" in res["failed_units"]["gone"]
    for uid, slope in SLOPES.items():
        coefs = _coefficients(out, uid)
        # order 1 about the centre of the data's range: the slope per °C is the T1 term
        # divided by the centring scale; compare the predicted change over the range instead
        assert set(coefs) >= {"T1"}
        rec = json.loads((out / "units" / uid / "unit.json").read_text())
        fig = rec["channels"]["gyro [deg/h]"]
        assert fig["unit"] == "deg/h"
        assert fig["rms_residual"] == pytest.approx(0.01, rel=0.15)  # the noise written
        assert fig["rms_after"] < 0.02 and fig["rms_before"] > 10 * slope  # compensated
    rows = pd.read_parquet(out / "summary.parquet")
    assert list(rows["id"]) == [*SLOPES, "bad", "gone"]
    assert list(rows["status"]) == ["ok"] * 6 + ["failed"] * 2
    assert rows["pass"].tolist()[:6] == [True] * 6
    csv = pd.read_csv(out / "summary.csv")
    assert csv.shape == rows.shape
    html = (out / "fleet.html").read_text()
    assert "bad_mod.parquet" in html and "yield" in html
    assert "u06" in html.split('id="outliers"')[1].split("</section>")[0]  # the outlier named
    assert not list((out / "units").glob(".*"))  # no temporary directory left
    # a unit's validation names the calibration beside it, not the worker's scratch copy
    for uid in SLOPES:
        folder = out / "units" / uid
        val = json.loads((folder / "validation.json").read_text())
        assert val["model"] == "calibration.json", val["model"]
        assert (folder / val["model"]).is_file()


def test_the_slope_recovered_against_the_truth(batch: Path, tmp_path: Path) -> None:
    """The compensated validation run: the model removes the written slope, so the model's
    prediction over the run follows bias + slope·(T − 25) (checked through the compensate
    command on the unit's calibration)."""
    out = tmp_path / "out"
    main(["fleet", str(batch), "-o", str(out), "--workers", "1"])
    for uid, slope in SLOPES.items():
        comp = tmp_path / f"{uid}_comp.csv"
        cal = out / "units" / uid / "calibration.json"
        src = batch.parent / "data" / f"{uid}_val.csv"
        assert main(["compensate", str(cal), str(src), "-o", str(comp)]) == 0
        df = pd.read_csv(comp)
        model = df["gyro [deg/h]_model"].to_numpy()
        temp = df["T1 [degC]"].to_numpy()
        fitted_slope = np.polyfit(temp, model, 1)[0]
        assert fitted_slope == pytest.approx(slope, rel=0.02), uid


def test_local_processes_and_this_process_agree_bit_for_bit(batch: Path, tmp_path: Path) -> None:
    one, two = tmp_path / "one", tmp_path / "two"
    main(["fleet", str(batch), "-o", str(one), "--workers", "1"])
    main(["fleet", str(batch), "-o", str(two), "--workers", "2"])
    for uid in SLOPES:
        assert _coefficients(one, uid) == _coefficients(two, uid)


def test_a_dask_cluster_gives_the_same_numbers(batch: Path, tmp_path: Path) -> None:
    distributed = pytest.importorskip("distributed")
    one, dask_out = tmp_path / "one", tmp_path / "dask"
    main(["fleet", str(batch), "-o", str(one), "--workers", "1"])
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0"
    ) as cluster:
        code = main(
            ["fleet", str(batch), "-o", str(dask_out), "--scheduler", cluster.scheduler_address]
        )
    assert code == fleet.EXIT_SOME_FAILED
    for uid in SLOPES:
        assert _coefficients(one, uid) == _coefficients(dask_out, uid)
    rows = pd.read_csv(dask_out / "summary.csv")
    assert dict(zip(rows["id"], rows["status"], strict=True))["bad"] == "failed"


def _interrupting(after: int, exc: BaseException) -> fleet.Executor:
    inner = fleet.local_executor(1)

    def run(tasks: list[fleet.UnitTask]) -> Any:
        for i, outcome in enumerate(inner(tasks)):
            if i == after:
                raise exc
            yield outcome

    return run


def test_an_interrupted_batch_resumes(batch: Path, tmp_path: Path) -> None:
    out = tmp_path / "out"
    cfg = fleet.load_config(batch)
    with pytest.raises(KeyboardInterrupt):
        fleet.run_fleet(cfg, out, executor=_interrupting(2, KeyboardInterrupt()))
    assert sorted(p.name for p in (out / "units").iterdir()) == ["u01", "u02"]
    # a dead worker pool: reported, the units done kept
    res = fleet.run_fleet(cfg, out, executor=_interrupting(1, BrokenProcessPool("killed")))
    assert res.interrupted is not None and "rerun to resume" in res.interrupted
    assert res.skipped == ("u01", "u02") and res.ran == ("u03",)
    # a half-written unit directory of a killed run is removed and the unit redone
    half = out / "units" / ".u04.tmp-deadbeef"
    half.mkdir()
    (half / "calibration.json").write_text("{")
    res = fleet.run_fleet(cfg, out)
    assert not half.exists()
    assert set(res.skipped) == {"u01", "u02", "u03"}
    assert set(res.ran) == {"u04", "u05", "u06", "bad", "gone"}  # the units not yet run
    rows = {r["id"]: r for r in res.rows}
    assert all(rows[u]["status"] == "ok" for u in SLOPES)
    assert rows["bad"]["status"] == rows["gone"]["status"] == "failed"
    # a plain rerun retries exactly the failed units (they ran and failed above)
    res = fleet.run_fleet(cfg, out)
    assert set(res.ran) == {"bad", "gone"} and set(res.skipped) == set(SLOPES)
    assert all("it failed before" in res.redone[u] for u in ("bad", "gone")), res.redone
    res = fleet.run_fleet(cfg, out, force=True)
    assert res.skipped == () and len(res.ran) == 8


def test_limits_pass_and_fail(batch: Path, tmp_path: Path) -> None:
    text = batch.read_text().replace(
        "rms_after_max = 0.05",
        'rms_after_max = 0.05\n[limits."gyro [deg/h]"]\nrms_residual_max = 0.0101',
    )
    batch.write_text(text)
    out = tmp_path / "out"
    res = fleet.run_fleet(fleet.load_config(batch), out)
    rows = {r["id"]: r for r in res.rows}
    residuals = {u: rows[u]["gyro [deg/h].rms_residual"] for u in SLOPES}
    for u, rms in residuals.items():
        assert rows[u]["pass"] is (rms <= 0.0101)
        if rms > 0.0101:
            assert "rms_residual" in rows[u]["fail_reasons"]
    assert any(r["pass"] is False for r in rows.values() if r["status"] == "ok")


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (("order = 1", "order = 1\nbogus = 3"), "not an option of thermocal fit"),
        (('id = "u02"', 'id = "u01"'), "used twice"),
        (("rms_after_max", "rms_aftr_max"), "not a limit"),
        (('[fit]\nmodel = "poly"', '[fitt]\nmodel = "poly"'), "unknown table"),
        (('id = "u03"', 'id = "../u03"'), "names a directory"),
        (("order = 1", 'order = "two"'), "Invalid value for '--order'"),
        (("order = 1", "order = [1, true]"), "Invalid value for '--order'"),
    ],
)
def test_bad_configurations_exit_2(
    batch: Path,
    tmp_path: Path,
    edit: tuple[str, str],
    message: str,
    capsys: pytest.CaptureFixture[str],
) -> None:
    batch.write_text(batch.read_text().replace(*edit, 1))
    code = main(["fleet", str(batch), "-o", str(tmp_path / "out")])
    assert code == 2
    assert message in capsys.readouterr().err
    assert not (tmp_path / "out").exists()


def test_robust_z_against_a_hand_computation() -> None:
    x = [1.0, 2.0, 3.0, 4.0, 100.0]
    # median 3, |x − 3| = 2, 1, 0, 1, 97 → MAD 1; z = 0.6745 (x − 3)
    assert fleet.robust_z(x) == pytest.approx([0.6745 * (v - 3.0) for v in x])
    assert all(math.isnan(z) for z in fleet.robust_z([2.0, 2.0, 2.0, 5.0]))  # MAD 0


def test_the_readme_configuration_is_valid(tmp_path: Path) -> None:
    readme = (Path(__file__).resolve().parents[2] / "README.md").read_text(encoding="utf-8")
    block = readme.split("```toml\n", 1)[1].split("```", 1)[0]
    cfg_path = tmp_path / "batch.toml"
    cfg_path.write_text(block, encoding="utf-8")
    cfg = fleet.load_config(cfg_path)
    assert [u.id for u in cfg.units] == ["SN0001", "SN0002"]
    assert cfg.fit_args[:4] == ("--model", "poly", "--order", "3")
    assert {lim.label for lim in cfg.limits} == {
        "rms_after ≤ 0.5",
        "condition_number ≤ 1e+06",
        "gz.bias_stability_after ≤ 0.05",
    }


def _slow_batch(folder: Path, prefix: str, seed: int) -> Path:
    """Eight units of 6·10⁵ rows (each a fraction of a second): a batch long enough for a
    signal or a kill to land in the middle of it.  Returns the configuration."""
    rng = np.random.default_rng(seed)
    n = 600_000
    t = np.arange(n, dtype=np.float64) * 0.1
    temp = np.linspace(-10.0, 60.0, n)
    lines = ['[fit]\nmodel = "poly"\norder = 1\nsignal = "gyro [deg/h]"\ntemps = "T1 [degC]"\n']
    for i in range(8):
        gyro = 1.0 + 0.02 * (temp - 25.0) + rng.normal(0.0, 0.01, n)
        frame = pd.DataFrame({"time [s]": t, "gyro [deg/h]": gyro, "T1 [degC]": temp})
        frame.to_parquet(folder / f"{prefix}{i}.parquet", index=False)
        lines.append(f'[[unit]]\nid = "{prefix}{i}"\nmodeling = ["{prefix}{i}.parquet"]\n')
    cfg = folder / f"{prefix}.toml"
    cfg.write_text("\n".join(lines), encoding="utf-8")
    return cfg


def _start_fleet_and_wait(cfg: Path, out: Path, *extra: str) -> Any:
    """``thermocal fleet CFG -o OUT --workers 2`` in a child process, returned once its first
    unit is written (or it has ended)."""
    import subprocess
    import sys
    import time

    cmd = [sys.executable, "-c", "import sys; from thermocal.cli import main; sys.exit(main())",
           "fleet", str(cfg), "-o", str(out), "--workers", "2", *extra]  # fmt: skip
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 120
    units = out / "units"
    while time.monotonic() < deadline and proc.poll() is None:
        if units.exists() and any(not p.name.startswith(".") for p in units.iterdir()):
            break
        time.sleep(0.02)
    return proc


def test_a_killed_worker_process_then_a_rerun(tmp_path: Path) -> None:
    """A real worker process killed mid-batch (SIGKILL) once the first unit is written: the
    units it may have held are rerun alone, each in a fresh process (issue 39: the batch
    stopped, "rerun to resume", the unit unnamed); none kills its process again, so the
    batch finishes, exit 0, no half-written unit is left, and a rerun skips them all."""
    import os
    import signal

    psutil = pytest.importorskip("psutil")
    cfg = _slow_batch(tmp_path, "k", seed=9)
    out = tmp_path / "out"
    proc = _start_fleet_and_wait(cfg, out, "--json")
    try:
        children = psutil.Process(proc.pid).children(recursive=True)
        workers = [c for c in children if "spawn_main" in " ".join(c.cmdline())]
        assert workers, "no worker processes"
        os.kill(workers[0].pid, signal.SIGKILL)  # one worker of the pool dies
        stdout, stderr = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 0, stderr + stdout
    assert "rerun to resume" not in stderr
    summary = json.loads(stdout)
    assert summary["pending"] == 0 and summary["failed"] == 0, summary
    assert not list((out / "units").glob(".*"))  # no half-written unit
    res = fleet.run_fleet(fleet.load_config(cfg), out)
    assert set(res.skipped) == {f"k{i}" for i in range(8)} and not res.ran
    assert all(r["status"] == "ok" for r in res.rows)


def test_scheduler_without_dask_says_how_to_install(
    batch: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    import sys

    monkeypatch.setitem(sys.modules, "distributed", None)  # as if not installed
    code = main(
        ["fleet", str(batch), "-o", str(tmp_path / "out"), "--scheduler", "tcp://127.0.0.1:1"]
    )
    err = capsys.readouterr().err
    assert code == 2
    assert err.count("\n") == 1 and "pip install 'thermocal[fleet]'" in err
    assert not (tmp_path / "out").exists()  # refused before anything is written


def test_ctrl_c_stops_the_batch_and_a_rerun_resumes(tmp_path: Path) -> None:
    """SIGINT to ``thermocal fleet`` with two worker processes, once a unit is written: exit
    130, the units written are complete, none is recorded as failed by the interruption,
    the workers are gone, and a rerun finishes the rest."""
    import os
    import signal

    psutil = pytest.importorskip("psutil")
    cfg = _slow_batch(tmp_path, "c", seed=4)
    out = tmp_path / "out"
    proc = _start_fleet_and_wait(cfg, out)
    try:
        children = psutil.Process(proc.pid).children(recursive=True)
        os.kill(proc.pid, signal.SIGINT)
        _stdout, stderr = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 130, stderr
    _gone, alive = psutil.wait_procs(children, timeout=10)
    assert alive == []  # the workers did not outlive the batch
    written = {p.name for p in (out / "units").iterdir() if not p.name.startswith(".")}
    for uid in written:
        assert fleet.read_unit(out, uid)["status"] == "ok"  # type: ignore[index]
    assert len(written) < 8
    res = fleet.run_fleet(fleet.load_config(cfg), out)
    assert set(res.skipped) == written and len(res.ran) == 8 - len(written)
    assert all(r["status"] == "ok" for r in res.rows)
