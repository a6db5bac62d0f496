"""Triad calibration without a turntable: the multi-position method.

A board placed by hand in several still orientations ("poses") and turned by hand between
them.  The accelerometer triad is calibrated from the magnitude of gravity over the poses
(or, with the six faces named, from their closed form), the gyro triad from the rotations
between poses and from 360° turns about named axes.  Everything here is pure maths on
numpy arrays: a notebook user with arrays of samples calls :func:`calibrate_session`; the
command ``thermocal multipos`` reads files through :mod:`thermocal.pipeline.multipos` and
calls the same function.

The public API:

* :func:`find_poses` / :func:`detect_poses` — the still poses of a session (judged against
  the sensor's own noise and the motions), :func:`parse_poses` — poses given by hand
  (imucal's section list or a POSES file's dict), :class:`Section`, :class:`PoseDetection`.
* :func:`calibrate_session` → :class:`SessionResult` (:class:`AccelFit`, :class:`GyroFit`;
  each with ``to_dict()`` and ``table()``).
* :func:`validate_held_out_session` → :class:`MultiposValidation` — a calibration of triads
  judged on a held-out session.
* :func:`simulate_session`, :func:`random_truth` — sessions with a known truth.

Notes
-----
The error model of each triad (the turntable's, :mod:`thermocal.turntable.model`):

.. math::

    f_\\mathrm{meas} = (I + E_a)\\, f_\\mathrm{true} + b_a + n_a, \\qquad
    \\omega_\\mathrm{meas} = (I + E_g)\\, \\omega_\\mathrm{true} + b_g + n_g

with θ (12 per triad): the bias ``b`` [mg or °/h], the scale-factor errors ``E_ii`` [ppm]
and the misalignments ``E_ij`` [″] (the terms of IEEE Std 1293 [3]_) in
:data:`thermocal.turntable.model.MISALIGNMENT_NAMES` order.  The accelerometer is
calibrated by minimising the gravity-magnitude misfit over the poses ``k`` (Tedaldi et
al. 2014 [1]_, eqs. 9-10):

.. math::

    \\min_{b, E} \\sum_k \\frac{\\left(\\lVert (I + E_a)^{-1} (\\bar f_k - b_a) \\rVert
    - g\\right)^2}{\\sigma_k^2}

The orientation of each pose is unknown, so a rotation of the whole triad is not
observable from gravity: the body frame **is the accelerometer frame** (body x along the x
accelerometer's sensitive axis, body y in the plane of the x and y accelerometers), so
``E_a`` is lower triangular (``yx = zx = zy = 0``, reported with σ = 0) and the gyro's six
misalignments are relative to that frame.  With the six faces named (``x_p`` … ``z_a``)
the closed form of Ferraris et al. (1995) [2]_ refers ``E_a`` to the faces of the box (all six
misalignments).

References
----------
.. [1] D. Tedaldi, A. Pretto and E. Menegatti, "A robust and easy to implement method for
   IMU calibration without external equipments", Proc. IEEE International Conference on
   Robotics and Automation (ICRA), Hong Kong, 2014, pp. 3042-3049, doi:10.1109/ICRA.2014.6907297.
.. [2] F. Ferraris, U. Grimaldi and M. Parvis, "Procedure for effortless in-field
   calibration of three-axis rate gyros and accelerometers", Sensors and Materials 7(5),
   1995, pp. 311-330.
.. [3] IEEE Std 1293-1998 (R2008), "IEEE Standard Specification Format Guide and Test
   Procedure for Linear, Single-Axis, Nongyroscopic Accelerometers", IEEE, 1999.

Examples
--------
A simulated session of 12 poses with known errors, calibrated from its arrays:

>>> import numpy as np
>>> from thermocal.multipos import calibrate_session, random_truth, simulate_session
>>> rng = np.random.default_rng(0)
>>> truth, _ = random_truth(rng)
>>> s = simulate_session(rng, truth.accel, truth.gyro, n_poses=12, rate_hz=50.0, dwell_s=3.0)
>>> res = calibrate_session(s["time_s"], s["accel_mg"], np.radians(s["gyro_deg_s"]),
...                         g_mg=s["g_m_s2"] / 9.80665e-3, latitude_deg=45.0)
>>> len(res.poses), res.accel.method
(12, 'gravity-magnitude')
>>> bool(np.all(abs(res.accel.theta[3:6] - truth.accel[3:6]) < 4 * res.accel.sigma[3:6]))
True
>>> bool(np.all(abs(res.gyro.theta[3:6] - truth.gyro[3:6]) < 4 * res.gyro.sigma[3:6]))
True
>>> res.table()[3]["parameter"], res.table()[3]["unit"]
('sf_x', 'ppm')
"""

from __future__ import annotations

from thermocal.multipos.accel import AccelFit, fit_gravity_magnitude, fit_six_faces
from thermocal.multipos.calibrate import MultiposValidation, SessionResult, calibrate_session
from thermocal.multipos.gyro import GyroFit
from thermocal.multipos.poses import (
    FACES,
    PoseDetection,
    Section,
    detect_poses,
    find_poses,
    parse_poses,
)
from thermocal.multipos.simulate import random_truth, simulate_session
from thermocal.multipos.validate import validate_held_out_session

__all__ = [
    "FACES",
    "AccelFit",
    "GyroFit",
    "MultiposValidation",
    "PoseDetection",
    "Section",
    "SessionResult",
    "calibrate_session",
    "detect_poses",
    "find_poses",
    "fit_gravity_magnitude",
    "fit_six_faces",
    "parse_poses",
    "random_truth",
    "simulate_session",
    "validate_held_out_session",
]
