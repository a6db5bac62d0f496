"""term_features of one block: the powers written out with numpy, and nothing of the block
kept once it returns (a fit calls it for hundreds of blocks: temporaries held in a reference
cycle piled up until the cycle collector ran)."""

from __future__ import annotations

import gc
import weakref

import numpy as np

from thermocal.models.term_scaling import fit_base_scaling
from thermocal.models.terms import parse_terms, term_features


def _block():
    rng = np.random.default_rng(0)
    return np.asfortranarray(20.0 + 10.0 * rng.random((4096, 2)))


def test_powers_are_the_scaled_temperatures_raised():
    temps = _block()
    terms = parse_terms("T1,T1^2,T1^3,T2^2,T2^4", 2)
    sc = fit_base_scaling([temps], None, terms)
    u = (temps - sc.t_center[None, :2]) / sc.t_scale[None, :2]
    want = np.column_stack([u[:, 0], u[:, 0] ** 2, u[:, 0] ** 3, u[:, 1] ** 2, u[:, 1] ** 4])
    np.testing.assert_allclose(term_features(terms, sc, temps, None), want, rtol=1e-13)


def test_a_block_is_freed_when_the_features_return():
    temps = _block()
    terms = parse_terms("T1,T1^2,T1^3,T2^2,T2^4", 2)
    sc = fit_base_scaling([temps], None, terms)
    out = np.empty((temps.shape[0], len(terms)), order="F")
    gc.disable()
    try:
        block = temps.copy(order="F")
        ref = weakref.ref(block)
        term_features(terms, sc, block, None, out=out)
        del block
        assert ref() is None  # freed by its reference count, not left to the collector
    finally:
        gc.enable()
