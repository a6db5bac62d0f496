"""The 14-state Kalman filter of the dual-axis turntable source document (CN104880182, claim 4).

State ``x = [θ (12), Δα, Δβ[, Δγ]]``: the twelve coefficients of :mod:`.model` as
random constants ([°/h], [ppm], [arcsec]) and the gyro-integrated gimbal angles minus
the encoder angles [arcsec] — 14 states as in the source, or 15 with the rotation Δγ
about the third axis e_⊥ = e_z × e_E^b whose true value is zero (our reading; see
:mod:`.model`).  Over a block of sample intervals the angle errors grow by
the gyro errors projected on each gimbal axis (model eq. (4) summed over the block;
exact for this linear model, whatever the block length)::

    θ_k = θ_{k−1}
    Δ_k = Δ_{k−1} + G_k θ_{k−1} + w_k

i.e. ``Φ_k = [[I₁₂, 0], [G_k, I]]``, G_k = Σ_i h_i (c×12), Q_k = Σ_i cov w_i.
Measurement, at rest and while rotating::

    z_k = Δ_k − v_k,     H = [0, I],   R = diag(σ_e², σ_e²[, 0]) (plus a tiny floor)

The update uses the Joseph form ``P⁺ = (I − KH) P (I − KH)ᵀ + K R Kᵀ`` for numerical
stability (Bucy & Joseph 1968; Grewal & Andrews, *Kalman Filtering*, 4th ed., §6.4.2).
After a gap in time the integration restarts: Δ is reset to the encoder (zero, variance
σ_e², uncorrelated with θ).  Steps are plain functions (pyins style).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from thermocal.turntable.estimate_ls import Blocks
from thermocal.turntable.model import N_COEFFS

FloatArray = npt.NDArray[np.float64]

R_FLOOR_ARCSEC2 = 1e-8
"""Measurement-noise floor [arcsec²] used when the encoders are taken as perfect."""


def kf_predict(
    x: FloatArray, p: FloatArray, g: FloatArray, q_delta: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """Propagate over one block: ``x ← Φ x``, ``P ← Φ P Φᵀ + Q`` with
    ``Φ = [[I, 0], [G, I]]`` and ``Q = blockdiag(0₁₂, q_delta)``.

    Parameters
    ----------
    x : numpy.ndarray, shape (12 + k,)
        State: θ (biases [°/h], ppm, arcsec) and the k angle increments Δ [arcsec].
    p : numpy.ndarray, shape (12 + k, 12 + k)
        Its covariance.
    g : numpy.ndarray, shape (k, 12)
        The block's regressors G [arcsec per unit of θ].
    q_delta : numpy.ndarray, shape (k, k)
        The block's noise covariance of Δ [arcsec²].

    Returns
    -------
    x, p : numpy.ndarray
        The propagated state and covariance.

    Notes
    -----
    .. math:: x \\leftarrow \\Phi x, \\quad P \\leftarrow \\Phi P \\Phi^\\mathsf{T} + Q

    References
    ----------
    - R. E. Kalman, "A new approach to linear filtering and prediction problems", *Trans.
      ASME J. Basic Engineering* 82(1), 35–45, 1960.
    """
    phi = np.eye(x.size)
    phi[N_COEFFS:, :N_COEFFS] = g
    x_new = phi @ x
    p_new = phi @ p @ phi.T
    p_new[N_COEFFS:, N_COEFFS:] += q_delta
    return x_new, p_new


def kf_update(
    x: FloatArray, p: FloatArray, z: FloatArray, h: FloatArray, r: FloatArray
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Joseph-form measurement update; returns ``(x⁺, P⁺, innovation)``.

    Parameters
    ----------
    x, p : numpy.ndarray
        Prior state (n,) and covariance (n, n).
    z : numpy.ndarray, shape (k,)
        The measurement [arcsec].
    h : numpy.ndarray, shape (k, n)
        Measurement matrix.
    r : numpy.ndarray, shape (k, k)
        Measurement noise covariance [arcsec²].

    Returns
    -------
    x, p, innovation : numpy.ndarray
        Posterior state and covariance, and ``z − H x`` [arcsec].

    Notes
    -----
    .. math:: K = P H^\\mathsf{T} (H P H^\\mathsf{T} + R)^{-1}, \\quad
              P^+ = (I - K H) P (I - K H)^\\mathsf{T} + K R K^\\mathsf{T}

    References
    ----------
    - R. E. Kalman, "A new approach to linear filtering and prediction problems", *Trans.
      ASME J. Basic Engineering* 82(1), 35–45, 1960.

    Examples
    --------
    >>> x, p = np.zeros(1), np.eye(1) * 4.0
    >>> x1, p1, _ = kf_update(x, p, np.array([1.0]), np.eye(1), np.eye(1))
    >>> round(float(x1[0]), 3), round(float(p1[0, 0]), 3)  # K = 4/5
    (0.8, 0.8)
    """
    innov = z - h @ x
    s = h @ p @ h.T + r
    k = np.linalg.solve(s, h @ p).T  # K = P Hᵀ S⁻¹ (S symmetric)
    x_new = x + k @ innov
    ikh = np.eye(x.size) - k @ h
    p_new = ikh @ p @ ikh.T + k @ r @ k.T
    p_new = 0.5 * (p_new + p_new.T)
    return x_new, p_new, innov


def kf_restart(p: FloatArray, x: FloatArray, r: FloatArray) -> None:
    """Reset Δ (in place) at the start of an integration: zero, covariance R.

    Parameters
    ----------
    p : numpy.ndarray, shape (12 + k, 12 + k)
        Covariance, modified in place.
    x : numpy.ndarray, shape (12 + k,)
        State, modified in place.
    r : numpy.ndarray, shape (k, k)
        Covariance of the restarted Δ [arcsec²].
    """
    x[N_COEFFS:] = 0.0
    p[N_COEFFS:, :] = 0.0
    p[:, N_COEFFS:] = 0.0
    p[N_COEFFS:, N_COEFFS:] = r


@dataclass(frozen=True)
class KalmanEstimate:
    """Filter output.

    ``theta``/``cov`` the final coefficient estimate and covariance (12); ``sigma_history``
    the coefficient σ after each update (k, 12); ``innovations`` (k, c) [arcsec] and
    their predicted variances ``innovation_var`` (k, c); ``n_states`` 14 or 15.

    Attributes
    ----------
    theta : numpy.ndarray, shape (12,)
        The final coefficient estimate (units of :mod:`.model`).
    cov : numpy.ndarray, shape (12, 12)
        Its covariance.
    time_index : numpy.ndarray of int, shape (k,)
        The sample interval of each update.
    sigma_history : numpy.ndarray, shape (k, 12)
        The coefficients' σ after each update.
    innovations, innovation_var : numpy.ndarray, shape (k, c)
        Innovations [arcsec] and their predicted variances [arcsec²].
    n_states : int
        14 or 15.
    """

    theta: FloatArray
    cov: FloatArray
    time_index: npt.NDArray[np.intp]
    sigma_history: FloatArray
    innovations: FloatArray
    innovation_var: FloatArray
    n_states: int

    @property
    def sigma(self) -> FloatArray:
        out: FloatArray = np.sqrt(np.diag(self.cov))
        return out

    @property
    def normalised_innovation_rms(self) -> float:
        """rms of innovation/σ (≈ 1 when the noise model fits)."""
        return float(np.sqrt(np.mean(self.innovations**2 / self.innovation_var)))


def run_filter(
    blocks: Blocks,
    prior_sigma: npt.ArrayLike,
    *,
    prior_mean: npt.ArrayLike | None = None,
    encoder_noise_arcsec: float = 0.0,
) -> KalmanEstimate:
    """Run the 14-state filter over the blocks (a measurement at each block end).

    Parameters
    ----------
    blocks : Blocks
        The summed measurement blocks.
    prior_sigma : array_like, shape (12,)
        Initial σ of the coefficients (random constants) [°/h, ppm, arcsec].
    prior_mean : array_like, shape (12,), optional
        Initial mean (default zero).
    encoder_noise_arcsec : float, default 0.0
        White noise of the encoder angles [arcsec].

    Returns
    -------
    KalmanEstimate

    References
    ----------
    - R. E. Kalman, "A new approach to linear filtering and prediction problems", *Trans.
      ASME J. Basic Engineering* 82(1), 35–45, 1960.
    - *A method for separating the combined error coefficients of a ring-laser gyro triad
      based on dual-axis rotation*, Chinese invention patent CN104880182 (the 14-state
      filter).
    """
    ps = np.asarray(prior_sigma, dtype=np.float64).reshape(N_COEFFS)
    nc = blocks.n_channels
    n_states = N_COEFFS + nc
    x = np.zeros(n_states)
    if prior_mean is not None:
        x[:N_COEFFS] = np.asarray(prior_mean, dtype=np.float64)
    p = np.zeros((n_states, n_states))
    p[:N_COEFFS, :N_COEFFS] = np.diag(ps**2)
    r = np.eye(nc) * R_FLOOR_ARCSEC2
    r[0, 0] += encoder_noise_arcsec**2
    r[1, 1] += encoder_noise_arcsec**2
    h = np.zeros((nc, n_states))
    h[:, N_COEFFS:] = np.eye(nc)
    z_cum = np.zeros(nc)
    k_n = blocks.n
    sig = np.empty((k_n, N_COEFFS))
    innov = np.empty((k_n, nc))
    innov_var = np.empty((k_n, nc))
    for j in range(k_n):
        if blocks.restart[j]:
            kf_restart(p, x, r)
            z_cum[:] = 0.0
        x, p = kf_predict(x, p, blocks.h[j], blocks.cov[j])
        z_cum += blocks.y[j]
        innov_var[j] = np.diag(p)[N_COEFFS:] + np.diag(r)
        x, p, innov[j] = kf_update(x, p, z_cum, h, r)
        sig[j] = np.sqrt(np.maximum(np.diag(p)[:N_COEFFS], 0.0))
    return KalmanEstimate(
        theta=x[:N_COEFFS].copy(),
        cov=p[:N_COEFFS, :N_COEFFS].copy(),
        time_index=blocks.stop.copy(),
        sigma_history=sig,
        innovations=innov,
        innovation_var=innov_var,
        n_states=n_states,
    )
