"""A recording folder written by ``thermocal station run``, read as one recording."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

from thermocal._lazy import LazyModule

if TYPE_CHECKING:
    import pandas as pd
    import pyarrow as pa
    import pyarrow.csv as pacsv
    import pyarrow.parquet as pq
else:
    pd = LazyModule("pandas")
    pa = LazyModule("pyarrow")
    pacsv = LazyModule("pyarrow.csv")
    pq = LazyModule("pyarrow.parquet")


def is_station_path(p: Path) -> bool:
    """``DIR`` (or ``DIR/SENSOR``) written by ``thermocal station run``."""
    return (p.is_dir() or not p.exists()) and (
        (p / "station.json").is_file() or (p.parent / "station.json").is_file()
    )


def read_station_table(p: Path) -> tuple[pd.DataFrame, dict[str, Any]]:
    """The closed Parquet parts of a station recording as one table
    (:func:`thermocal.station.recorder.read_station`)."""
    from thermocal.station.recorder import read_station

    table, meta = read_station(p)
    return table.to_pandas(), meta
