"""CPU time of ``noise_terms`` (the least-squares fit with the Allan variances' covariance
across τ, and the slope lines) on one simulated record, octave and log τ, side by side with
another source tree (``--before SRC``: a ``git archive`` of main), interleaved, best of five.

    PYTHONPATH=src python benchmarks/bench_noise_terms.py --before /tmp/before/src
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys

CHILD = """
import json, time, numpy as np
from thermocal.simulate.noise import NoiseParams, simulate_noise
from thermocal.stability.allan import noise_terms, overlapping_adev
noise = NoiseParams(white_density=1.0, bias_instability=0.3, rate_random_walk=0.01)
y = simulate_noise(2_000_000, 0.01, noise, np.random.default_rng(0))
out = {}
for taus in ("octave", "log"):
    r = overlapping_adev(y, 0.01, taus)
    best = float("inf")
    for _ in range(5):
        t = time.process_time()
        noise_terms(r)
        best = min(best, time.process_time() - t)
    out[taus] = (int(r.tau_s.size), best)
print(json.dumps(out))
"""


def _run(src: str) -> dict[str, list[float]]:
    env = dict(os.environ, PYTHONPATH=src)
    res = subprocess.run(
        [sys.executable, "-c", CHILD], env=env, capture_output=True, text=True, check=True
    )
    out: dict[str, list[float]] = json.loads(res.stdout)
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--before", help="another tree's src directory, run side by side")
    args = ap.parse_args()
    here = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "src")
    trees = [("this tree", here)] + ([("before", args.before)] if args.before else [])
    for name, src in trees:
        for taus, (n_tau, cpu) in _run(src).items():
            print(f"{name:10s} {taus:7s} {n_tau:3d} τ  noise_terms CPU {cpu * 1e3:8.1f} ms")


if __name__ == "__main__":
    main()
