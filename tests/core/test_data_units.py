"""A signal in the data's own unit (thermocal.data_units), and allan loading no metrics."""

import subprocess
import sys
from pathlib import Path

import numpy as np

from thermocal.data_units import data_unit_of, signal_in_data_unit
from thermocal.recording import Recording


def test_deg_per_second_stays_deg_per_second() -> None:
    t = np.arange(5) * 0.1
    rate = np.array([0.5, -1.0, 2.0, 0.25, 3.0])  # [°/s]
    rec = Recording.from_arrays(t, {"gx": rate}, signal_unit="deg/s")
    values, unit = signal_in_data_unit(rec, "gx")
    assert unit == "deg/s"
    np.testing.assert_allclose(values, rate, rtol=1e-15)
    canonical, canon = rec.signal("gx")
    np.testing.assert_allclose(canonical, rate * 3600.0, rtol=1e-15)
    assert canon == "deg/h"
    assert data_unit_of(rec, "gx", canon) == ("deg/s", 3600.0)  # 1 °/s = 3600 °/h


def test_allan_loads_no_metrics(tmp_path: Path) -> None:
    data = tmp_path / "r.csv"
    rows = "\n".join(f"{0.01 * i:.2f},{(i * 7919) % 13 - 6}" for i in range(3000))
    data.write_text("time [s],rate [deg/h]\n" + rows + "\n")
    code = (
        "import sys; from thermocal.cli import main; "
        f"s = main(['allan', {str(data)!r}, '--signal', 'rate [deg/h]', '--json']); "
        "print(s, sorted(m for m in sys.modules if m.startswith('thermocal.metrics')), "
        "file=sys.stderr)"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stderr.strip().splitlines()[-1] == "0 []"
