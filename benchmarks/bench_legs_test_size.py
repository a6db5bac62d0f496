"""The size of the heating-vs-cooling t test (``thermocal.legs.compare_legs``) under slow
noise, and what an effective-sample-size correction would do to it and to its power.

Size: a 1 Hz record of the simulator's thermal-lag program (hold 30 min at 20 °C, 1 °C/min
to 60 °C, hold, back to 20 °C, hold) with no hysteresis, the residual AR(1) noise of
correlation time ``tc`` (0: white); the 12 temperature bins' differences ``d_b`` as
``compare_legs`` forms them; the share of ``--trials`` records the 99 % test rejects, as
shipped (bins independent) and with ``n_eff = m (1 − r)/(1 + r)`` [Bayley & Hammersley 1946],
``r`` the bins' lag-1 autocorrelation with Kendall's (1954) small-sample bias taken off,
``r = (m r₁ + 1)/(m − 3)``, clipped to [0, 1), ``n_eff ≥ 2``, ``n_eff − 1`` degrees of freedom.

Power: the simulator's sweep (seeds 0–3, τ = 300 s of lag) with a cubic ``poly`` fitted on
the heating leg (the tutorial's case, 10.5 °/h apart): t and its critical value both ways.

Run: ``PYTHONPATH=src .venv/bin/python benchmarks/bench_legs_test_size.py [--trials 1500]``.
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import warnings

import numpy as np
from scipy import signal, stats

from thermocal.legs import CONFIDENCE, _bin_differences, find_legs
from thermocal.models import RunData
from thermocal.models.registry import make_model
from thermocal.simulate import SCENARIOS

Q = 0.5 + CONFIDENCE / 2.0


def _ar1(rng: np.random.Generator, n: int, tc: float) -> np.ndarray:
    if tc <= 0:
        return rng.standard_normal(n)
    phi = math.exp(-1.0 / tc)
    e = rng.standard_normal(n) * math.sqrt(1.0 - phi**2)
    y, _ = signal.lfilter([1.0], [1.0, -phi], e, zi=[phi * rng.standard_normal()])
    return np.asarray(y)


def _tests(d: np.ndarray) -> tuple[float, float, float, float, float]:
    """(t, its critical value) as shipped, (t, critical) with n_eff, and n_eff."""
    m = d.size
    mean, sd = float(d.mean()), float(d.std(ddof=1))
    c = d - mean
    r1 = float(c[1:] @ c[:-1] / (c @ c))
    r = min(max((m * r1 + 1.0) / (m - 3.0), 0.0), 0.999)
    ne = max(m * (1.0 - r) / (1.0 + r), 2.0)
    t0, t1 = mean / (sd / math.sqrt(m)), mean / (sd / math.sqrt(ne))
    return t0, float(stats.t.ppf(Q, m - 1)), t1, float(stats.t.ppf(Q, ne - 1)), ne


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--trials", type=int, default=1500)
    args = ap.parse_args()
    t = np.arange(0.0, 10200.0)
    temp = np.interp(t, [0, 1800, 4200, 6000, 8400, 10200], [20, 20, 60, 60, 20, 20])
    legs = find_legs(t, temp)
    heat, cool = legs.mask("heating"), legs.mask("cooling")
    print("| noise | rejected, bins independent | rejected, n_eff | median n_eff |")
    print("|---|---|---|---|")
    for tc in (0.0, 100.0, 300.0, 1000.0):
        rng = np.random.default_rng(1)
        plain = corr = 0
        nes = []
        for _ in range(args.trials):
            r = _ar1(rng, t.size, tc)
            d, _ = _bin_differences(temp, r - r.mean(), heat, cool)
            t0, c0, t1, c1, ne = _tests(d)
            plain += abs(t0) > c0
            corr += abs(t1) > c1
            nes.append(ne)
        what = "white" if tc == 0 else f"AR(1), {tc:g} s"
        print(f"| {what} | {plain / args.trials:.1%} | {corr / args.trials:.1%} "
              f"| {np.median(nes):.1f} |")  # fmt: skip
    print("\n| seed | t, bins independent (critical) | t, n_eff (critical) | n_eff |")
    print("|---|---|---|---|")
    for seed in range(4):
        rec, _ = SCENARIOS["thermal-lag"](seed, quant_c=0.0625)[0]
        run = RunData.from_recording(rec, "gyro", ["T1"])
        lg = find_legs(run.time_s, run.temps_c[:, 0])
        (h,) = lg.of("heating")
        part = dataclasses.replace(run, time_s=run.time_s[h.start : h.stop],
                                   temps_c=run.temps_c[h.start : h.stop],
                                   signal=run.signal[h.start : h.stop])  # fmt: skip
        model = make_model("poly", order=3).fit([part])
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            res = model.residuals(run)
        d, _ = _bin_differences(run.temps_c[:, 0], res - res.mean(), lg.mask("heating"),
                                lg.mask("cooling"))  # fmt: skip
        t0, c0, t1, c1, ne = _tests(d)
        print(f"| {seed} | {t0:.2f} ({c0:.2f}) | {t1:.2f} ({c1:.2f}) | {ne:.1f} |")


if __name__ == "__main__":
    main()
