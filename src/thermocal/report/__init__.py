"""HTML report of a temperature-compensation workflow: model, validation and figures of merit.

:func:`build_report` turns :class:`ReportInputs` (model files, validation
results, recordings) into one self-contained HTML document; :func:`write_report`
writes it atomically.  Figures come from :mod:`thermocal.report.figures`
(matplotlib, Agg backend, imported only here).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from thermocal.report.build import (
        ModelEntry,
        ReportInputs,
        build_report,
        figures_of_merit,
        fmt_num,
        improvement_pct,
        write_report,
    )


def __getattr__(name: str) -> Any:
    """The report's names are imported from :mod:`thermocal.report.build` on first use, so
    ``thermocal.report.analysis`` (pure numbers) loads without the file layer."""
    if name in __all__:
        from thermocal.report import build

        return getattr(build, name)
    raise AttributeError(f"module 'thermocal.report' has no attribute {name!r}")


__all__ = [
    "ModelEntry",
    "ReportInputs",
    "build_report",
    "figures_of_merit",
    "fmt_num",
    "improvement_pct",
    "write_report",
]
