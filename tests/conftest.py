"""Shared fixtures."""

from __future__ import annotations

import os

# Two pytest-xdist workers share CI's two cores: multi-threaded BLAS in each worker
# oversubscribes them and makes tall least-squares solves several times slower.
for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import matplotlib  # noqa: E402
import pytest  # noqa: E402
from hypothesis import settings  # noqa: E402

# On CI the property tests draw the same examples every run (a red build is then one
# the next commit can reproduce, never a coin toss); locally they explore new examples
# each run and keep the failures they find in .hypothesis/.
settings.register_profile("ci", derandomize=True, database=None, print_blob=True)
if os.environ.get("CI"):
    settings.load_profile("ci")

matplotlib.use("Agg")
os.environ.setdefault("MPLBACKEND", "Agg")


@pytest.fixture
def rng():  # type: ignore[no-untyped-def]
    import numpy as np

    return np.random.default_rng(12345)
