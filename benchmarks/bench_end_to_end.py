"""Benchmark: whole commands against what a user would run instead (issue 17).

Each figure is printed next to its anchor, measured in the same run, as a ratio:

* start-up: ``thermocal --version`` (also as ``python -m thermocal``), ``thermocal`` alone,
  ``thermocal --help`` and ``thermocal fit --help`` against ``python -c "import typer, rich"``
  (the floor), and against a one-command typer application's own ``--help`` (typer ≥ 0.28
  imports pydantic to coerce a command's options: a cost every typer command line pays);
  medians of 15 rounds, each running every command once (interleaved), with ``--before SRC``
  the same commands of an older tree in the same rounds; bytecode cached in a temporary
  folder for every interpreter, floor included, as an installed package has it
  (``--no-bytecode``: compiled at each start when ``PYTHONDONTWRITEBYTECODE`` is set);
* Allan end to end: ``thermocal allan FILE --signal ...`` (read + compute, octave τ, the
  table printed) against a three-line allantools script (pyarrow read of the two columns,
  ``1/median(diff(t))``, ``allantools.oadev(..., taus="octave")``) at 10⁷ and 10⁸ rows of
  a five-column Parquet file (time, rate, two temperatures, one unused column), read once
  beforehand so that both find it in the page cache; interleaved runs, best of 5 at 10⁷
  and of 2 at 10⁸;
* compensation of a 10⁸-row Parquet file (time, a gyro, a temperature; a linear model):
  ``thermocal compensate`` against a plain pyarrow read + write of the same columns plus
  one output column (``iter_batches`` → ``ParquetWriter``), wall time and peak resident
  memory of each process.

Run: ``.venv/bin/python benchmarks/bench_end_to_end.py [--skip-1e8] [--startup-only]
[--before OLD/src] [--runs 15] [--no-bytecode]``.  Files go to
``benchmarks/_data/`` (git-ignored; about 4 + 2.4 GB at 10⁸ rows, written once).
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from _harness import THERMOCAL, measure, write_allan_parquet

DATA = Path(__file__).resolve().parent / "_data"
PY = sys.executable


ALLANTOOLS_SCRIPT = r"""
import sys, numpy as np, pyarrow.parquet as pq, allantools
tab = pq.read_table(sys.argv[1], columns=["time [s]", "rate [deg/h]"])
t, y = tab.column(0).to_numpy(), tab.column(1).to_numpy()
taus, adev, err, n = allantools.oadev(y, rate=1.0 / np.median(np.diff(t)), data_type="freq",
                                      taus="octave")
print(len(taus), adev[0])
"""

PYARROW_SCRIPT = r"""
import sys, numpy as np, pyarrow as pa, pyarrow.parquet as pq
src, out = sys.argv[1], sys.argv[2]
pf = pq.ParquetFile(src, pre_buffer=False)
writer = None
for batch in pf.iter_batches(batch_size=500_000, columns=["time", "gyro", "T1"]):
    gyro = batch.column(1).to_numpy()
    temp = batch.column(2).to_numpy()
    comp = gyro - (0.5 + 0.02 * (temp - 25.0))
    table = pa.Table.from_batches([batch]).append_column("gyro_comp", pa.array(comp))
    if writer is None:
        writer = pq.ParquetWriter(out, table.schema, use_dictionary=False)
    writer.write_table(table)
writer.close()
"""

SPEED_FLOOR_SCRIPT = r"""
import typer
from typing import Annotated
app = typer.Typer(rich_markup_mode=None)
@app.command()
def one(x: Annotated[float, typer.Option("--x", help="A number.")] = 1.0) -> None:
    '''One command with one option.'''
@app.command()
def two() -> None:
    '''A second command, so that the first is a subcommand.'''
import sys
app(sys.argv[1:], prog_name="one")
"""


def run(cmd: list[str]) -> tuple[float, float]:
    """(wall seconds, peak resident MB) of one process."""
    return measure(cmd)


STARTUP_COMMANDS: dict[str, tuple[list[str], tuple[int, ...]]] = {
    "--version": ([*THERMOCAL, "--version"], (0,)),
    "-m --version": ([PY, "-m", "thermocal", "--version"], (0,)),
    "(no arguments)": ([*THERMOCAL], (0,)),  # its help, as --help
    "--help": ([*THERMOCAL, "--help"], (0,)),
    "fit --help": ([*THERMOCAL, "fit", "--help"], (0,)),
}
"""Each start-up figure: its command and the exit statuses it may end with (``thermocal``
alone prints the help as its one ``error:`` line, exit 2)."""


def _env(src: str | None, cache: str | None) -> dict[str, str]:
    """The children's environment: ``src`` first on the path (None: as inherited); with
    ``cache``, bytecode read from and written to that folder (``PYTHONPYCACHEPREFIX``), as
    an installed package has it compiled, for the floor and thermocal alike."""
    env = dict(os.environ)
    if src is not None:
        env["PYTHONPATH"] = src
    if cache is not None:
        env.pop("PYTHONDONTWRITEBYTECODE", None)
        env["PYTHONPYCACHEPREFIX"] = cache
    return env


def _once(cmd: list[str], env: dict[str, str], codes: tuple[int, ...]) -> float | None:
    """Wall seconds of one run, None when it ends with another status (the older tree
    without ``python -m thermocal``)."""
    t0 = time.perf_counter()
    res = subprocess.run(cmd, capture_output=True, env=env)
    dt = time.perf_counter() - t0
    return dt if res.returncode in codes else None


def startup(runs: int = 15, before: str | None = None, bytecode: bool = True) -> dict[str, float]:
    """Medians of ``runs`` interleaved rounds (floor, typer's own, every thermocal figure,
    the same of the ``before`` tree): one run of each per round, so that a change of load
    touches all alike."""
    with tempfile.TemporaryDirectory() as tmp:
        cache = str(Path(tmp) / "pycache") if bytecode else None
        mini = Path(tmp) / "mini.py"
        mini.write_text(SPEED_FLOOR_SCRIPT)
        jobs: dict[str, tuple[list[str], dict[str, str], tuple[int, ...]]] = {
            "floor": ([PY, "-c", "import typer, rich"], _env(None, cache), (0,)),
            "typer's own": ([PY, str(mini), "one", "--help"], _env(None, cache), (0,)),
        }
        trees = {"": None} if before is None else {"": None, " (before)": before}
        for suffix, src in trees.items():
            for name, (cmd, codes) in STARTUP_COMMANDS.items():
                jobs[name + suffix] = (cmd, _env(src, cache), codes)
        for cmd, env, codes in jobs.values():  # warm-up: bytecode written, files cached
            _once(cmd, env, codes)
        times: dict[str, list[float]] = {name: [] for name in jobs}
        for _ in range(runs):
            for name, (cmd, env, codes) in jobs.items():
                t = _once(cmd, env, codes)
                if t is not None:
                    times[name].append(t)
    med = {name: statistics.median(ts) for name, ts in times.items() if ts}
    floor, own = med["floor"], med["typer's own"]
    kind = "bytecode cached" if bytecode else "no bytecode (compiled at each start)"
    load = os.getloadavg()[0]
    print(f"start-up (medians of {runs} interleaved rounds, {kind}, load {load:.2f}):")
    print(f"  floor `import typer, rich` {floor:.3f} s; a one-option")
    print(f"  typer command's own --help {own:.3f} s ({own / floor:.2f}x the floor)")
    for name in jobs:
        if name in ("floor", "typer's own"):
            continue
        if name not in med:
            print(f"  thermocal {name:<26s} n/a (fails)")
            continue
        t = med[name]
        extra = f", {t / own:.2f}x typer's own" if name.startswith("fit --help") else ""
        print(f"  thermocal {name:<26s} {t:.3f} s = {t / floor:.2f}x the floor{extra}")
    ok = med["--version"] <= 1.1 * floor and med["--help"] <= 2 * floor
    print(f"  target (--version within 1.1x, --help within 2x the floor): "
          f"{'met' if ok else 'NOT met'}")  # fmt: skip
    return med


def allan_file(rows: int) -> Path:
    return write_allan_parquet(DATA / f"e2e_allan_{rows}.parquet", rows)


def warm(path: Path) -> None:
    """Read a file once so that both sides find it in the page cache (the first reader
    of a cold 4 GB file pays the disk, whichever it is)."""
    with open(path, "rb") as fh:
        while fh.read(1 << 24):
            pass


def allan(rows: int, repeat: int) -> float:
    path = allan_file(rows)
    warm(path)
    ours: list[tuple[float, float]] = []
    theirs: list[tuple[float, float]] = []
    with tempfile.TemporaryDirectory() as tmp:
        script = Path(tmp) / "allantools_script.py"
        script.write_text(ALLANTOOLS_SCRIPT)
        for _ in range(repeat):  # interleaved: a slow spell of the machine hits both
            ours.append(run([*THERMOCAL, "allan", str(path), "--signal", "rate [deg/h]"]))
            theirs.append(run([PY, str(script), str(path)]))
    t_ours, mb_ours = min(ours)
    t_theirs, mb_theirs = min(theirs)
    ratio = t_theirs / t_ours
    med = statistics.median(b[0] for b in theirs) / statistics.median(a[0] for a in ours)
    print(f"allan end to end, {rows:.0e} rows (best of {repeat}, interleaved):")
    print(f"  thermocal allan   {t_ours:7.2f} s  {mb_ours:7.0f} MB")
    print(f"  allantools script {t_theirs:7.2f} s  {mb_theirs:7.0f} MB")
    print(f"  speed-up {ratio:.2f}x (of the medians {med:.2f}x); target >= 3x: "
          f"{'met' if ratio >= 3 else 'NOT met'}")  # fmt: skip
    return ratio


def compensate(rows: int) -> tuple[float, float]:
    import pyarrow as pa
    import pyarrow.parquet as pq

    DATA.mkdir(exist_ok=True)
    path = DATA / f"e2e_comp_{rows}.parquet"
    if not path.exists():
        meta = {"format": "thermocal-recording", "version": 1, "time": "time",
                "time_unit": "s", "signals": {"gyro": "deg/h"},
                "temperatures": {"T1": "degC"}}  # fmt: skip
        fields = [(name, pa.float64()) for name in ("time", "gyro", "T1")]
        schema = pa.schema(fields).with_metadata({"thermocal": json.dumps(meta)})
        rng = np.random.default_rng(1)
        with pq.ParquetWriter(path, schema) as writer:  # written in slices: bounded memory
            step = 5_000_000
            for a in range(0, rows, step):
                t = np.arange(a, min(rows, a + step)) * 0.01
                temp = 25.0 + 15.0 * np.sin(2 * np.pi * t / (rows * 0.01))
                gyro = 0.5 + 0.02 * (temp - 25.0) + rng.normal(0.0, 0.05, t.size)
                writer.write_table(pa.table({"time": t, "gyro": gyro, "T1": temp}, schema=schema))
    model = DATA / "e2e_comp_model.json"
    small = DATA / "e2e_comp_fit.parquet"
    if not model.exists():
        pq.write_table(pq.ParquetFile(path).read_row_group(0).slice(0, 200_000), small)
        subprocess.run([*THERMOCAL, "fit", str(small), "--model", "poly", "--order", "1",
                        "--signal", "gyro", "--temps", "T1", "-o", str(model)],
                       check=True, capture_output=True)  # fmt: skip
    out = DATA / "e2e_comp_out.parquet"
    with tempfile.TemporaryDirectory() as tmp:
        script = Path(tmp) / "pyarrow_script.py"
        script.write_text(PYARROW_SCRIPT)
        t_pa, mb_pa = run([PY, str(script), str(path), str(out)])
        out.unlink(missing_ok=True)
        t_tc, mb_tc = run([*THERMOCAL, "compensate", str(model), str(path), "-o", str(out)])
        out.unlink(missing_ok=True)
    ratio = t_tc / t_pa
    print(f"compensate, {rows:.0e} rows (one run each):")
    print(f"  thermocal compensate  {t_tc:7.1f} s  {mb_tc:7.0f} MB")
    print(f"  pyarrow read + write  {t_pa:7.1f} s  {mb_pa:7.0f} MB")
    ok = ratio <= 1.5 and mb_tc <= 600
    print(f"  time ratio {ratio:.2f}x (target <= 1.5x), peak {mb_tc:.0f} MB (target <= 600 MB): "
          f"{'met' if ok else 'NOT met'}")  # fmt: skip
    return ratio, mb_tc


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--skip-1e8", action="store_true", help="only the start-up and 10⁷ figures")
    ap.add_argument("--startup-only", action="store_true", help="only the start-up figures")
    ap.add_argument("--runs", type=int, default=15, help="interleaved start-up rounds")
    ap.add_argument("--before", metavar="SRC", help="also time the package in SRC (a src/ folder)")
    ap.add_argument("--no-bytecode", action="store_true",
                    help="start-up compiling at each start (PYTHONDONTWRITEBYTECODE)")  # fmt: skip
    args = ap.parse_args()
    print(f"load average {os.getloadavg()[0]:.2f}, {os.cpu_count()} cores")
    startup(args.runs, args.before, not args.no_bytecode)
    print(f"load average at the end of the start-up {os.getloadavg()[0]:.2f}")
    if args.startup_only:
        return
    allan(10**7, repeat=5)
    if not args.skip_1e8:
        allan(10**8, repeat=2)
        compensate(10**8)


if __name__ == "__main__":
    main()
