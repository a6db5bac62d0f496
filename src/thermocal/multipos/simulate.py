"""Hand-placed multi-position sessions with known truth.

Poses: ``n_poses`` orientations drawn uniformly on SO(3) (a board put down by hand in
random orientations), each held ``dwell_s`` (± 30 %) with a small tremor (a rotation of
``tremor_deg`` amplitude at a few hertz about a random axis); between them a hand
rotation about the fixed body axis of the relative rotation, with the smooth profile
``(1 − cos πt/T)/2`` over ``move_s`` (± 30 %), and a linear acceleration bump of the hand.
The attitude is integrated from the body rate exactly as the estimator integrates
(``C_{i+1} = C_i exp([ω_i τ×])``, :func:`.geometry.attitude_along`); the gyro reads the
body rate plus the earth rate at ``latitude_deg`` (ENU local frame), the accelerometer the
specific force ``C_nᵇ (0, 0, g) + a_hand``, both through the error model of the package
docstring with white noise.  Several temperatures: each parameter is
``θ(T) = θ₀ + θ₁ (T − 25 °C)``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from thermocal import units
from thermocal.defaults import MAX_SIMULATED_SAMPLES
from thermocal.errors import ParameterError
from thermocal.multipos.geometry import attitude_along, matrix_to_rotvec
from thermocal.turntable import model

FloatArray = npt.NDArray[np.float64]

MG_M_S2 = 9.80665e-3
TREF_TRUTH_C = 25.0


@dataclass(frozen=True)
class Truth:
    """True θ of both triads at a temperature (units of :mod:`thermocal.turntable.thermal`).

    Attributes
    ----------
    accel : numpy.ndarray, shape (12,)
        Accelerometer θ: biases [mg], scale factors [ppm], misalignments [arcsec].
    gyro : numpy.ndarray, shape (12,)
        Gyro θ: biases [°/h], scale factors [ppm], misalignments [arcsec].
    """

    accel: FloatArray
    gyro: FloatArray


def random_truth(rng: np.random.Generator) -> tuple[Truth, Truth]:
    """θ₀ and the slope θ₁ [per °C] of a consumer MEMS IMU.  Accelerometer misalignments
    lower triangular (the accelerometer frame is the body frame).

    Parameters
    ----------
    rng : numpy.random.Generator
        The random source.

    Returns
    -------
    theta0, theta1 : Truth
        θ at 25 °C and its slope per °C (units of :class:`Truth`, per °C for the slope).

    Examples
    --------
    >>> t0, t1 = random_truth(np.random.default_rng(0))
    >>> t0.gyro.shape, bool(abs(t0.accel[0]) <= 40), float(t1.gyro[6])
    ((12,), True, 0.0)
    """
    a0 = np.zeros(12)
    a0[0:3] = rng.uniform(-40, 40, 3)  # mg
    a0[3:6] = rng.uniform(-8000, 8000, 3)  # ppm
    a0[[8, 10, 11]] = rng.uniform(-2000, 2000, 3)  # xy, xz, yz [″]
    g0 = np.zeros(12)
    g0[0:3] = rng.uniform(-2000, 2000, 3)  # °/h
    g0[3:6] = rng.uniform(-8000, 8000, 3)
    g0[6:12] = rng.uniform(-3000, 3000, 6)
    a1 = np.zeros(12)
    a1[0:3] = rng.uniform(-0.5, 0.5, 3)  # mg/°C
    a1[3:6] = rng.uniform(-50, 50, 3)  # ppm/°C
    g1 = np.zeros(12)
    g1[0:3] = rng.uniform(-30, 30, 3)  # °/h/°C
    g1[3:6] = rng.uniform(-50, 50, 3)
    return Truth(a0, g0), Truth(a1, g1)


def _random_rotation(rng: np.random.Generator) -> FloatArray:
    q = rng.normal(size=4)
    q /= np.linalg.norm(q)
    w, x, y, z = q
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])  # fmt: skip


def simulate_session(
    rng: np.random.Generator,
    accel_theta: FloatArray,
    gyro_theta: FloatArray,
    *,
    n_poses: int = 16,
    rate_hz: float = 100.0,
    dwell_s: float = 5.0,
    move_s: float = 2.0,
    accel_noise_mg: float = 2.0,
    gyro_noise_deg_s: float = 0.03,
    tremor_deg: float = 0.003,
    latitude_deg: float = 45.0,
    max_angle_deg: float = 170.0,
    g_sensitivity_deg_h_g: FloatArray | None = None,
    accel_k2_mg_g2: FloatArray | None = None,
) -> dict[str, Any]:
    """One session (module docstring): ``time_s``, ``accel_mg`` (n, 3), ``gyro_deg_s``
    (n, 3), the true ``attitude`` (n, 3, 3, body → local), ``poses`` (start, end) of the
    still windows and ``g_m_s2``.

    Parameters
    ----------
    rng : numpy.random.Generator
        The random source (poses, durations, noise).
    accel_theta, gyro_theta : numpy.ndarray, shape (12,)
        True θ of the accelerometer (mg, ppm, arcsec) and the gyro (°/h, ppm, arcsec).
    n_poses : int, default 16
        Number of still poses, drawn uniformly on SO(3).
    rate_hz : float, default 100.0
        Sample rate [Hz].
    dwell_s, move_s : float, default 5.0, 2.0
        Mean still time per pose and mean move time [s] (each ± 30 %).
    accel_noise_mg, gyro_noise_deg_s : float, default 2.0, 0.03
        White-noise σ per sample [mg], [°/s].
    tremor_deg : float, default 0.003
        Amplitude of the hand's tremor while still [°].
    latitude_deg : float, default 45.0
        Latitude for the earth rate [°].
    max_angle_deg : float, default 170.0
        Largest rotation between consecutive poses [°] (the smallest is 30°).
    g_sensitivity_deg_h_g : numpy.ndarray, shape (3, 3), optional
        The gyro's sensitivity to specific force [°/h per g] (:func:`simulate_attitudes`).
    accel_k2_mg_g2 : numpy.ndarray, shape (3,), optional
        The accelerometer's second-order coefficient per axis [mg per g²]
        (:func:`simulate_attitudes`).

    Returns
    -------
    dict
        ``time_s`` [s], ``accel_mg`` [mg], ``gyro_deg_s`` [°/s], ``attitude``, ``poses``
        (sample index pairs), ``g_m_s2`` [m/s²].

    References
    ----------
    - D. Tedaldi, A. Pretto and E. Menegatti, "A robust and easy to implement method for
      IMU calibration without external equipments", Proc. IEEE ICRA 2014, 3042–3049.

    Examples
    --------
    >>> th = np.zeros(12)
    >>> s = simulate_session(np.random.default_rng(0), th, th, n_poses=4, rate_hz=20.0)
    >>> len(s["poses"]), s["accel_mg"].shape[1]
    (4, 3)
    """
    cs = [_random_rotation(rng)]
    while len(cs) < n_poses:
        c = _random_rotation(rng)
        ang = np.linalg.norm(matrix_to_rotvec(cs[-1].T @ c))
        if ang < math.radians(max_angle_deg) and ang > math.radians(30.0):
            cs.append(c)
    return simulate_attitudes(rng, cs, accel_theta, gyro_theta, rate_hz=rate_hz,
                              dwell_s=dwell_s, move_s=move_s, accel_noise_mg=accel_noise_mg,
                              gyro_noise_deg_s=gyro_noise_deg_s, tremor_deg=tremor_deg,
                              latitude_deg=latitude_deg,
                              g_sensitivity_deg_h_g=g_sensitivity_deg_h_g,
                              accel_k2_mg_g2=accel_k2_mg_g2)  # fmt: skip


def simulate_attitudes(
    rng: np.random.Generator,
    attitudes: list[FloatArray],
    accel_theta: FloatArray,
    gyro_theta: FloatArray,
    *,
    rate_hz: float = 100.0,
    dwell_s: float = 5.0,
    move_s: float = 2.0,
    accel_noise_mg: float = 2.0,
    gyro_noise_deg_s: float = 0.03,
    tremor_deg: float = 0.003,
    latitude_deg: float = 45.0,
    g_sensitivity_deg_h_g: FloatArray | None = None,
    accel_k2_mg_g2: FloatArray | None = None,
) -> dict[str, Any]:
    """A session through the given still ``attitudes`` (body → local ENU rotations, each
    move shorter than a half turn), as :func:`simulate_session` (which draws them at
    random): for a held-out turn of a known angle.

    Parameters
    ----------
    rng : numpy.random.Generator
        The random source (durations, tremor, noise).
    attitudes : list of numpy.ndarray, shape (3, 3)
        The still poses, body → local ENU.
    accel_theta, gyro_theta : numpy.ndarray, shape (12,)
        True θ of the accelerometer (mg, ppm, arcsec) and the gyro (°/h, ppm, arcsec).
    rate_hz : float, default 100.0
        Sample rate [Hz].
    dwell_s, move_s : float, default 5.0, 2.0
        Mean still time per pose and mean move time [s] (each ± 30 %).
    accel_noise_mg, gyro_noise_deg_s : float, default 2.0, 0.03
        White-noise σ per sample [mg], [°/s].
    tremor_deg : float, default 0.003
        Amplitude of the hand's tremor while still [°].
    latitude_deg : float, default 45.0
        Latitude for the earth rate [°].
    g_sensitivity_deg_h_g : numpy.ndarray, shape (3, 3), optional
        The gyro's sensitivity to specific force ``A`` (row: gyro axis, column: the specific
        force's axis) [°/h per g] (:mod:`thermocal.multipos.gsens`); None: none.
    accel_k2_mg_g2 : numpy.ndarray, shape (3,), optional
        The accelerometer's second-order coefficient per axis [mg per g², g = 1000 mg]:
        each axis reads ``K2_i (a_i/g)²`` more under the true specific force ``a``
        (:mod:`thermocal.multipos.accel_k2`); None: none.

    Returns
    -------
    dict
        As :func:`simulate_session`.
    """
    spec = _Spec(rate_hz, dwell_s, move_s, tremor_deg, 6.0)
    w_nb, poses, _turns = _body_rates(rng, attitudes, {}, spec)
    return _measure(rng, attitudes[0], w_nb, poses, accel_theta, gyro_theta,
                    accel_noise_mg, gyro_noise_deg_s, latitude_deg, rate_hz,
                    g_sensitivity_deg_h_g, accel_k2_mg_g2)  # fmt: skip


FERRARIS_TURNS: dict[str, tuple[str, float]] = {
    "x_p": ("x_rot", 1.0),
    "y_a": ("y_rot", -1.0),
    "z_p": ("z_rot", -1.0),
}
"""The Ferraris session's 360° turns: the face the board lies on during it, its name, and
its sense about the local vertical (+1 counter-clockwise seen from above): one of them
the other way."""

FERRARIS_ORDERS = ("faces-then-turns", "turn-after-face")
"""How a Ferraris session is recorded: the six faces, then the three turns, each from
whatever pose the board is in (imucal's guide, what users record); or each turn right
after its face."""


def face_rotation(face: str, heading_rad: float = 0.0) -> FloatArray:
    """Body → local (ENU) rotation of a face (``x_p``: body x up, ``x_a``: body x down…),
    turned by ``heading_rad`` about the vertical.

    Parameters
    ----------
    face : str
        ``x_p``, ``x_a``, ``y_p``, ``y_a``, ``z_p`` or ``z_a`` (the body axis pointing up,
        ``_p``, or down, ``_a``).
    heading_rad : float, default 0.0
        Turn about the local vertical [rad].

    Returns
    -------
    numpy.ndarray, shape (3, 3)
        The rotation matrix C_b^n.

    References
    ----------
    - F. Ferraris, U. Grimaldi and M. Parvis, "Procedure for effortless in-field
      calibration of three-axis rate gyros and accelerometers", *Sensors and Materials*
      7(5), 311–330, 1995.

    Examples
    --------
    >>> (face_rotation("x_p") @ [1.0, 0.0, 0.0]).round(3).tolist()  # body x up
    [0.0, 0.0, 1.0]
    """
    from thermocal.multipos.geometry import rotvec_to_matrix

    axis = np.eye(3)["xyz".index(face[0])] * (1.0 if face.endswith("_p") else -1.0)
    up = np.array([0.0, 0.0, 1.0])
    c_ax = np.cross(axis, up)
    if np.linalg.norm(c_ax) < 1e-12:
        c0 = np.eye(3) if axis[2] > 0 else rotvec_to_matrix([math.pi, 0.0, 0.0])
    else:
        ang = math.acos(float(np.clip(axis @ up, -1.0, 1.0)))
        c0 = rotvec_to_matrix(c_ax / np.linalg.norm(c_ax) * ang)
    out: FloatArray = rotvec_to_matrix(up * heading_rad) @ c0
    return out


def simulate_ferraris(
    rng: np.random.Generator,
    accel_theta: FloatArray,
    gyro_theta: FloatArray,
    *,
    rate_hz: float = 100.0,
    dwell_s: float = 5.0,
    move_s: float = 2.0,
    turn_s: float = 6.0,
    turn_tilt_deg: float = 0.0,
    accel_noise_mg: float = 2.0,
    gyro_noise_deg_s: float = 0.03,
    tremor_deg: float = 0.003,
    latitude_deg: float = 45.0,
    order: str = "faces-then-turns",
    g_sensitivity_deg_h_g: FloatArray | None = None,
) -> dict[str, Any]:
    """A Ferraris session (imucal's form): the six faces ``x_p``, ``y_p``, ``z_p``, ``x_a``,
    ``y_a``, ``z_a`` in that order (no flip to the opposite face: a half turn; random
    headings, each move between 30° and 150°) and the three full 360° turns about the
    vertical over ``turn_s``, each with the board on the face and in the sense of
    :data:`FERRARIS_TURNS`.  ``order`` (:data:`FERRARIS_ORDERS`): ``faces-then-turns``
    (what users record, imucal's guide), the turns after the six faces, ``x_rot``,
    ``y_rot``, ``z_rot``, each from the pose the board is in: moved onto the turn's face
    (a new heading), held still ``dwell_s`` (a pose that is no section), turned and moved
    on; ``turn-after-face``, each turn right after its face.  ``turn_tilt_deg``: each
    turn's axis tilted from the vertical by that angle about a random horizontal axis
    (a box not flat against its guide, a hand's wobble).  As
    :func:`simulate_session`, plus ``sections``: the POSES file's object
    ``{name: {"start": i, "end": j}}`` (faces and turns); ``poses`` lists every still
    window (with the faces-then-turns order, the three before the turns too).

    Parameters
    ----------
    rng : numpy.random.Generator
        The random source.
    accel_theta, gyro_theta : numpy.ndarray, shape (12,)
        True θ of the accelerometer (mg, ppm, arcsec) and the gyro (°/h, ppm, arcsec).
    turn_s : float, default 6.0
        Duration of each 360° turn [s].
    turn_tilt_deg : float, default 0.0
        Tilt of each turn's axis from the vertical [°].
    order : {"faces-then-turns", "turn-after-face"}
        The recording order.
    rate_hz : float, default 100.0
        Sample rate [Hz].
    dwell_s, move_s : float, default 5.0, 2.0
        Mean still time per pose and mean move time [s] (each ± 30 %).
    accel_noise_mg, gyro_noise_deg_s : float, default 2.0, 0.03
        White-noise σ per sample [mg], [°/s].
    tremor_deg : float, default 0.003
        Amplitude of the hand's tremor while still [°].
    latitude_deg : float, default 45.0
        Latitude for the earth rate [°].
    g_sensitivity_deg_h_g : numpy.ndarray, shape (3, 3), optional
        The gyro's sensitivity to specific force [°/h per g] (:func:`simulate_attitudes`).

    Returns
    -------
    dict
        As :func:`simulate_session`, plus ``sections``.

    Raises
    ------
    ValueError
        ``order`` not in :data:`FERRARIS_ORDERS`.

    References
    ----------
    - F. Ferraris, U. Grimaldi and M. Parvis, "Procedure for effortless in-field
      calibration of three-axis rate gyros and accelerometers", *Sensors and Materials*
      7(5), 311–330, 1995.
    """
    if order not in FERRARIS_ORDERS:
        raise ValueError(f"order must be one of {FERRARIS_ORDERS}, got {order!r}")
    faces = ["x_p", "y_p", "z_p", "x_a", "y_a", "z_a"]  # no face after its opposite
    if order == "faces-then-turns":
        at = faces + list(FERRARIS_TURNS)  # the turns' faces, in x, y, z order
        turn_after = {6 + i: sense for i, (_n, sense) in enumerate(FERRARIS_TURNS.values())}
    else:
        at = faces
        turn_after = {faces.index(f): sense for f, (_n, sense) in FERRARIS_TURNS.items()}
    cs: list[FloatArray] = []
    for f in at:  # headings that keep every move well short of a half turn
        c = face_rotation(f, rng.uniform(0, 2 * math.pi))
        while cs and not 0.5 < np.linalg.norm(matrix_to_rotvec(cs[-1].T @ c)) < 2.6:
            c = face_rotation(f, rng.uniform(0, 2 * math.pi))
        cs.append(c)
    spec = _Spec(rate_hz, dwell_s, move_s, tremor_deg, turn_s, turn_tilt_deg)
    w_nb, poses, turns = _body_rates(rng, cs, turn_after, spec)
    out = _measure(rng, cs[0], w_nb, poses, accel_theta, gyro_theta, accel_noise_mg,
                   gyro_noise_deg_s, latitude_deg, rate_hz, g_sensitivity_deg_h_g)  # fmt: skip
    sections = {f: {"start": a, "end": b} for f, (a, b) in zip(faces, poses, strict=False)}
    for k, (a, b) in turns.items():
        sections[FERRARIS_TURNS[at[k]][0]] = {"start": a, "end": b}
    out["sections"] = sections
    return out


@dataclass(frozen=True)
class _Spec:
    rate_hz: float
    dwell_s: float
    move_s: float
    tremor_deg: float
    turn_s: float
    turn_tilt_deg: float = 0.0


def _body_rates(
    rng: np.random.Generator,
    cs: list[FloatArray],
    turn_after: dict[int, float],
    spec: _Spec,
) -> tuple[FloatArray, list[tuple[int, int]], dict[int, tuple[int, int]]]:
    """The body rate through the poses ``cs`` (dwell with tremor, then the move to the
    next), with a 360° turn about the vertical after pose k of sense ``turn_after[k]``;
    the still windows and the turns' sample ranges."""
    dt = 1.0 / spec.rate_hz
    # the most samples the loop below can make (dwell and move drawn up to 1.3×)
    wanted = spec.rate_hz * (
        len(cs) * 1.3 * (spec.dwell_s + spec.move_s) + len(turn_after) * spec.turn_s
    )
    if not wanted <= MAX_SIMULATED_SAMPLES:
        raise ParameterError(
            "rate_hz",
            f"rate_hz {spec.rate_hz:g}: up to {wanted:.3g} samples for {len(cs)} poses, "
            f"above the limit of {MAX_SIMULATED_SAMPLES:.3g}: lower {{name}}",
        )
    rates = []
    poses = []
    turns = {}
    n0 = 0
    for k in range(len(cs)):
        n_d = round(spec.dwell_s * rng.uniform(0.7, 1.3) * spec.rate_hz)
        tt = np.arange(n_d + 1) * dt
        axis = rng.normal(size=3)
        axis /= np.linalg.norm(axis)
        ang = math.radians(spec.tremor_deg) * np.sin(2 * math.pi * rng.uniform(1.5, 4.0) * tt
                                                     + rng.uniform(0, 2 * math.pi))  # fmt: skip
        ang -= ang[0]
        rates.append(np.diff(ang)[:, None] / dt * axis[None, :])
        poses.append((n0, n0 + n_d))
        n0 += n_d
        c_now = cs[k] @ _rodrigues(axis * ang[-1])
        if k in turn_after:
            # a full turn about the vertical: the body axis now up, back to c_now
            up_b = c_now.T @ np.array([0.0, 0.0, 1.0])
            if spec.turn_tilt_deg:
                h = rng.normal(size=3)
                h -= (h @ up_b) * up_b
                tilt = math.radians(spec.turn_tilt_deg) * h / np.linalg.norm(h)
                up_b = _rodrigues(tilt) @ up_b
            n_t = round(spec.turn_s * spec.rate_hz)
            s = (1 - np.cos(np.pi * np.arange(n_t + 1) / n_t)) / 2
            rates.append(np.diff(s)[:, None] / dt * (2 * math.pi * turn_after[k]) * up_b)
            turns[k] = (n0, n0 + n_t)
            n0 += n_t
        if k + 1 < len(cs):
            # the tremor leaves the attitude at exp(ang[-1] axis): rotate from there
            phi = matrix_to_rotvec(c_now.T @ cs[k + 1])
            n_m = round(spec.move_s * rng.uniform(0.7, 1.3) * spec.rate_hz)
            s = (1 - np.cos(np.pi * np.arange(n_m + 1) / n_m)) / 2
            rates.append(np.diff(s)[:, None] / dt * phi[None, :])
            n0 += n_m
    return np.vstack(rates), poses, turns


def _measure(
    rng: np.random.Generator,
    c0: FloatArray,
    w_nb: FloatArray,
    poses: list[tuple[int, int]],
    accel_theta: FloatArray,
    gyro_theta: FloatArray,
    accel_noise_mg: float,
    gyro_noise_deg_s: float,
    latitude_deg: float,
    rate_hz: float,
    g_sensitivity: FloatArray | None = None,
    accel_k2: FloatArray | None = None,
) -> dict[str, Any]:
    """The attitude from the body rate, and what the triads read (module docstring); the
    gyro's bias moves by ``g_sensitivity`` [°/h per g] times the true specific force, each
    accelerometer axis reads ``accel_k2`` [mg per g²] times its square [g²] more."""
    dt = 1.0 / rate_hz
    n = w_nb.shape[0]
    d = attitude_along(np.vstack([w_nb, np.zeros((1, 3))]), np.full(n + 1, dt))
    att = c0[None] @ d  # body → local (ENU), n + 1 samples
    g = units.normal_gravity_m_s2(latitude_deg)
    f_true = np.einsum("nji,j->ni", att, np.array([0.0, 0.0, g])) / MG_M_S2  # mg
    # the hand's acceleration during the moves (local frame), ≤ 0.05 g
    moving = np.ones(n + 1, dtype=bool)
    for s0, e0 in poses:
        moving[s0 : e0 + 1] = False
    bump = np.zeros((n + 1, 3))
    bump[moving] = (
        rng.normal(0, 30.0, size=(1, 3))
        * np.sin(np.linspace(0, 40 * np.pi, n + 1)[moving])[:, None]
    )
    f_true += np.einsum("nji,nj->ni", att, bump)
    lat = math.radians(latitude_deg)
    om_n = units.EARTH_RATE_RAD_S * np.array([0.0, math.cos(lat), math.sin(lat)])
    w_true = np.vstack([w_nb, np.zeros((1, 3))]) + np.einsum("nji,j->ni", att, om_n)
    e_a = model.error_matrices(accel_theta)
    e_g = model.error_matrices(gyro_theta)
    accel = f_true @ (np.eye(3) + e_a).T + accel_theta[0:3]
    if accel_k2 is not None:  # IEEE Std 1293-1998's K2 a², a in g (1000 mg)
        accel += np.asarray(accel_k2) * (f_true / 1000.0) ** 2
    accel += rng.normal(0, accel_noise_mg, size=accel.shape)
    gyro = w_true @ (np.eye(3) + e_g).T + gyro_theta[0:3] * units.DH_TO_RS
    if g_sensitivity is not None:  # specific force in g (standard gravity: 1000 mg)
        gyro += (f_true / 1000.0) @ np.asarray(g_sensitivity).T * units.DH_TO_RS
    gyro = gyro * units.RAD_TO_DEG + rng.normal(0, gyro_noise_deg_s, size=gyro.shape)
    return {
        "time_s": np.arange(n + 1) * dt,
        "accel_mg": accel,
        "gyro_deg_s": gyro,
        "attitude": att,
        "poses": poses,
        "g_m_s2": g,
    }


def _rodrigues(phi: FloatArray) -> FloatArray:
    from thermocal.multipos.geometry import rotvec_to_matrix

    out: FloatArray = rotvec_to_matrix(phi)
    return out


ACCEL_COLUMNS = ("accel_x", "accel_y", "accel_z")
GYRO_COLUMNS = ("gyro_x", "gyro_y", "gyro_z")
TEMPERATURE_COLUMN = "T_imu"


def _recording(
    s: dict[str, Any], tc: float, rate_hz: float, latitude_deg: float
) -> tuple[Any, FloatArray]:
    """One simulated session as a Recording (m/s², °/s, drifting ``T_imu``) and its temperature."""
    from thermocal.recording import Metadata, Recording

    n = s["time_s"].size
    temp = tc + 0.2 * np.sin(np.linspace(0, np.pi, n))
    acc = s["accel_mg"] * MG_M_S2
    sig = {c: acc[:, k] for k, c in enumerate(ACCEL_COLUMNS)}
    sig |= {c: s["gyro_deg_s"][:, k] for k, c in enumerate(GYRO_COLUMNS)}
    unit = {c: "m/s^2" for c in ACCEL_COLUMNS} | {c: "deg/s" for c in GYRO_COLUMNS}
    rec = Recording.from_arrays(
        s["time_s"], sig, {TEMPERATURE_COLUMN: temp}, signal_unit=unit,
        meta=Metadata(latitude_deg=latitude_deg, sample_interval_s=1.0 / rate_hz),
    )  # fmt: skip
    return rec, temp


def simulate_runs(
    seed_rngs: list[np.random.Generator],
    *,
    runs: int = 1,
    rate_hz: float = 100.0,
    latitude_deg: float = 45.0,
    n_poses: int = 16,
    temperatures_c: tuple[float, ...] | None = None,
    held_out: bool = True,
    turns: bool = False,
) -> list[tuple[Any, dict[str, Any]]]:
    """``runs`` sessions of one IMU at temperatures spread over −10…+50 °C (one: 25 °C),
    each a :class:`~thermocal.recording.Recording` (accelerometer in m/s², gyro in °/s,
    ``T_imu`` [°C] drifting ±0.2 °C) with its truth: θ at the run's mean temperature,
    θ₀ and θ₁ of :func:`random_truth`, the still windows, g and the latitude.  With
    ``held_out`` one more session of the same IMU (other poses, other noise), labelled
    ``held-out``, at the first temperature (several runs: midway between the first two),
    for validation.  With ``turns`` every session but the held-out one is a Ferraris
    session (:func:`simulate_ferraris`: the six faces and three 360° turns, one the other
    way), its truth carrying ``sections``, the POSES file's object (``poses``).

    Parameters
    ----------
    seed_rngs : list of numpy.random.Generator
        Two generators: the truth's and the sessions'.
    runs : int, default 1
        Number of sessions (temperatures) besides the held-out one.
    rate_hz, latitude_deg : float, default 100.0, 45.0
        Sample rate [Hz] and latitude [°].
    n_poses : int, default 16
        Poses per random session.
    temperatures_c : tuple of float, optional
        The sessions' temperatures [°C] (default as above).
    held_out, turns : bool, default True, False
        Add the held-out session; record Ferraris sessions.

    Returns
    -------
    list of (Recording, dict)
        Each session and its truth.

    Raises
    ------
    ValueError
        ``runs`` below 1.
    """
    if runs < 1:
        raise ValueError("runs must be at least 1")
    truth0, slope = random_truth(seed_rngs[0])
    temps = temperatures_c or (
        (TREF_TRUTH_C,) if runs == 1 else tuple(np.linspace(-10.0, 50.0, runs).tolist())
    )
    held = temps[0] if len(temps) == 1 else 0.5 * (temps[0] + temps[1])
    if held_out:
        temps = (*temps, held)
    out = []
    for i, tc in enumerate(temps):
        rng = np.random.default_rng(seed_rngs[1].integers(2**63) + i)
        ta = truth0.accel + slope.accel * (tc - TREF_TRUTH_C)
        tg = truth0.gyro + slope.gyro * (tc - TREF_TRUTH_C)
        is_held = held_out and i == len(temps) - 1
        if turns and not is_held:
            s = simulate_ferraris(rng, ta, tg, rate_hz=rate_hz, latitude_deg=latitude_deg)
        else:
            s = simulate_session(rng, ta, tg, n_poses=n_poses, rate_hz=rate_hz,
                                 latitude_deg=latitude_deg)  # fmt: skip
        rec, temp = _recording(s, tc, rate_hz, latitude_deg)
        label = "held-out" if is_held else f"T{tc:+.0f}"
        out.append(
            (
                rec,
                {
                    "label": label,
                    "held_out": is_held,
                    "temperature_c": float(np.mean(temp)),
                    "accel_theta": ta.tolist(),
                    "gyro_theta": tg.tolist(),
                    "theta_units": {"accel": "mg, ppm, arcsec", "gyro": "deg/h, ppm, arcsec"},
                    "accel_theta0": truth0.accel.tolist(),
                    "accel_theta1_per_c": slope.accel.tolist(),
                    "gyro_theta0": truth0.gyro.tolist(),
                    "gyro_theta1_per_c": slope.gyro.tolist(),
                    "tref_c": TREF_TRUTH_C,
                    "poses": [list(p) for p in s["poses"]],
                    "gravity_m_s2": s["g_m_s2"],
                    "latitude_deg": latitude_deg,
                    "misalignment_names": list(model.MISALIGNMENT_NAMES),
                    **({"sections": s["sections"]} if "sections" in s else {}),
                },
            )
        )
    return out


__all__ = [
    "FERRARIS_ORDERS",
    "FERRARIS_TURNS",
    "Truth",
    "face_rotation",
    "random_truth",
    "simulate_attitudes",
    "simulate_ferraris",
    "simulate_runs",
    "simulate_session",
]
