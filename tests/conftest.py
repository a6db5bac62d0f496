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


@pytest.fixture(autouse=True)
def _fresh_consoles() -> None:
    """Each test's CLI run builds its consoles anew, as a new process does: their width is
    decided on first use (``COLUMNS``, a terminal or not), so a console kept from an earlier
    test would carry that test's ``COLUMNS`` into this one (an order-dependent failure)."""
    from thermocal.cli import common

    for console in (common.stdout, common.stderr):
        console._console = None  # type: ignore[attr-defined]
