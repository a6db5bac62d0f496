"""Ctrl-C on the command line (exit status 130, saying what was kept)."""

from __future__ import annotations

import sys

EXIT_INTERRUPTED = 130
"""128 + SIGINT, the shell's convention for a program stopped by Ctrl-C."""


def report_interrupted() -> int:
    """Print what was kept and return :data:`EXIT_INTERRUPTED`.

    Complete outputs were renamed into place (:data:`thermocal.writers.WRITTEN`); the one being
    written was still a temporary and has been removed by its writer.
    """
    tio = sys.modules.get("thermocal.writers")  # not loaded: nothing can have been written
    done = [str(p) for p in getattr(tio, "WRITTEN", [])]
    if done:
        print(
            "interrupted: kept " + ", ".join(done) + " (complete); anything else being "
            "written was discarded",
            file=sys.stderr,
        )
    else:
        print("interrupted: nothing written", file=sys.stderr)
    return EXIT_INTERRUPTED
