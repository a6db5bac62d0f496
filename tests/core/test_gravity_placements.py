"""A gravity placement's direction (:mod:`thermocal.gravity`) is that of all its runs (kills a
mutant of ``benchmarks/mutation_check.py``, ``h39mp-…``)."""

from __future__ import annotations

import math

import numpy as np


def test_a_placements_direction_is_that_of_all_its_runs() -> None:
    """Two runs 2.3° apart (one placement, tolerance 5°): the placement's gravity direction
    is that of the mean of both runs' mean specific forces, (0, −10, 1000)/|…|, for each."""
    from thermocal.gravity import group_placements

    dirs, place = group_placements([[0.0, 10.0, 1000.0], [0.0, -30.0, 1000.0]])
    assert place == (0, 0)
    want = np.array([0.0, -10.0, 1000.0]) / math.hypot(10.0, 1000.0)
    for d in dirs:
        np.testing.assert_allclose(d, want, atol=1e-14)
