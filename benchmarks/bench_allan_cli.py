"""Benchmark: ``thermocal allan`` end to end against the allantools script it replaces, for
every deviation of the family, rate and phase input (issue 41, items 2 and 3).

A Parquet file of ``--rows`` rows (default 10⁷; time [s], the signal, two temperatures and
one unused column, as ``bench_end_to_end.py`` writes) is written once per data type —
``rate [deg/h]`` for rate input, ``angle [deg]`` (its running sum times τ0) for
``--data-type phase`` — and read once beforehand so that every process finds it in the
page cache.  Then, for each deviation X and data type, interleaved (ours, theirs[,
before], ours, theirs …), best of ``--repeat``:

* ours: ``thermocal allan FILE --signal COL [--deviation X] [--data-type phase]``
  (``default`` is the plain command: overlapping ADEV, noise identification, Greenhall's
  EDF, intervals, noise terms and the table; ``oadev/stable32`` is ``--deviation oadev
  --noise-id stable32``, which must be no slower than ``--deviation oadev``);
* theirs: the script a user writes instead — a pyarrow read of the two columns,
  ``rate = 1/median(diff(t))``, ``allantools.X(y, rate, data_type=..., taus="octave")``
  (the default's anchor is ``allantools.oadev``);
* before (``--before SRC``): the same command run on another tree's ``src`` (e.g. ``git
  archive BASE src | tar -x -C /tmp/old``), so that a gain is the code's, not the machine's.

Every process's wall time, CPU time (user + system: the steadier figure on a loaded
machine) and peak resident memory come from :func:`_harness.measure_cpu`'s wrapper; each
side's best wall and best CPU time are compared (target ≥ 3× in both).  Memory per row is
``bench_memory.py``'s figure, ``(peak RSS at N rows − peak RSS of the same command at 10⁴
rows) / N``; target ≤ 40 B/row.

thermocal is an editable install here and the environment may set
``PYTHONDONTWRITEBYTECODE``: every child runs with byte-code caching on, into a cache
under ``benchmarks/_data/pycache*`` filled by a warm-up run, as an installed package's
``.pyc`` files are (allantools's are in site-packages).

Run::

    .venv/bin/python benchmarks/bench_allan_cli.py                 # every deviation, rate+phase
    .venv/bin/python benchmarks/bench_allan_cli.py --quick         # default, adev, hdev, totdev
    .venv/bin/python benchmarks/bench_allan_cli.py --rows 20000000 --memory-only
    .venv/bin/python benchmarks/bench_allan_cli.py --before /tmp/old/src

Files go to ``benchmarks/_data/`` (git-ignored; 0.4 GB per data type at 10⁷ rows).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

from _harness import ALLAN_COLUMNS, THERMOCAL, measure_cpu, write_allan_parquet

HERE = Path(__file__).resolve().parent
DATA = HERE / "_data"
SRC = HERE.parent / "src"
PY = sys.executable
TINY = 10_000
"""Rows of the memory baseline's file."""

COLUMN = ALLAN_COLUMNS
DEVIATIONS = ["default", "oadev", "oadev/stable32", "adev", "mdev", "tdev", "hdev", "ohdev",
              "totdev", "tierms"]  # fmt: skip
QUICK = ["default", "adev", "hdev", "totdev"]

SCRIPT = r"""
import sys, numpy as np, pyarrow.parquet as pq, allantools
path, column, dev, data_type = sys.argv[1:5]
tab = pq.read_table(path, columns=["time [s]", column])
t, y = tab.column(0).to_numpy(), tab.column(1).to_numpy()
out = getattr(allantools, dev)(y, rate=1.0 / np.median(np.diff(t)), data_type=data_type,
                               taus="octave")
print(len(out[0]), out[1][0])
"""


def write_file(rows: int, data_type: str) -> Path:
    """The benchmark's Parquet file (written once, :func:`_harness.write_allan_parquet`)."""
    return write_allan_parquet(DATA / f"allan_cli_{rows}_{data_type}.parquet", rows, data_type)


def warm(path: Path) -> None:
    """Read the file once: every process then finds it in the page cache."""
    with open(path, "rb") as fh:
        while fh.read(1 << 24):
            pass


def child_env(src: Path, cache: str) -> dict[str, str]:
    """The environment of a child: ``src`` imported, byte code cached under ``cache``."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    env["PYTHONPATH"] = str(src)
    env["PYTHONPYCACHEPREFIX"] = str(DATA / cache)
    return env


def measure(cmd: list[str], env: dict[str, str]) -> tuple[float, float, float]:
    """(wall seconds, peak resident MB, CPU seconds) of one child process
    (:func:`_harness.measure_cpu`); a failure stops the benchmark."""
    return measure_cpu(cmd, env)


def ours(path: Path, data_type: str, dev: str) -> list[str]:
    """thermocal's command line for one deviation."""
    cmd = [*THERMOCAL, "allan", str(path), "--signal", COLUMN[data_type]]
    if data_type == "phase":
        cmd += ["--data-type", "phase"]
    if dev == "oadev/stable32":
        cmd += ["--deviation", "oadev", "--noise-id", "stable32"]
    elif dev != "default":
        cmd += ["--deviation", dev]
    return cmd


def theirs(script: Path, path: Path, data_type: str, dev: str) -> list[str]:
    """The allantools script's command line for one deviation."""
    name = "oadev" if dev in ("default", "oadev/stable32") else dev
    kind = "freq" if data_type == "rate" else "phase"
    return [PY, str(script), str(path), COLUMN[data_type], name, kind]


def _numbers(a: object, b: object, where: str, worst: list[tuple[float, str]]) -> None:
    """Walk two JSON values side by side: the largest relative difference of their numbers
    into ``worst``; any other difference (keys, texts, lengths) is printed."""
    if isinstance(a, dict) and isinstance(b, dict):
        if a.keys() != b.keys():
            print(f"  {where}: keys differ: {sorted(set(a) ^ set(b))}")
        for k in a.keys() & b.keys():
            _numbers(a[k], b[k], f"{where}.{k}", worst)
    elif isinstance(a, list) and isinstance(b, list) and len(a) == len(b):
        for i, (u, v) in enumerate(zip(a, b, strict=True)):
            _numbers(u, v, f"{where}[{i}]", worst)
    elif isinstance(a, float | int) and isinstance(b, float | int) and a != b:
        rel = abs(a - b) / max(abs(a), abs(b))
        worst.append((rel, f"{where}: {a!r} / {b!r}"))
    elif type(a) is not type(b) or (not isinstance(a, float | int | list | dict) and a != b):
        print(f"  {where}: {str(a)[:80]!r} != {str(b)[:80]!r}")


def compare_json(args: argparse.Namespace, envs: dict[str, dict[str, str]], devs: list[str],
                 kinds: list[str]) -> None:  # fmt: skip
    """``allan --json`` of this tree and of ``--before`` on a ``--rows`` file, for every
    deviation and data type: identical, or the largest relative difference of a number."""
    print(f"allan --json, this tree against {args.before}, {args.rows:.0e} rows:")
    for kind in kinds:
        path = write_file(args.rows, kind)
        for dev in devs:
            got = {}
            for side in ("ours", "before"):
                res = subprocess.run([*ours(path, kind, dev), "--json"], capture_output=True,
                                     text=True, env=envs[side], check=True)  # fmt: skip
                got[side] = json.loads(res.stdout)
            worst: list[tuple[float, str]] = []
            _numbers(got["before"], got["ours"], "", worst)
            if not worst:
                print(f"  {kind:<6s}{dev:<15s} identical")
            else:
                rel, what = max(worst)
                print(
                    f"  {kind:<6s}{dev:<15s} {len(worst)} numbers differ, largest relative "
                    f"{rel:.2e} ({what}){'' if rel <= 1e-12 else '  ABOVE 1e-12'}"
                )


def load() -> str:
    return f"{os.getloadavg()[0]:.2f}"


def run_one(
    args: argparse.Namespace, script: Path, data_type: str, dev: str, envs: dict[str, dict]
) -> dict[str, tuple[float, float, float]]:
    """One row of the table: interleaved runs, best of ``args.repeat`` (wall and CPU each
    its own best; memory the wall-best run's)."""
    path = write_file(args.rows, data_type)
    tiny = write_file(TINY, data_type)
    best: dict[str, tuple[float, float]] = {}
    cpu: dict[str, float] = {}
    sides = ["ours", "theirs", *(["before"] if "before" in envs else [])]
    if args.memory_only:
        sides = ["ours", *(["before"] if "before" in envs else [])]
    for _ in range(args.repeat):
        for side in sides:
            if side == "theirs":
                wall, mb, c = measure(theirs(script, path, data_type, dev), envs["ours"])
            else:
                wall, mb, c = measure(ours(path, data_type, dev), envs[side])
            best[side] = min(best.get(side, (wall, mb)), (wall, mb))
            cpu[side] = min(cpu.get(side, c), c)
    base = {s: measure(ours(tiny, data_type, dev), envs[s])[1] for s in sides if s != "theirs"}
    t_o, mb_o = best["ours"]
    per_row = (mb_o - base["ours"]) * 1024 * 1024 / args.rows
    line = f"{data_type:<6s}{dev:<15s}{t_o:6.2f} s {cpu['ours']:5.2f} cpu {mb_o:5.0f} MB"
    line += f" {per_row:5.1f} B/row"
    if "theirs" in best:
        t_t, mb_t = best["theirs"]
        ratio, c_ratio = t_t / t_o, cpu["theirs"] / cpu["ours"]
        line += f" | allantools {t_t:6.2f} s {cpu['theirs']:5.2f} cpu {mb_t:5.0f} MB"
        line += f" | {ratio:5.2f}x wall {c_ratio:5.2f}x cpu"
        line += " met" if min(ratio, c_ratio) >= 3 else " NOT met"
    if "before" in best:
        t_b, mb_b = best["before"]
        pr_b = (mb_b - base["before"]) * 1024 * 1024 / args.rows
        line += f" | before {t_b:6.2f} s {cpu['before']:5.2f} cpu {mb_b:5.0f} MB {pr_b:5.1f} B/row"
        line += f" ({t_b / t_o:4.2f}x wall {cpu['before'] / cpu['ours']:4.2f}x cpu)"
    line += f" | mem {'met' if per_row <= 40 else 'NOT met'} | load {load()}"
    print(line, flush=True)
    return {s: (*best[s], cpu[s]) for s in sides}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rows", type=int, default=10_000_000)
    ap.add_argument("--repeat", type=int, default=3, help="best of this many (default 3)")
    ap.add_argument("--quick", action="store_true", help=f"rate input, {', '.join(QUICK)}")
    ap.add_argument("--deviations", help="comma-separated, of " + ", ".join(DEVIATIONS))
    ap.add_argument("--data-types", default="rate,phase")
    ap.add_argument("--before", type=Path, help="another tree's src, run side by side")
    ap.add_argument("--ours", type=Path, default=SRC, help="the src measured (default this tree's)")
    ap.add_argument("--memory-only", action="store_true", help="no allantools runs")
    ap.add_argument(
        "--compare-json",
        action="store_true",
        help="with --before: compare the --json outputs instead of timing",
    )
    args = ap.parse_args()
    devs = QUICK if args.quick else DEVIATIONS
    if args.deviations:
        devs = args.deviations.split(",")
    kinds = ["rate"] if args.quick else args.data_types.split(",")
    envs = {"ours": child_env(args.ours.resolve(), "pycache")}
    if args.before is not None:
        envs["before"] = child_env(args.before.resolve(), "pycache_before")
    if args.compare_json:
        if args.before is None:
            raise SystemExit("--compare-json needs --before")
        compare_json(args, envs, devs, kinds)
        return
    print(f"load average {load()} at start, {os.cpu_count()} cores, {args.rows:.0e} rows, "
          f"best of {args.repeat}, interleaved")  # fmt: skip
    with tempfile.TemporaryDirectory() as tmp:
        script = Path(tmp) / "allantools_script.py"
        script.write_text(SCRIPT)
        for kind in kinds:
            warm(write_file(args.rows, kind))
            for env in envs.values():  # fill the byte-code cache
                measure(ours(write_file(TINY, kind), kind, "default"), env)
            print(
                f"{'input':<6s}{'deviation':<15s} thermocal (wall, CPU, peak, above 10⁴ rows) "
                "| anchor | ratios, target >= 3x | before | memory target <= 40 B/row"
            )
            for dev in devs:
                run_one(args, script, kind, dev, envs)
    print(f"load average {load()} at end")


if __name__ == "__main__":
    main()
