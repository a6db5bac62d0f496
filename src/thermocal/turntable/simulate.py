"""Simulator of the ``turntable-16`` scenario: a gyro triad on the dual-axis turntable.

The trajectory is :func:`thermocal.turntable.schedule.build_schedule` ;
the body rates follow kinematics eq. (2); the gyros read::

    g_i = (I + E) ω̄_true,i + b + n_i,      n_i ~ N(0, N² / τ)

where ω̄_true,i is the mean true rate over the interval ending at sample i (exact
for the gimbal rates of single-axis moves; the earth rate at the interval's mid
angles), N the angle random walk and τ the sample interval.  Encoder angles are
given at the sample times, wrapped to [0, 360) °, optionally with white noise.
Every draw comes from ``numpy.random.default_rng(seed)``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt

from thermocal import units
from thermocal.defaults import MAX_SIMULATED_SAMPLES
from thermocal.errors import ParameterError
from thermocal.recording import Metadata, Recording
from thermocal.turntable import kinematics, model
from thermocal.turntable.gsens import specific_force_g
from thermocal.turntable.schedule import POSITIONS_16, build_schedule

FloatArray = npt.NDArray[np.float64]

GYRO_COLUMNS = ("gyro_x", "gyro_y", "gyro_z")
ALPHA_COLUMN = "alpha_deg"
BETA_COLUMN = "beta_deg"


@dataclass(frozen=True)
class TurntableTruth:
    """The simulated triad's errors, as applied to the true rates.

    ``misalignment_arcsec`` in the order of :data:`.model.MISALIGNMENT_NAMES` (yx, zx, xy,
    zy, xz, yz), mapping to
    ``E[0,1], E[0,2], E[1,0], E[1,2], E[2,0], E[2,1]`` (see :mod:`.model`).  The
    default is a navigation-grade triad whose xy misalignments have an antisymmetric
    part of 20″ (a rotation of the triad about the inner axis relative to the
    encoder zero, ``inner_axis_azimuth_arcsec``).

    Attributes
    ----------
    bias_deg_h : tuple of 3 float
        Biases [°/h].
    scale_factor_ppm : tuple of 3 float
        Scale-factor errors [ppm].
    misalignment_arcsec : tuple of 6 float
        Misalignments yx, zx, xy, zy, xz, yz [″].
    """

    bias_deg_h: tuple[float, float, float] = (0.02, -0.035, 0.015)
    scale_factor_ppm: tuple[float, float, float] = (45.0, -80.0, 25.0)
    misalignment_arcsec: tuple[float, float, float, float, float, float] = field(
        default=(30.0, -25.0, -10.0, 15.0, 40.0, -35.0)
    )

    @property
    def theta(self) -> FloatArray:
        """θ (12) of :mod:`.model`, physical."""
        return np.array([*self.bias_deg_h, *self.scale_factor_ppm, *self.misalignment_arcsec])

    @property
    def error_matrix(self) -> FloatArray:
        """Physical error matrix E (dimensionless)."""
        return model.error_matrix_from_coeffs(self.theta)[0]

    @classmethod
    def random(cls, seed: int) -> TurntableTruth:
        """A random navigation-grade triad: biases 0.01–0.05 °/h, scale-factor
        errors 10–100 ppm, misalignments 5–60″ (random signs).

        Parameters
        ----------
        seed : int
            Seed of :func:`numpy.random.default_rng`.

        Returns
        -------
        TurntableTruth
        """
        rng = np.random.default_rng(seed)

        def draw(lo: float, hi: float, n: int) -> list[float]:
            mag = rng.uniform(lo, hi, n)
            sign = rng.choice([-1.0, 1.0], n)
            return [float(v) for v in mag * sign]

        b = draw(0.01, 0.05, 3)
        k = draw(10.0, 100.0, 3)
        m = draw(5.0, 60.0, 6)
        return cls((b[0], b[1], b[2]), (k[0], k[1], k[2]), (m[0], m[1], m[2], m[3], m[4], m[5]))

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready truth with the keys of the calibration result."""
        return {
            "bias_deg_h": [float(v) for v in self.bias_deg_h],
            "scale_factor_ppm": [float(v) for v in self.scale_factor_ppm],
            "misalignment_arcsec": [float(v) for v in self.misalignment_arcsec],
            "misalignment_names": list(model.MISALIGNMENT_NAMES),
            "error_matrix": self.error_matrix.tolist(),
            "inner_axis_azimuth_arcsec": model.inner_axis_azimuth(self.theta)[0],
        }


def _sampled_motion(
    sched: Any, rate_hz: float, latitude_deg: float
) -> tuple[int, FloatArray, FloatArray, FloatArray, FloatArray]:
    """Samples of a schedule at ``rate_hz``: (n, time [s], α [°], β [°], the mean true body
    rate over each interval ending at sample i [rad/s], row 0 at rest)."""
    tau = 1.0 / rate_hz
    wanted = sched.duration_s * rate_hz + 1.0
    if not wanted <= MAX_SIMULATED_SAMPLES:
        raise ParameterError(
            "rate_hz",
            f"rate_hz {rate_hz:g}: {wanted:.3g} samples over the {sched.duration_s:g} s "
            f"schedule, above the limit of {MAX_SIMULATED_SAMPLES:.3g}: lower {{name}}",
        )
    n = int(np.floor(sched.duration_s * rate_hz)) + 1
    t = np.arange(n, dtype=np.float64) * tau
    a_deg, b_deg = sched.angles_at(t)
    a = a_deg * units.DEG_TO_RAD
    b = b_deg * units.DEG_TO_RAD
    a_prev = np.concatenate([[a[0]], a[:-1]])
    b_prev = np.concatenate([[b[0]], b[:-1]])
    a_mid = 0.5 * (a + a_prev)
    b_mid = 0.5 * (b + b_prev)
    omega = kinematics.omega_ib_b(
        a_mid, b_mid, (a - a_prev) / tau, (b - b_prev) / tau, latitude_deg
    )
    return n, t, a_deg, b_deg, omega


def simulate_turntable16(
    seed: int = 0,
    *,
    rate_hz: float = 100.0,
    dwell_s: float = 60.0,
    move_rate_deg_s: float = 10.0,
    latitude_deg: float = 40.0,
    arw_deg_sqrt_h: float = 0.003,
    truth: TurntableTruth | None = None,
    encoder_noise_arcsec: float = 0.0,
    settle_s: float = 1.0,
    alpha0_deg: float = 0.0,
    beta0_deg: float = 0.0,
    positions_deg: tuple[tuple[float, float], ...] = POSITIONS_16,
    g_sensitivity_deg_h_g: npt.ArrayLike | None = None,
) -> tuple[Recording, dict[str, Any]]:
    r"""Simulate a 16-position turntable run with known truth.

    Parameters
    ----------
    seed : int, optional
        Seed of the noise (default 0).
    rate_hz : float, optional
        Sample rate [Hz] (default 100).
    dwell_s, settle_s : float, optional
        Dwell at each position and settling after each move [s] (default 60 and 1).
    move_rate_deg_s : float, optional
        Table rate during the moves [°/s] (default 10).
    latitude_deg : float, optional
        Site latitude [°] (the earth rate; default 40).
    arw_deg_sqrt_h : float, optional
        Gyro angle random walk [°/√h] (default 0.003).
    truth : TurntableTruth or None, optional
        The triad's errors (default :class:`TurntableTruth`'s).
    encoder_noise_arcsec : float, optional
        Encoder reading noise σ [″] (default 0).
    alpha0_deg, beta0_deg : float, optional
        Encoder readings at the schedule's zero [°] (default 0).
    positions_deg : tuple of (float, float), optional
        The (α, β) positions [°] (default the sixteen of the source).
    g_sensitivity_deg_h_g : array_like, shape (3, 3), optional
        The gyro's sensitivity to specific force ``A`` [°/h per g] (row the gyro axis,
        column the specific force's axis; default none): each sample reads ``A f`` more,
        ``f`` the specific force at the interval's mid angles [g] (normal gravity at the
        latitude over standard gravity).

    Returns
    -------
    rec : Recording
        ``time`` [s], ``gyro_x/y/z`` [°/s, mean rate over the interval ending at each
        sample], ``alpha_deg``/``beta_deg`` [°, encoder angles at the sample times,
        wrapped to [0, 360)].
    truth : dict
        JSON-ready truth (``bias_deg_h``, ``scale_factor_ppm``, ``misalignment_arcsec``,
        ``error_matrix``, ``inner_axis_azimuth_arcsec``, ``latitude_deg``, ``seed``, …).

    Raises
    ------
    ValueError
        ``rate_hz`` not positive.
    thermocal.errors.ParameterError
        More samples than :data:`MAX_SIMULATED_SAMPLES`.

    Notes
    -----
    Each sample's gyro output, with :math:`\omega` the true body rate (table and earth):

    .. math:: \omega_\mathrm{meas} = (I + E)\,\omega + b + A f + n, \qquad
              \sigma_n = \mathrm{ARW} / \sqrt{\tau}

    References
    ----------
    - *A method for separating the combined error coefficients of a ring-laser gyro triad
      based on dual-axis rotation*, Chinese invention patent CN104880182.
    """
    if rate_hz <= 0:
        raise ValueError("rate_hz must be positive")
    tr = truth if truth is not None else TurntableTruth()
    rng = np.random.default_rng(seed)
    sched = build_schedule(alpha0_deg=alpha0_deg, beta0_deg=beta0_deg, dwell_s=dwell_s,
                           move_rate_deg_s=move_rate_deg_s, settle_s=settle_s,
                           positions_deg=positions_deg)  # fmt: skip
    tau = 1.0 / rate_hz
    n, t, a_deg, b_deg, omega_true = _sampled_motion(sched, rate_hz, latitude_deg)
    a_sens = np.zeros((3, 3)) if g_sensitivity_deg_h_g is None else (
        np.asarray(g_sensitivity_deg_h_g, dtype=np.float64).reshape(3, 3))  # fmt: skip
    omega_meas = _gyro16(omega_true, tr, a_sens, (a_deg, b_deg), latitude_deg, rng,
                         (arw_deg_sqrt_h, tau))  # fmt: skip
    enc_sigma_deg = encoder_noise_arcsec * units.ARCSEC_TO_DEG
    a_enc = a_deg + rng.standard_normal(n) * enc_sigma_deg
    b_enc = b_deg + rng.standard_normal(n) * enc_sigma_deg
    rec = _recording16(t, omega_meas * units.RAD_TO_DEG, a_enc, b_enc, tau, latitude_deg, seed)
    settings = {"latitude_deg": latitude_deg, "seed": seed, "rate_hz": rate_hz,
                "dwell_s": dwell_s, "move_rate_deg_s": move_rate_deg_s,
                "arw_deg_sqrt_h": arw_deg_sqrt_h, "encoder_noise_arcsec": encoder_noise_arcsec,
                "duration_s": float(t[-1]), "g_sensitivity_deg_h_g": a_sens.tolist()}  # fmt: skip
    return rec, _truth16(tr, settings)


def _gyro16(
    omega_true: FloatArray,
    tr: TurntableTruth,
    a_sens: FloatArray,
    angles_deg: tuple[FloatArray, FloatArray],
    latitude_deg: float,
    rng: np.random.Generator,
    arw_tau: tuple[float, float],
) -> FloatArray:
    """The gyro outputs [rad/s] of :func:`simulate_turntable16`: ``(I + E) ω + b + n`` (the
    noise drawn first, σ = ARW/√τ from ``arw_tau`` = (ARW [°/√h], τ [s])) plus ``A f``."""
    n = omega_true.shape[0]
    arw_rad_sqrt_s = arw_tau[0] * units.DEG_TO_RAD / np.sqrt(units.SECONDS_PER_HOUR)
    noise = rng.standard_normal((n, 3)) * (arw_rad_sqrt_s / np.sqrt(arw_tau[1]))
    bias = np.asarray(tr.bias_deg_h) * units.DH_TO_RS
    out: FloatArray = omega_true @ (np.eye(3) + tr.error_matrix).T + bias + noise
    out += _specific_force_g(*angles_deg, latitude_deg) @ a_sens.T * units.DH_TO_RS
    return out


def _specific_force_g(a_deg: FloatArray, b_deg: FloatArray, latitude_deg: float) -> FloatArray:
    """The specific force [g] at each interval's mid angles (row 0 at rest), normal gravity."""
    a_mid = 0.5 * (a_deg + np.concatenate([a_deg[:1], a_deg[:-1]]))
    b_mid = 0.5 * (b_deg + np.concatenate([b_deg[:1], b_deg[:-1]]))
    return specific_force_g(a_mid, b_mid, units.normal_gravity_m_s2(latitude_deg))


def _recording16(
    t: FloatArray,
    gyro_deg_s: FloatArray,
    a_enc: FloatArray,
    b_enc: FloatArray,
    tau: float,
    latitude_deg: float,
    seed: int,
) -> Recording:
    """A run of :func:`simulate_turntable16` as a recording (encoders wrapped to [0, 360))."""
    return Recording.from_arrays(
        t,
        signals={c: gyro_deg_s[:, k] for k, c in enumerate(GYRO_COLUMNS)},
        signal_unit="deg/s",
        other={ALPHA_COLUMN: np.mod(a_enc, 360.0), BETA_COLUMN: np.mod(b_enc, 360.0)},
        other_units={ALPHA_COLUMN: "deg", BETA_COLUMN: "deg"},
        meta=Metadata(
            sample_interval_s=tau,
            latitude_deg=latitude_deg,
            run_id=f"turntable-16 seed {seed}",
            notes="simulated 16-position dual-axis turntable run (thermocal turntable-16)",
            extra={"scenario": "turntable-16"},
        ),
    )


def _truth16(tr: TurntableTruth, settings: dict[str, Any]) -> dict[str, Any]:
    """The JSON-ready truth of :func:`simulate_turntable16`: the errors, then ``settings``."""
    return {
        "scenario": "turntable-16",
        **tr.to_dict(),
        **settings,
        "columns": {
            "time": "time",
            "gyro": list(GYRO_COLUMNS),
            "alpha": ALPHA_COLUMN,
            "beta": BETA_COLUMN,
        },
        "constraint": "inner encoder zero exact (defines body x azimuth); "
        "inner_axis_azimuth_arcsec = (yx - xy)/2",
    }


# --- several soaks: the error model over temperature ------------------------------------

THERMAL_TREF_C = 20.0
"""Reference temperature of the thermal truth's polynomials [°C]."""

GYRO_THERMAL_TRUTH: dict[str, tuple[tuple[float, ...], ...]] = {
    # coefficients of (T − TREF)^0..3 per element of θ: cubic biases [°/h], quadratic
    # scale factors [ppm], linear misalignments [″] (a tactical-grade triad)
    "bias": (
        (0.05, 2.0e-3, -3.0e-5, 4.0e-7),
        (-0.03, -1.5e-3, 2.0e-5, -3.0e-7),
        (0.02, 1.0e-3, 1.0e-5, 2.0e-7),
    ),
    "scale_factor": ((60.0, 1.2, 0.015), (-40.0, -0.8, 0.010), (25.0, 1.5, -0.012)),
    "misalignment": (
        (30.0, 0.25),
        (-25.0, 0.15),
        (-10.0, -0.2),
        (15.0, 0.1),
        (40.0, -0.3),
        (-35.0, 0.2),
    ),
}
ACCEL_THERMAL_TRUTH: dict[str, tuple[tuple[float, ...], ...]] = {
    # biases [mg], scale factors [ppm], misalignments [″]
    "bias": (
        (1.2, 0.02, -3.0e-4, 2.0e-6),
        (-0.8, -0.015, 2.0e-4, -1.0e-6),
        (0.5, 0.01, 1.0e-4, 1.5e-6),
    ),
    "scale_factor": ((150.0, 2.5, 0.02), (-120.0, -2.0, 0.015), (90.0, 3.0, -0.02)),
    "misalignment": (
        (20.0, 0.3),
        (-15.0, 0.2),
        (10.0, -0.25),
        (25.0, 0.15),
        (-30.0, 0.1),
        (12.0, -0.2),
    ),
}


def thermal_theta(spec: dict[str, tuple[tuple[float, ...], ...]], temp_c: Any) -> FloatArray:
    """θ (…, 12) of a thermal truth at temperatures [°C] (polynomials in T − TREF).

    Parameters
    ----------
    spec : dict
        ``bias``, ``scale_factor``, ``misalignment``: per parameter, the coefficients of
        ascending powers of ``T − THERMAL_TREF_C`` [°/h, ppm, arcsec per °C^p].
    temp_c : array_like
        Temperatures [°C].

    Returns
    -------
    numpy.ndarray, shape (..., 12)
        θ (biases [°/h], scale factors [ppm], misalignments [arcsec]).

    Notes
    -----
    .. math:: \\theta_k(T) = \\sum_p c_{kp} (T - T_\\mathrm{ref})^p
    """
    d = np.asarray(temp_c, dtype=np.float64) - THERMAL_TREF_C
    cols = [
        np.polynomial.polynomial.polyval(d, np.asarray(c))
        for key in ("bias", "scale_factor", "misalignment")
        for c in spec[key]
    ]
    out: FloatArray = np.stack(cols, axis=-1)
    return out


def _thermal_truth(
    label: str,
    soak: float,
    mean_t: float,
    drift_c: float,
    g: float,
    latitude_deg: float,
    seed: int,
    rate_hz: float,
    arw_deg_sqrt_h: float,
    accel_noise_mg: float,
) -> dict[str, Any]:
    """The truth of one run of :func:`simulate_turntable_thermal`: the polynomials, the run's
    mean temperature ``mean_t`` [°C] and θ at it, and the simulation's settings."""
    return {
        "scenario": "turntable-thermal",
        "label": label,
        "soak_c": soak,
        "held_out": label.startswith("heldout"),
        "temperature_c": mean_t,
        "drift_c": drift_c,
        "tref_c": THERMAL_TREF_C,
        "gyro_polynomials": {k: [list(c) for c in v] for k, v in GYRO_THERMAL_TRUTH.items()},
        "accel_polynomials": {k: [list(c) for c in v] for k, v in ACCEL_THERMAL_TRUTH.items()},
        "gyro_theta_at_mean": thermal_theta(GYRO_THERMAL_TRUTH, mean_t).tolist(),
        "accel_theta_at_mean": thermal_theta(ACCEL_THERMAL_TRUTH, mean_t).tolist(),
        "gravity_m_s2": g,
        "latitude_deg": latitude_deg,
        "seed": seed,
        "rate_hz": rate_hz,
        "arw_deg_sqrt_h": arw_deg_sqrt_h,
        "accel_noise_mg": accel_noise_mg,
    }


def _kinematic(
    positions: tuple[tuple[float, float], ...],
    dwell_s: float,
    move_rate_deg_s: float,
    rate_hz: float,
    latitude_deg: float,
    g: float,
) -> tuple[Any, ...]:
    """The sampled schedule through ``positions``: samples, times [s], α, β [°], true body
    rate [rad/s] and true specific force [m/s²]."""
    sched = build_schedule(
        dwell_s=dwell_s, move_rate_deg_s=move_rate_deg_s, positions_deg=positions
    )
    n, t, a_deg, b_deg, omega = _sampled_motion(sched, rate_hz, latitude_deg)
    a, b = a_deg * units.DEG_TO_RAD, b_deg * units.DEG_TO_RAD
    f = np.einsum("nji,j->ni", kinematics.mat_nb(a, b), np.array([0.0, 0.0, g]))
    return n, t, a_deg, b_deg, omega, f


def _thermal_outputs(
    omega_true: FloatArray,
    f_true: FloatArray,
    temp: FloatArray,
    rng: np.random.Generator,
    gyro_sigma_rad_s: float,
    accel_noise_mg: float,
) -> tuple[FloatArray, FloatArray]:
    """The gyro [rad/s] and accelerometer [m/s²] outputs with the thermal truth's errors at
    each sample's temperature and white noise (the gyro's drawn first)."""
    tg = thermal_theta(GYRO_THERMAL_TRUTH, temp)
    ta = thermal_theta(ACCEL_THERMAL_TRUTH, temp)
    e_g = model.error_matrices(tg)
    e_a = model.error_matrices(ta)
    n = omega_true.shape[0]
    gyro = (
        omega_true
        + np.einsum("nij,nj->ni", e_g, omega_true)
        + tg[:, 0:3] * units.DH_TO_RS
        + rng.standard_normal((n, 3)) * gyro_sigma_rad_s
    )
    acc = (
        f_true
        + np.einsum("nij,nj->ni", e_a, f_true)
        + ta[:, 0:3] * units.MG_TO_MS2
        + rng.standard_normal((n, 3)) * accel_noise_mg * units.MG_TO_MS2
    )
    return gyro, acc


def _with_g_sensitivity(
    gyro: FloatArray, f_true: FloatArray, a_deg_h_g: npt.ArrayLike | None
) -> FloatArray:
    """The gyro [rad/s] plus :math:`A f`, ``A`` [°/h per g] and ``f`` the true specific force
    [m/s²] over :math:`g_0` = 9.80665 m/s² (unchanged without ``A``)."""
    if a_deg_h_g is None:
        return gyro
    a_sens = np.asarray(a_deg_h_g, dtype=np.float64).reshape(3, 3)
    out: FloatArray = gyro + (f_true / units.STANDARD_GRAVITY_M_S2) @ a_sens.T * units.DH_TO_RS
    return out


def _thermal_recording(
    t: FloatArray,
    gyro: FloatArray,
    acc: FloatArray,
    temp: FloatArray,
    encoders: tuple[FloatArray, FloatArray],
    tau: float,
    latitude_deg: float,
    run: str,
) -> Recording:
    """One run of :func:`simulate_turntable_thermal` as a recording."""
    return Recording.from_arrays(
        t,
        signals={c: gyro[:, k] * units.RAD_TO_DEG for k, c in enumerate(GYRO_COLUMNS)},
        temperatures={"T_imu": temp},
        signal_unit="deg/s",
        other={
            **{f"accel_{ax}": acc[:, k] for k, ax in enumerate("xyz")},
            ALPHA_COLUMN: encoders[0],
            BETA_COLUMN: encoders[1],
        },
        other_units={
            **{f"accel_{ax}": "m/s^2" for ax in "xyz"},
            ALPHA_COLUMN: "deg",
            BETA_COLUMN: "deg",
        },
        meta=Metadata(
            sample_interval_s=tau,
            latitude_deg=latitude_deg,
            run_id=f"turntable-thermal {run}",
            notes="simulated 16-position run at a soak temperature (turntable-thermal)",
            extra={"scenario": "turntable-thermal"},
        ),
    )


def simulate_turntable_thermal(
    seed: int = 0,
    *,
    soaks_c: tuple[float, ...] = (-40.0, -20.0, 0.0, 20.0, 40.0, 60.0),
    held_out_c: float = 10.0,
    drift_c: float = 1.5,
    rate_hz: float = 20.0,
    dwell_s: float = 60.0,
    move_rate_deg_s: float = 10.0,
    latitude_deg: float = 40.0,
    arw_deg_sqrt_h: float = 0.01,
    accel_noise_mg: float = 0.05,
    encoder_noise_arcsec: float = 0.0,
    drop_position: tuple[str, int] | None = None,
    g_sensitivity_deg_h_g: npt.ArrayLike | None = None,
) -> list[tuple[Recording, dict[str, Any]]]:
    r"""16-position runs at several soaks plus a held-out run at an unseen one, of a gyro and
    an accelerometer triad whose every parameter follows :data:`GYRO_THERMAL_TRUTH` /
    :data:`ACCEL_THERMAL_TRUTH` at each sample's temperature; the soak drifts by ``drift_c``.

    Parameters
    ----------
    seed : int, optional
        Seed of the noise (default 0).
    soaks_c : tuple of float, optional
        The soak temperatures [°C].
    held_out_c : float, optional
        The held-out run's soak [°C] (default 10).
    drift_c : float, optional
        Temperature drift across each run [°C] (default 1.5).
    rate_hz : float, optional
        Sample rate [Hz] (default 20).
    dwell_s : float, optional
        Dwell at each position [s] (default 60).
    move_rate_deg_s : float, optional
        Table rate during the moves [°/s] (default 10).
    latitude_deg : float, optional
        Site latitude [°] (earth rate and normal gravity; default 40).
    arw_deg_sqrt_h : float, optional
        Gyro angle random walk [°/√h] (default 0.01).
    accel_noise_mg : float, optional
        Accelerometer white noise per sample [mg] (default 0.05).
    encoder_noise_arcsec : float, optional
        Encoder reading noise σ [″] (default 0).
    drop_position : tuple of (str, int) or None, optional
        ``(label, index)``: that run misses that position (default none).
    g_sensitivity_deg_h_g : array_like, shape (3, 3), optional
        The gyro's sensitivity ``A`` [°/h per g], constant in temperature: :math:`A f`
        added to the gyro, ``f`` the true specific force in g (default none).

    Returns
    -------
    list of (Recording, dict)
        Each run: ``time`` [s], ``gyro_x/y/z`` [°/s], ``accel_x/y/z`` [m/s²],
        ``alpha_deg``/``beta_deg`` [°], ``T_imu`` [°C]; and its truth (the polynomials, the
        run's mean temperature and θ at it).

    Notes
    -----
    With :math:`\theta(T)` of :func:`thermal_theta` at each sample's temperature:

    .. math:: \omega_\mathrm{meas} = (I + E_g(T))\,\omega + b_g(T) + n_g, \qquad
              f_\mathrm{meas} = (I + E_a(T))\,f + b_a(T) + n_a

    References
    ----------
    - *A method for separating the combined error coefficients of a ring-laser gyro triad
      based on dual-axis rotation*, Chinese invention patent CN104880182.
    """
    tau = 1.0 / rate_hz
    g = units.normal_gravity_m_s2(latitude_deg)
    motion = (dwell_s, move_rate_deg_s, rate_hz, latitude_deg, g)
    full = _kinematic(POSITIONS_16, *motion)
    runs = [(f"T{c:+g}", c) for c in soaks_c] + [(f"heldout_T{held_out_c:+g}", held_out_c)]
    ss = np.random.SeedSequence([int(seed), 19])
    out: list[tuple[Recording, dict[str, Any]]] = []
    for (label, soak), child in zip(runs, ss.spawn(len(runs)), strict=True):
        rng = np.random.default_rng(child)
        n, t, a_deg, b_deg, omega_true, f_true = full
        if drop_position is not None and drop_position[0] == label:
            kept = tuple(pos for i, pos in enumerate(POSITIONS_16) if i != drop_position[1])
            n, t, a_deg, b_deg, omega_true, f_true = _kinematic(kept, *motion)
        temp = soak + drift_c * (t / t[-1] - 0.5)
        arw = arw_deg_sqrt_h * units.DEG_TO_RAD / np.sqrt(units.SECONDS_PER_HOUR)
        gyro, acc = _thermal_outputs(omega_true, f_true, temp, rng, arw / np.sqrt(tau),
                                     accel_noise_mg)  # fmt: skip
        gyro = _with_g_sensitivity(gyro, f_true, g_sensitivity_deg_h_g)
        enc = encoder_noise_arcsec * units.ARCSEC_TO_DEG
        alpha = np.mod(a_deg + rng.standard_normal(n) * enc, 360.0)
        beta = np.mod(b_deg + rng.standard_normal(n) * enc, 360.0)
        rec = _thermal_recording(
            t, gyro, acc, temp, (alpha, beta), tau, latitude_deg, f"seed {seed} {label}"
        )
        truth = _thermal_truth(
            label, soak, float(np.mean(temp)), drift_c, g, latitude_deg, seed, rate_hz,
            arw_deg_sqrt_h, accel_noise_mg,
        )  # fmt: skip
        out.append((rec, truth))
    return out
