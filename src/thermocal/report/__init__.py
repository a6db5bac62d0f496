"""HTML report of a temperature-compensation workflow (SPEC §1, §4a–§5, §8).

:func:`build_report` turns :class:`ReportInputs` (model files, validation
results, recordings) into one self-contained HTML document; :func:`write_report`
writes it atomically.  Figures come from :mod:`thermocal.report.figures`
(matplotlib, Agg backend, imported only here).
"""

from __future__ import annotations

from thermocal.report.build import (
    ModelEntry,
    ReportInputs,
    build_report,
    figures_of_merit,
    fmt_num,
    improvement_pct,
    write_report,
)

__all__ = [
    "ModelEntry",
    "ReportInputs",
    "build_report",
    "figures_of_merit",
    "fmt_num",
    "improvement_pct",
    "write_report",
]
