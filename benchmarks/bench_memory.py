"""Benchmark: peak memory of whole commands against the length of the file (issues 14, 26,
41).

For each size (rows) a Parquet recording is written once — time [s], one gyro [°/h] and
``--temps`` temperatures T1…Tk [°C], all float64, units in the file's metadata — and
``inspect``, ``metrics``, ``allan``, ``fit`` (plain polynomial, ``--order 2``) and
``compensate`` run on it, each as its own ``thermocal`` process
(:func:`benchmarks._harness.measure`: the peak resident memory of that one child).

The figure (issue 26, item 8)::

    bytes per row = (peak RSS on the N-row file − peak RSS of the same command on a
                     10 000-row file) / N

The baseline (the interpreter, numpy, pyarrow, scipy … and whatever the command holds
that does not grow with the file) is measured the same way, so what is left is what the
command holds per row of the file.  It is printed as bytes per row and, divided by the
number of columns the command uses (time, signal and temperatures; allan: time and
signal), as bytes per value.  Target (issue 41, item 3): **≤ 40 bytes per row for every
command**, whatever the number of columns (four temperatures are 48 B of float64 data a
row: a command meets it only by not holding every column at once).  The earlier,
column-based figure ``max(40, 16 + 8 × columns)`` B/row (issue 26) is printed beside it.
``compensate`` streams its file: its target is a constant, ≤ 200 MB above its baseline
whatever the length (printed as B/row at that length).

Run: ``.venv/bin/python benchmarks/bench_memory.py [--rows 10000000 20000000] [--temps 1 4]
[--before OLD/src] [--repeat N] [--quick]``.  ``--repeat N`` runs each command N times, the
trees interleaved (after, before, after, before …), and prints the best time and the
smallest peak of each.
Files go to ``benchmarks/_data/`` (git-ignored); a file of 2·10⁷ rows and four
temperatures is 0.9 GB.
"""

from __future__ import annotations

import argparse
import json
import os
from pathlib import Path

import numpy as np

from _harness import THERMOCAL, measure

DATA = Path(__file__).resolve().parent / "_data"
TINY = 10_000
"""Rows of the baseline file."""
WORKING_B_PER_ROW = 16
"""Bytes a row of working space the target allows above the columns used."""


def write_file(rows: int, n_temps: int) -> Path:
    """The recording (written once, in slices: bounded memory)."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    path = DATA / f"mem_{rows}_{n_temps}t.parquet"
    if path.exists():
        return path
    DATA.mkdir(exist_ok=True)
    rng = np.random.default_rng(1)
    temps = [f"T{k + 1}" for k in range(n_temps)]
    meta = {
        "format": "thermocal-recording",
        "version": 1,
        "time": "time",
        "time_unit": "s",
        "signals": {"gyro": "deg/h"},
        "temperatures": dict.fromkeys(temps, "degC"),
    }
    schema = pa.schema([(c, pa.float64()) for c in ("time", "gyro", *temps)]).with_metadata(
        {"thermocal": json.dumps(meta)}
    )
    span = max((rows - 1) * 0.01, 1.0)
    tmp = path.with_suffix(".tmp")
    with pq.ParquetWriter(tmp, schema) as w:
        for a in range(0, rows, 1 << 20):
            t = np.arange(a, min(rows, a + (1 << 20)), dtype=np.float64) * 0.01
            base = 25.0 + 15.0 * np.sin(2 * np.pi * t / span)
            cols = {"time": t}
            # each sensor its own lag: no temperature a linear combination of the others
            ts = [base + 0.4 * k * np.sin(2 * np.pi * (k + 1) * t / span) for k in range(n_temps)]
            cols["gyro"] = 0.5 + 0.02 * (ts[0] - 25.0) + rng.normal(0.0, 0.05, t.size)
            cols.update(zip(temps, ts, strict=True))
            w.write_table(pa.table(cols, schema=schema))
    tmp.rename(path)
    return path


def commands(src: Path, n_temps: int, out: Path) -> dict[str, tuple[list[str], int]]:
    """name → (thermocal arguments, number of columns used)."""
    temps = ",".join(f"T{k + 1}" for k in range(n_temps))
    model = DATA / f"mem_model_{n_temps}t.json"
    return {
        "inspect": (["inspect", str(src), "--json"], 2 + n_temps),
        "metrics": (["metrics", str(src), "--signal", "gyro", "--temps", temps,
                     "--average", "10", "--json"], 2 + n_temps),
        "allan": (["allan", str(src), "--signal", "gyro", "--json"], 2),
        "fit": (["fit", str(src), "--model", "poly", "--order", "2", "--signal", "gyro",
                 "--temps", temps, "--allow-narrow", "-o", str(out.with_suffix(".json")),
                 "--json"], 2 + n_temps),
        "compensate": (["compensate", str(model), str(src), "-o", str(out)], 0),
    }  # fmt: skip


COMPENSATE_MB = 200.0
"""``compensate`` streams its file: at most this much above its baseline, whatever the
length (its chunks and the writer's buffers)."""


TARGET_B_PER_ROW = 40.0
"""Bytes a row above the baseline allowed to every command (issue 41, item 3)."""


def target(name: str, n_cols: int, rows: int) -> float:
    """Bytes a row allowed above the baseline: :data:`TARGET_B_PER_ROW` for every command;
    for ``compensate`` the constant :data:`COMPENSATE_MB` spread over the rows."""
    if name == "compensate":
        return COMPENSATE_MB * 1024 * 1024 / rows
    return TARGET_B_PER_ROW


def column_target(name: str, n_cols: int, rows: int) -> float:
    """The earlier, column-based figure (issue 26): 40 B a row of the columns used, and
    8 B more for every column beyond three (``max(40, 16 + 8 × columns)``)."""
    if name == "compensate":
        return target(name, n_cols, rows)
    return max(40.0, WORKING_B_PER_ROW + 8.0 * n_cols)


def _row(
    tree: str,
    rows: int,
    n_temps: int,
    name: str,
    n_cols: int,
    measured: tuple[float, float],
    base_mb: float,
) -> str:
    """One line of the table."""
    seconds, mb = measured
    per_row = (mb - base_mb) * 1024 * 1024 / rows
    per_value = per_row / n_cols if n_cols else float("nan")
    goal, old = target(name, n_cols, rows), column_target(name, n_cols, rows)
    verdict = "met" if per_row <= goal else "NOT met"
    was = "met" if per_row <= old else "NOT met"
    return (f"{tree:<6s} {rows:>10d} {n_temps:>2d} {name:<11s} {mb:8.0f} {base_mb:8.0f} "
            f"{per_row:7.1f} {n_cols:>4d} {per_value:7.1f} {seconds:6.1f}  "
            f"target ≤ {goal:.0f} B/row: {verdict}  (columns ≤ {old:.0f}: {was})")  # fmt: skip


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rows", type=int, nargs="+", default=[10_000_000, 20_000_000])
    ap.add_argument("--temps", type=int, nargs="+", default=[1, 4], help="temperature columns")
    ap.add_argument("--only", nargs="*", help="commands to run (default all)")
    ap.add_argument("--quick", action="store_true", help="10⁶ rows only (a few minutes)")
    ap.add_argument("--repeat", type=int, default=1, help="runs of each command and tree, "
                    "interleaved: the best time and the smallest peak")  # fmt: skip
    ap.add_argument("--before", metavar="SRC", help="also run the package under SRC (an older "
                    "tree's src/), each command interleaved with this one")  # fmt: skip
    args = ap.parse_args()
    if args.quick:
        args.rows = [1_000_000]
    trees: dict[str, list[str]] = {"after": THERMOCAL}
    if args.before:
        trees["before"] = ["env", f"PYTHONPATH={args.before}", *THERMOCAL]
    print(f"load average at start: {os.getloadavg()[0]:.2f}")
    print(f"{'tree':<6s} {'rows':>10s} {'T':>2s} {'command':<11s} {'peak MB':>8s} {'base MB':>8s} "
          f"{'B/row':>7s} {'cols':>4s} {'B/value':>7s} {'s':>6s}  target")  # fmt: skip
    for n_temps in args.temps:
        tiny = write_file(TINY, n_temps)
        model = DATA / f"mem_model_{n_temps}t.json"
        if not model.exists():
            fit_src = write_file(100_000, n_temps)
            temps = ",".join(f"T{k + 1}" for k in range(n_temps))
            measure([*THERMOCAL, "fit", str(fit_src), "--model", "poly", "--order", "1",
                     "--signal", "gyro", "--temps", temps, "--allow-narrow",
                     "-o", str(model)])  # fmt: skip
        out_tiny = DATA / "mem_out_tiny.parquet"
        base: dict[tuple[str, str], float] = {}
        for name, (cmd, _cols) in commands(tiny, n_temps, out_tiny).items():
            if args.only and name not in args.only:
                continue
            for tree, prefix in trees.items():
                base[tree, name] = measure([*prefix, *cmd])[1]
                out_tiny.unlink(missing_ok=True)
        for rows in args.rows:
            src = write_file(rows, n_temps)
            out = DATA / f"mem_out_{rows}.parquet"
            for name, (cmd, n_cols) in commands(src, n_temps, out).items():
                if ("after", name) not in base:
                    continue
                best: dict[str, tuple[float, float]] = {}
                for _ in range(max(args.repeat, 1)):
                    for tree, prefix in trees.items():  # interleaved: after, before
                        s, mb = measure([*prefix, *cmd])
                        out.unlink(missing_ok=True)
                        out.with_suffix(".json").unlink(missing_ok=True)
                        was = best.get(tree, (s, mb))
                        best[tree] = (min(was[0], s), min(was[1], mb))
                for tree in trees:
                    print(_row(tree, rows, n_temps, name, n_cols, best[tree], base[tree, name]),
                          flush=True)  # fmt: skip
    print(f"load average at end: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
