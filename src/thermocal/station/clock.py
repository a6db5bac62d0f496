"""The station's clock: Unix time [s] that a step of the host's clock does not move.

An NTP step, a virtual machine resumed, an operator setting the date: ``time.time()``
jumps, and a loop timed by it stalls (a step back of an hour froze the program, the polls,
the part rotation and the chamber's timeout for an hour) or skips (a step forward ended the
program at once).  The station times everything by :func:`now`: the wall clock read once,
when this module is loaded, plus the monotonic time elapsed since (POSIX
``CLOCK_MONOTONIC``: never stepped, slewed with the wall clock by NTP).
"""

from __future__ import annotations

import time

_WALL0 = time.time()
_MONO0 = time.monotonic()


def now() -> float:
    """Unix time [s]: ``wall₀ + (monotonic − monotonic₀)``, unmoved by a step of the host's
    clock."""
    return _WALL0 + (time.monotonic() - _MONO0)


def wall_step() -> float:
    """How far the host's wall clock has been stepped since this module was loaded [s]:
    ``time.time() − now()`` (0 but for steps and for the slew of the two clocks)."""
    return time.time() - now()
