"""A new file format from a package of its own, through the one registration the recipe of
ARCHITECTURE.md names ("A new file format"): an entry point of group ``thermocal.formats``.

The test writes, in ``tmp_path``, a tiny package (a reader of a made-up ``.toy`` format) and
its ``*.dist-info/entry_points.txt``, then runs the command line in a subprocess with that
folder on ``PYTHONPATH``, as a user who ``pip install``\\ ed the package would.  Every number
asserted is computed here from the toy data (numpy), never by thermocal.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import thermocal

RATE_HZ = 10.0
N = 2000
SLOPE = 3.0  # °/h per °C
NOISE = 0.1  # °/h

TOY_READER = '''\
"""A reader of the made-up toy format: a line ``TOY rate=HZ``, then one sample a line,
``rate;temperature`` (°/h; °C)."""

from pathlib import Path

import numpy as np
import pandas as pd

from thermocal.readers.formats import FileFormat


def read_toy(path: Path, read):
    lines = path.read_text(encoding="utf-8").splitlines()
    rate = float(lines[0].split("=")[1])
    rows = np.array([[float(v) for v in ln.split(";")] for ln in lines[1:] if ln.strip()])
    table = pd.DataFrame(
        {"time": np.arange(len(rows)) / rate, "gx": rows[:, 0], "T": rows[:, 1]}
    )
    return table, {"time": "time", "time_unit": "s", "signals": {"gx": "deg/h"},
                   "temperatures": {"T": "degC"}}


FORMAT = FileFormat("toy", "a toy logger's file", read_toy, suffixes=(".toy",))
PACKED = FileFormat("toyz", "a packed toy file", read_toy, suffixes=(".toyz",), chunks="none")
'''


def _package(folder: Path, entry_points: str, name: str = "toy_reader") -> None:
    """A module and its distribution's metadata, as ``pip install`` leaves them."""
    folder.mkdir(parents=True, exist_ok=True)
    (folder / f"{name}.py").write_text(TOY_READER, encoding="utf-8")
    info = folder / f"{name}-1.0.dist-info"
    info.mkdir()
    (info / "METADATA").write_text(
        f"Metadata-Version: 2.1\nName: {name.replace('_', '-')}\nVersion: 1.0\n", encoding="utf-8"
    )
    (info / "entry_points.txt").write_text(entry_points, encoding="utf-8")


@pytest.fixture(scope="module")
def toy(tmp_path_factory: pytest.TempPathFactory) -> dict[str, object]:
    d = tmp_path_factory.mktemp("toy")
    _package(
        d / "site",
        "[thermocal.formats]\ntoy = toy_reader:FORMAT\ntoyz = toy_reader:PACKED\n",
    )
    rng = np.random.default_rng(0)
    temp = np.linspace(15.0, 45.0, N)
    gx = 50.0 + SLOPE * (temp - 25.0) + rng.normal(0.0, NOISE, N)
    body = "".join(f"{a:.6f};{b:.6f}\n" for a, b in zip(gx, temp, strict=True))
    (d / "run.toy").write_text(f"TOY rate={RATE_HZ:g}\n{body}", encoding="utf-8")
    (d / "run.toyz").write_text(f"TOY rate={RATE_HZ:g}\n{body}", encoding="utf-8")
    # the values as the file holds them (6 decimals), read back by numpy, not by thermocal
    data = np.loadtxt(d / "run.toy", delimiter=";", skiprows=1)
    return {"dir": d, "site": d / "site", "gx": data[:, 0], "T": data[:, 1]}


def _run(folder: Path, site: list[Path], *args: str) -> subprocess.CompletedProcess[str]:
    src = Path(thermocal.__file__).resolve().parents[1]
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(src), *map(str, site)])}
    code = "import sys; from thermocal.cli import main; sys.exit(main())"
    return subprocess.run(
        [sys.executable, "-c", code, *args],
        cwd=folder,
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )


def test_inspect_reads_the_toy_format(toy: dict[str, object]) -> None:
    d, site = toy["dir"], toy["site"]
    assert isinstance(d, Path) and isinstance(site, Path)
    gx = np.asarray(toy["gx"])
    proc = _run(d, [site], "inspect", "run.toy", "--json")
    assert proc.returncode == 0, proc.stderr
    out = json.loads(proc.stdout)
    assert out["n_samples"] == N
    assert out["sample_rate_hz"] == pytest.approx(RATE_HZ, rel=1e-12)
    assert out["duration_s"] == pytest.approx((N - 1) / RATE_HZ, rel=1e-12)
    col = out["columns"]["gx"]
    assert (col["role"], col["unit"]) == ("signal", "deg/h")
    assert col["min"] == pytest.approx(gx.min(), abs=1e-9)
    assert col["max"] == pytest.approx(gx.max(), abs=1e-9)
    assert col["mean"] == pytest.approx(gx.mean(), rel=1e-9)
    assert out["columns"]["T"]["role"] == "temperature"


def test_metrics_and_allan_read_the_toy_format(toy: dict[str, object]) -> None:
    d, site = toy["dir"], toy["site"]
    assert isinstance(d, Path) and isinstance(site, Path)
    gx = np.asarray(toy["gx"])
    proc = _run(d, [site], "metrics", "run.toy", "--signal", "gx", "--json")
    assert proc.returncode == 0, proc.stderr
    out = json.loads(proc.stdout)
    assert out["unit"] == "deg/h"
    assert out["bias"] == pytest.approx(gx.mean(), rel=1e-9)
    assert out["peak_to_peak"] == pytest.approx(gx.max() - gx.min(), rel=1e-9)
    proc = _run(d, [site], "allan", "run.toy", "--signal", "gx", "--json")
    assert proc.returncode == 0, proc.stderr
    out = json.loads(proc.stdout)
    # overlapping ADEV at τ0 (IEEE Std 952-1997): σ² = Σ (y[i+1] − y[i])² / (2 (N − 1))
    adev_tau0 = np.sqrt(np.sum(np.diff(gx) ** 2) / (2 * (N - 1)))
    assert out["tau_s"][0] == pytest.approx(1.0 / RATE_HZ, rel=1e-12)
    assert out["adev"][0] == pytest.approx(adev_tau0, rel=1e-9)


def test_fit_and_compensate_the_toy_format(toy: dict[str, object]) -> None:
    d, site = toy["dir"], toy["site"]
    assert isinstance(d, Path) and isinstance(site, Path)
    gx, temp = np.asarray(toy["gx"]), np.asarray(toy["T"])
    proc = _run(d, [site], "fit", "run.toy", "--signal", "gx", "--temps", "T", "--model",
                "poly", "--order", "1", "-o", "m.json", "--json")  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    proc = _run(d, [site], "compensate", "m.json", "run.toy", "-o", "comp.csv", "--json")
    assert proc.returncode == 0, proc.stderr
    out = json.loads(proc.stdout)
    assert out["n_rows"] == N
    got = pd.read_csv(d / "comp.csv")
    np.testing.assert_allclose(got["gx"].to_numpy(), gx, rtol=0, atol=1e-12)
    # a straight line in T by least squares (numpy), removed: the residual is the noise
    resid = gx - np.polyval(np.polyfit(temp, gx, 1), temp)
    comp = got["gx_comp"].to_numpy()
    assert np.std(comp) == pytest.approx(np.std(resid), rel=1e-6)
    assert out["rms_after"] == pytest.approx(np.std(resid), rel=1e-6)
    assert np.std(resid) == pytest.approx(NOISE, rel=0.1)


def test_compensate_refuses_a_format_it_cannot_read_in_chunks(toy: dict[str, object]) -> None:
    """A registered format declared ``chunks="none"`` and a suffix no format has: exit 2,
    one ``error:`` line naming the file, never read as CSV."""
    d, site = toy["dir"], toy["site"]
    assert isinstance(d, Path) and isinstance(site, Path)
    proc = _run(d, [site], "fit", "run.toy", "--signal", "gx", "--temps", "T", "--model",
                "poly", "--order", "1", "-o", "m2.json")  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    proc = _run(d, [site], "compensate", "m2.json", "run.toyz", "-o", "z.csv")
    assert proc.returncode == 2, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1
    assert lines[0].startswith("error: run.toyz: a packed toy file (toyz format) cannot be read")
    assert "write it as CSV or Parquet first" in lines[0]
    assert not (d / "z.csv").exists()
    (d / "run.xyz").write_text("time,gx,T\n0,1,20\n0.1,1,20\n", encoding="utf-8")
    proc = _run(d, [site], "compensate", "m2.json", "run.xyz", "-o", "x.csv")
    assert proc.returncode == 2, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1
    assert lines[0].startswith("error: run.xyz: not a CSV or Parquet file")
    assert ".toy for a toy logger's file" in lines[0]  # the installed formats are listed
    assert not (d / "x.csv").exists()


def test_a_broken_plugin_is_one_warning_and_skipped(toy: dict[str, object]) -> None:
    d, site = toy["dir"], toy["site"]
    assert isinstance(d, Path) and isinstance(site, Path)
    broken = d / "broken"
    _package(broken, "[thermocal.formats]\nbad = no_such_module:FORMAT\n", name="bad_reader")
    proc = _run(d, [site, broken], "inspect", "run.toy", "--json")
    assert proc.returncode == 0, proc.stderr
    assert json.loads(proc.stdout)["n_samples"] == N
    warned = [ln for ln in proc.stderr.splitlines() if "file-format plugin 'bad'" in ln]
    assert len(warned) == 1
    assert warned[0].startswith("warning: ")
    assert "ModuleNotFoundError" in warned[0] and "skipped" in warned[0]


def test_a_built_in_format_never_looks_at_the_installed_packages(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A name a built-in format claims is looked up without reading any package's metadata
    (``importlib.metadata``: 10–30 ms a run); another name, or the list of every format,
    reads it once."""
    from thermocal.errors import FileFormatError
    from thermocal.readers import formats

    scans: list[int] = []
    monkeypatch.setattr(formats, "_plugin_formats", lambda: scans.append(1) or [])
    formats._plugins.cache_clear()
    try:
        names = [formats.format_of(p).name for p in ("a.parquet", "b.CSV.gz", "c.ulg", "d.bin")]
        assert names == ["parquet", "csv", "ulog", "dataflash"]
        assert formats.file_kind("e.mcap") == "rosbag"
        assert formats.file_suffix("f.pq") == ".pq"
        assert formats.format_named("csv").name == "csv"
        assert scans == []
        with pytest.raises(FileFormatError, match="not a CSV or Parquet file"):
            formats.format_of("g.toy")
        assert scans == [1]
        assert [f.name for f in formats.registered_formats()] == [f.name for f in formats.BUILT_IN]
        assert scans == [1]  # once a process
    finally:
        formats._plugins.cache_clear()


def test_reading_parquet_imports_no_package_metadata(tmp_path: Path) -> None:
    """A fresh interpreter reads a Parquet recording without importing
    ``importlib.metadata`` (the plugin scan's import)."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    path = tmp_path / "r.parquet"
    t = np.arange(100) * 0.1
    pq.write_table(pa.table({"time": t, "gx": np.sin(t)}), path)
    code = (
        "import sys; from thermocal.readers import ReadOptions, read_recording; "
        f"rec = read_recording({str(path)!r}, ReadOptions(signals=['gx'])); "
        "print(rec.n_samples, 'importlib.metadata' in sys.modules)"
    )
    src = Path(thermocal.__file__).resolve().parents[1]
    proc = subprocess.run(
        [sys.executable, "-c", code], env={**os.environ, "PYTHONPATH": str(src)},
        capture_output=True, text=True, timeout=300, check=False,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.split() == ["100", "False"]
