"""Turntable calibration of a gyro triad on a dual-axis rotation mechanism.

A triad (and optionally an accelerometer triad) mounted on a two-axis table is taken
through sixteen positions; the gimbal angles integrated from the gyro outputs are compared
with the encoders' and the twelve coefficients of the triad's static error model are
estimated by a Kalman filter, with a batch least-squares solution as the cross-check and the
design's Cramér–Rao bound.  Everything here is pure maths on arrays or a
:class:`~thermocal.recording.Recording`: :func:`calibrate_arrays` for arrays,
:func:`calibrate` for a recording; the command ``thermocal turntable`` reads files and fits
over temperature through :mod:`thermocal.pipeline.turntable`.

Modules: :mod:`.kinematics` (frames, the true body rate from the encoder angles),
:mod:`.schedule` (the 16 positions, design checks, motion detection), :mod:`.model` (error
model, measurement model, Cramér–Rao bound), :mod:`.simulate` (runs with a known truth),
:mod:`.estimate_ls` (batch least squares), :mod:`.kalman` (14/15-state filter),
:mod:`.calibration` (one run end to end, the validation on another run), :mod:`.accel` (the
accelerometer triad from the dwells), :mod:`.thermal` (every coefficient over temperature),
:mod:`.gsens` (the gyro's sensitivity to specific force from the dwells, its drift taken off
the moves when significant).

Notes
-----
The error model of the triad, with ``b`` the biases [°/h], ``diag(E)`` the scale-factor
errors [ppm] and the off-diagonal of ``E`` the six misalignments [″]:

.. math::

    \\omega_\\mathrm{meas} = (I + E)\\, \\omega_\\mathrm{true} + b + n

Over a sample interval of length :math:`\\tau_i` the gyro-integrated gimbal angle minus the
encoders' change is linear in the coefficients θ (the measurement of the filter), e.g. for
the inner axis

.. math::

    y_{\\alpha,i} = e_z \\cdot \\left(g_i \\tau_i - C_n^b\\, \\omega_{ie}^n \\tau_i\\right)
    - \\Delta\\alpha_{\\mathrm{enc},i} = h_{\\alpha,i}\\, \\theta + w_{\\alpha,i}

with :math:`g_i` the gyro mean rate and :math:`\\omega_{ie}^n` the earth rate at the site's
latitude (:mod:`.model`).  The sixteen positions and the filter are those of the
dual-axis turntable source document [1]_; the terms follow the IEEE test procedures for
gyros and accelerometers [2]_ [3]_.

References
----------
.. [1] *A method for separating the combined error coefficients of a ring-laser gyro triad
   based on dual-axis rotation*, Chinese invention patent CN104880182.
.. [2] IEEE Std 952-1997 (R2008), "IEEE Standard Specification Format Guide and Test
   Procedure for Single-Axis Interferometric Fiber Optic Gyros", IEEE, 1998.
.. [3] IEEE Std 1293-1998 (R2008), "IEEE Standard Specification Format Guide and Test
   Procedure for Linear, Single-Axis, Nongyroscopic Accelerometers", IEEE, 1999.

Examples
--------
A simulated run with known coefficients, calibrated from a recording:

>>> from thermocal.turntable import calibrate, simulate_turntable16
>>> rec, truth = simulate_turntable16(0, rate_hz=10.0, dwell_s=20.0)
>>> res = calibrate(rec, 40.0, min_dwell_s=10.0)
>>> res.n_positions, res.to_dict()["method"]
(16, 'kalman (15 states)')
>>> [round(v) for v in res.to_dict()["misalignment_arcsec"]]
[30, -25, -10, 15, 40, -35]
>>> truth["misalignment_arcsec"]
[30.0, -25.0, -10.0, 15.0, 40.0, -35.0]
"""

from __future__ import annotations

from thermocal.turntable.calibration import (
    TurntableResult,
    calibrate,
    calibrate_arrays,
    validate_turntable_run,
)
from thermocal.turntable.model import COEFF_NAMES, MISALIGNMENT_NAMES, coefficient_rows
from thermocal.turntable.schedule import (
    POSITIONS_16,
    TurntableScheduleError,
    TurntableWarning,
    build_schedule,
)
from thermocal.turntable.simulate import TurntableTruth, simulate_turntable16

__all__ = [
    "COEFF_NAMES",
    "MISALIGNMENT_NAMES",
    "POSITIONS_16",
    "TurntableResult",
    "TurntableScheduleError",
    "TurntableTruth",
    "TurntableWarning",
    "build_schedule",
    "calibrate",
    "calibrate_arrays",
    "coefficient_rows",
    "simulate_turntable16",
    "validate_turntable_run",
]
