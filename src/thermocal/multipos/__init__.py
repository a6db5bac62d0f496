"""Triad calibration without a turntable: the multi-position method (issue 30).

A board placed by hand in several still orientations ("poses") and turned by hand between
them.  The error models are those of the turntable (:mod:`thermocal.turntable.model`)::

    f_meas = (I + E_a) f_true + b_a + n_a       (accelerometer, specific force)
    ω_meas = (I + E_g) ω_true + b_g + n_g       (gyro, body rate)

θ (12) per triad: bias [mg or °/h], scale-factor errors ``E_ii`` [ppm], misalignments
``E_ij`` [″] in :data:`thermocal.turntable.model.MISALIGNMENT_NAMES` order.

Frames and the constraint taken.  The orientation of each pose is unknown, so a rotation
of the whole triad is not observable from gravity: the body frame **is the accelerometer
frame** — body x along the x accelerometer's sensitive axis, body y in the plane of the x
and y accelerometers (Tedaldi, Pretto & Menegatti, "A robust and easy to implement method
for IMU calibration without external equipments", ICRA 2014, doi:10.1109/ICRA.2014.6907297,
§III-A).  So ``E_a`` is lower triangular: ``yx = zx = zy = 0`` for the accelerometer
(reported with σ = 0), and the gyro's six misalignments are relative to that frame.  With
the six faces named (``--poses`` ``x_p``…``z_a``) the closed form instead refers ``E_a``
to the faces of the box (all six misalignments).

Modules: :mod:`.poses` (static poses, the POSES file), :mod:`.accel` (accelerometer from
the gravity magnitude, six-face closed form), :mod:`.gyro` (gyro from the rotations
between poses and from 360° turns), :mod:`.calibrate` (one session end to end, its
validation), :mod:`.simulate` (sessions with known truth): pure maths on numpy arrays, no
I/O.  :mod:`thermocal.pipeline.multipos` is the file driver ``thermocal multipos`` calls: it
reads the sessions, fits in temperature and saves the calibration.
"""
