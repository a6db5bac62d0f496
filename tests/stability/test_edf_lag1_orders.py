"""The phase noise identification's one-pass lag-1 sums (:func:`edf.lag1_of_differences`)
against Riley & Greenhall's r1 written here as whole-array sums, and the record's reused
decimation buffer (:meth:`family._Record.phase_r1`) against the strided phase."""

from __future__ import annotations

import numpy as np
import pytest

from thermocal.stability import edf as ed
from thermocal.stability import family


def _r1_whole(v: np.ndarray) -> float:
    """r1 = Σ_k c_k c_{k+1} / Σ_k c_k², c = v − mean(v) (Riley & Greenhall 2004, eq. 2), as
    plain sums over the whole array (no numpy.corrcoef, no blocks)."""
    c = v - np.sum(v) / v.size
    return float(np.sum(c[:-1] * c[1:]) / np.sum(c * c))


def _records(n: int) -> dict[str, np.ndarray]:
    rng = np.random.default_rng(11)
    w = rng.standard_normal(n)
    flicker = np.fft.irfft(np.fft.rfft(w) / np.sqrt(np.maximum(np.arange(n // 2 + 1), 1)), n)
    return {
        "white PM": w * 1e-9 + 5.0,  # a large offset over a tiny noise
        "white FM": np.cumsum(w) + 1e6,
        "flicker FM": np.cumsum(flicker),
        "random-walk FM": np.cumsum(np.cumsum(w)),
        "frequency offset": np.arange(n) * 1e3 + w,  # the mean dominates Σ w² of d = 1
    }


BLOCK = 1 << 15  # ed._LAG_BLOCK, written out: the test must not follow a change of it


@pytest.mark.parametrize("m", [1, 3, 7, 1000])
def test_one_pass_r1_per_order_equals_the_whole_array_sums(m: int) -> None:
    """Every order 0…3 of x[::m] − shift, with and without the decimation written out,
    equals the whole-array formula to 1e-12: rungs of 3 blocks and a part (m = 1), of one
    block and a part (m = 3), shorter than a block (m = 7, 1000)."""
    assert ed._LAG_BLOCK == BLOCK
    n = 3 * BLOCK + 12_345
    for name, x in _records(n).items():
        z = x[::m]
        shift = ed.phase_shift(x)
        want = [_r1_whole(np.diff(z - shift, d)) for d in range(4)]
        got = ed.lag1_of_differences(z, 3, shift=shift)
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-12, err_msg=f"{name} m={m}")
        out = np.empty(z.size + 5)
        assert ed.lag1_of_differences(z, 3, shift=shift, out=out) == got, name
        np.testing.assert_array_equal(out[: z.size], z - shift)
        # orders 0, 1 bit for bit; order 2's lag sum a dot product at dmax = 2 and from
        # order 3's squares at dmax = 3: rounding apart
        two = ed.lag1_of_differences(z, 2, shift=shift)
        assert two[:2] == got[:2], name
        assert two[2] == pytest.approx(got[2], rel=0, abs=1e-12), name


def test_walk_on_the_orders_equals_riley_greenhall_by_hand() -> None:
    """α, d and method from the one-pass r1 equal Riley & Greenhall's walk written here on
    whole arrays (difference until ρ = r1/(1 + r1) < 0.25 or d = dmax, α = −round(2ρ) −
    2d + 2), with Stable32's (n − 1)/n normalisation of each order too."""
    n = 2 * BLOCK + 999
    expected_alpha = {"white PM": 2, "white FM": 0, "random-walk FM": -2}
    for name, x in _records(n).items():
        z = x[::2]
        zc = z - ed.phase_shift(x)
        for dmax in (2, 3):
            for sample in (False, True):
                d = 0
                while True:
                    r1 = _r1_whole(np.diff(zc, d))
                    if sample:
                        r1 *= (zc.size - d - 1) / (zc.size - d)
                    rho = r1 / (1 + r1)
                    if rho < 0.25 or d >= dmax:
                        break
                    d += 1
                rules = ed.IdRules(r1_sample=sample)
                nid = ed.identify_noise(x, 2, dmax=dmax, phase_input=True, rules=rules)
                assert (nid.alpha, nid.d, nid.method) == (-round(2 * rho) - 2 * d + 2, d, "lag1")
                assert nid.alpha == expected_alpha.get(name, nid.alpha), name


def test_reused_rungs_hold_the_strided_phase() -> None:
    """A 2²¹-point phase record: the record's rungs (one buffer, written in place from the
    last rung when its factor divides m, else from the phase) hold x[::m] − shift and give
    the r1 of the strided phase bit for bit, at octave m, at m the last rung does not
    divide, and after a shorter rung was asked again (kept, not recomputed)."""
    n = 1 << 21
    rng = np.random.default_rng(5)
    phase = np.cumsum(rng.standard_normal(n)) * 1e-3 + rng.standard_normal(n) * 1e-4
    rec = family._Record(phase, [slice(0, n)], 0.01, "phase", ["oadev", "hdev"])
    x = rec.centred()[rec.longest]
    shift = ed.phase_shift(x)
    first: np.ndarray | None = None
    last, seen = 0, set()
    for m in (2, 4, 8, 16, 3, 6, 12, 1024, 5000, 65536, 4):
        got = rec.phase_r1(m, 2)
        assert got == ed.lag1_of_differences(x[::m], 3, shift=shift), m
        assert rec._rung is not None
        k, buf, size = rec._rung
        assert k == (last if m in seen else m)  # m = 4 again: kept, no rung written
        last = k
        seen.add(m)
        np.testing.assert_array_equal(buf[:size], x[::k] - shift)
        first = buf if first is None else first
        assert buf is first  # one buffer for every rung
        assert rec.identify(m, 3) == ed.identify_noise(x, m, dmax=3, phase_input=True)
        nid, ref = rec.identify(m, 2), ed.identify_noise(x, m, dmax=2, phase_input=True)
        assert (nid.alpha, nid.method, nid.d) == (ref.alpha, ref.method, ref.d)
        assert nid.alpha_float == pytest.approx(ref.alpha_float, rel=0, abs=1e-13)


def test_short_records_and_far_shifts() -> None:
    """A record under the rung threshold reads strided views, as identify_noise does (the
    same NoiseId, bit for bit); a shift far from the phase (its mean carrying Σ w²) is
    taken in exact passes and gives the same r1 as the whole-array formula."""
    rng = np.random.default_rng(3)
    phase = np.cumsum(rng.standard_normal(5000)) + rng.standard_normal(5000) * 3.0
    rec = family._Record(phase, [slice(0, 5000)], 1.0, "phase", ["oadev", "hdev"])
    x = rec.centred()[rec.longest]
    for m in (1, 2, 7, 100):
        assert rec.identify(m, 3) == ed.identify_noise(x, m, dmax=3, phase_input=True), m
    assert rec._rung is None
    z = rng.standard_normal(3 * BLOCK + 5)
    for shift in (100.0, -1000.0):  # |mean| ≫ σ = 1, still resolved by float64
        want = [_r1_whole(np.diff(z - shift, d)) for d in range(3)]
        got = ed.lag1_of_differences(z, 2, shift=shift)
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-12)
        short = ed.lag1_of_differences(z[:1000], 2, shift=shift)
        want = [_r1_whole(np.diff(z[:1000] - shift, d)) for d in range(3)]
        np.testing.assert_allclose(short, want, rtol=0, atol=1e-12)


def test_orders_above_three() -> None:
    """Orders beyond the Hadamard family's (a walk asked to go to d = 5) read windows long
    enough for their differences: the whole-array formula to 1e-12."""
    z = np.cumsum(np.cumsum(np.random.default_rng(4).standard_normal(2 * BLOCK + 77)))
    want = [_r1_whole(np.diff(z, d)) for d in range(6)]
    np.testing.assert_allclose(ed.lag1_of_differences(z, 5), want, rtol=0, atol=1e-12)
    nid = ed.identify_noise(z, 1, dmax=5, phase_input=True)
    assert nid.method == "lag1" and nid.d >= 2


@pytest.mark.parametrize("plan", [[1, 2, 4, 8, 16, 64, 3, 6, 1000], [1, 2, 4, 10, 20, 40, 100]])
def test_next_rung_written_in_the_same_pass(plan: list[int]) -> None:
    """With the factors planned (octave, decade, and ones the last rung does not divide),
    each pass writes the next planned factor's rung behind it (the buffer holds x[::m'] −
    shift for the next m' that m divides) and every r1 equals the strided phase's, bit for
    bit; asked out of plan order, the r1 are still the strided phase's."""
    n = (1 << 20) + 4321
    rng = np.random.default_rng(8)
    phase = np.cumsum(rng.standard_normal(n)) + rng.standard_normal(n) * 30.0
    rec = family._Record(phase, [slice(0, n)], 0.01, "phase", ["oadev"])
    rec.set_octave(np.array(sorted(plan), dtype=np.int64))
    x = rec.centred()[rec.longest]
    shift = ed.phase_shift(x)
    ordered = sorted(plan)
    for m in ordered:
        assert rec.phase_r1(m, 2) == ed.lag1_of_differences(x[::m], 2, shift=shift), m
        nxt = next((q for q in ordered if q > m and q % m == 0), 0)
        if nxt:
            assert rec._rung is not None
            k, buf, size = rec._rung
            assert (k, size) == (nxt, x[::nxt].size)
            np.testing.assert_array_equal(buf[:size], x[::nxt] - shift)
    late = family._Record(phase, [slice(0, n)], 0.01, "phase", ["oadev"])
    late.set_octave(np.array(ordered, dtype=np.int64))
    for m in reversed(ordered):
        assert late.phase_r1(m, 2) == ed.lag1_of_differences(x[::m], 2, shift=shift), m


def test_rung_needing_exact_passes_read_again() -> None:
    """A long record whose first block sits far from the rest (the offset removed is the
    first block's mean): the rungs' Σ w² is carried by the mean, the exact passes need the
    series the next rung was written over, and the record reads x[::m] again: the same r1
    as the strided phase, none NaN."""
    n = 1 << 22
    rng = np.random.default_rng(9)
    phase = rng.standard_normal(n)
    phase[:BLOCK] += 1000.0
    phase[-1] += 1000.0  # the line through the end points is flat: centring keeps the step
    rec = family._Record(phase, [slice(0, n)], 0.01, "phase", ["oadev"])
    rec.set_octave(np.array([1, 2, 4], dtype=np.int64))
    x = rec.centred()[rec.longest]
    shift = ed.phase_shift(x)
    for m in (1, 2, 4):
        got = rec.phase_r1(m, 2)
        assert got == ed.lag1_of_differences(x[::m], 2, shift=shift), m
        assert np.all(np.isfinite(got))
        assert got[0] == pytest.approx(_r1_whole(x[::m] - shift), rel=0, abs=1e-12)
