"""Benchmark: the noise identification of phase data (issue 41, item 2), in-process, this
tree against another (``--before SRC``), side by side.

On the 10⁷-row phase file of ``bench_allan_cli.py`` (``angle [deg]``, written there once),
centred as :func:`thermocal.stability.family.stability` centres it, each child process
(one per side, alternated ``--repeat`` times; best CPU time of all) measures, with BLAS on
one thread as ``stability`` runs it:

* ``identify``: ``_Record.identify(m, dmax)`` at every octave m with at least 30 decimated
  points (dmax 2 for oadev/adev, 3 for hdev/ohdev), the record's factors planned as
  ``stability`` plans them;
* ``stability``: :func:`~thermocal.stability.family.stability` of the deviation, octave τ,
  the phase given up (``overwrite=True``, as the command does);

and prints the CPU milliseconds of each side and their ratio, and whether the two sides'
``to_dict()`` are equal.

Run::

    .venv/bin/python benchmarks/bench_phase_noise_id.py --before /tmp/old/src
    .venv/bin/python benchmarks/bench_phase_noise_id.py --deviations oadev,hdev --repeat 9
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

from _harness import write_allan_parquet

HERE = Path(__file__).resolve().parent
SRC = HERE.parent / "src"

CHILD = r"""
import json, sys, time
import numpy as np, pyarrow.parquet as pq
from threadpoolctl import threadpool_limits
from thermocal.stability import deviations as dv, family as fam
path, name, inner = sys.argv[1], sys.argv[2], int(sys.argv[3])
t = pq.read_table(path, columns=["angle [deg]"]).column(0).to_numpy()
dmax = 3 if name in ("hdev", "ohdev") else 2
best = {"identify": 9e9, "stability": 9e9}
with threadpool_limits(limits=1, user_api="blas"):
    x = dv.centred(t.copy(), inplace=True)
    ms = fam.factors("octave", 0.01, x.size // 2)
    for _ in range(inner):
        rec = fam._Record(x, [slice(0, x.size)], 0.01, "phase", [name])
        rec._centred = [x]
        rec.set_octave(ms)
        c = time.process_time()
        for m in ms.tolist():
            if x[::m].size >= 30:
                rec.identify(m, dmax)
        best["identify"] = min(best["identify"], time.process_time() - c)
        y = t.copy()
        c = time.process_time()
        r = fam.stability(y, 0.01, [name], "octave", data_type="phase", overwrite=True)
        best["stability"] = min(best["stability"], time.process_time() - c)
best["json"] = json.dumps(r.to_dict())
print(json.dumps(best))
"""


def child(src: Path, path: Path, name: str, inner: int) -> dict[str, float | str]:
    """One child's best times [s] and its result's JSON, run on the tree ``src``."""
    env = dict(os.environ, PYTHONPATH=str(src))
    out = subprocess.run(
        [sys.executable, "-c", CHILD, str(path), name, str(inner)],
        capture_output=True, text=True, env=env, check=True,
    )  # fmt: skip
    result: dict[str, float | str] = json.loads(out.stdout.strip().splitlines()[-1])
    return result


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--before", type=Path, required=True, help="the other tree's src")
    ap.add_argument("--deviations", default="oadev,adev,hdev,ohdev")
    ap.add_argument("--repeat", type=int, default=3, help="children per side (alternated)")
    ap.add_argument("--inner", type=int, default=3, help="repetitions inside each child")
    args = ap.parse_args()
    path = write_allan_parquet(
        HERE / "_data" / "allan_cli_10000000_phase.parquet", 10_000_000, "phase"
    )
    print(f"load average {os.getloadavg()[0]:.2f} at start; CPU ms, best of "
          f"{args.repeat}x{args.inner} per side")  # fmt: skip
    for name in args.deviations.split(","):
        best: dict[str, dict[str, float]] = {"before": {}, "after": {}}
        js: dict[str, str] = {}
        for _ in range(args.repeat):
            for side, src in (("before", args.before.resolve()), ("after", SRC)):
                got = child(src, path, name, args.inner)
                js[side] = str(got.pop("json"))
                for k, v in got.items():
                    best[side][k] = min(best[side].get(k, 9e9), float(v))
        b, a = best["before"], best["after"]
        print(
            f"{name:6s} identify {1e3 * b['identify']:6.1f} -> {1e3 * a['identify']:6.1f} ms "
            f"({b['identify'] / a['identify']:.2f}x) | stability {1e3 * b['stability']:6.1f} "
            f"-> {1e3 * a['stability']:6.1f} ms ({b['stability'] / a['stability']:.2f}x) | "
            f"to_dict equal: {js['before'] == js['after']}",
            flush=True,
        )
    print(f"load average {os.getloadavg()[0]:.2f} at end")


if __name__ == "__main__":
    main()
