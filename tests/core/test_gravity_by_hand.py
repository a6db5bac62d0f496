"""Gravity placements (:mod:`thermocal.gravity`): runs along different directions are
different placements (kills a mutant of ``benchmarks/mutation_check.py``)."""

from __future__ import annotations

import numpy as np
import pytest


def test_runs_in_different_directions_are_different_placements() -> None:
    """Means along +z, +z (0.5° off) and +x [mg]: the first two are one placement within
    the tolerance, the third another (mutant gravity-placement-tolerance joins all)."""
    from thermocal.gravity import group_placements

    s = np.sin(np.radians(0.5))
    dirs, place = group_placements(
        [(0.0, 0.0, 1000.0), (1000.0 * s, 0.0, 1000.0), (1000.0, 0.0, 0.0)]
    )
    assert place == (0, 0, 1)
    assert dirs[2] == pytest.approx((1.0, 0.0, 0.0))
