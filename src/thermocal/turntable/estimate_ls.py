"""Batch least squares for the turntable calibration (our cross-check of
the source's filter).

The data are cut into blocks of sample intervals: each dwell is one block (its
angle increments are the static averages projected on the gimbal axes, times the
dwell length) and each rotation is cut into blocks of at most ``max_move_block_s``
(the gyro-integrated angle against the encoder's over each piece of the move).
For block j and channel c ∈ {α, β, γ} (model eq. (4) summed over the block)::

    Y_cj = Σ_i y_ci = (Σ_i h_ci) θ + W_cj,     cov W_j = Σ_i cov w_i

With encoder noise σ_e the α, β increments of blocks sharing an end point are
correlated (``C = blockdiag(cov W_j) + σ_e² (D Dᵀ ⊗ diag(1, 1, 0))``, D the
block/end-point incidence); the system is
whitened by the Cholesky factor of C and solved by SVD (generalised least squares;
Kay 1993, §4.5 and §8.3), with covariance ``(Aᵀ C⁻¹ A)⁻¹`` from the singular values.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt

from thermocal._lazy import LazyModule
from thermocal.errors import DesignError
from thermocal.turntable.model import N_COEFFS, IntervalModel
from thermocal.turntable.schedule import runs

if TYPE_CHECKING:
    from scipy import linalg as sla
else:
    sla = LazyModule("scipy.linalg")

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.intp]


@dataclass(frozen=True)
class Blocks:
    """Sample-interval blocks and their sums.

    Attributes
    ----------
    start, stop : interval index ranges ``[start, stop)``, (k,).
    restart : True where the block starts a new integration (record start, after a gap).
    static : True for blocks at rest.
    duration_s : block lengths [s].
    y : summed measurements (k, c) [arcsec]; h : summed regressors (k, c, 12);
    cov : summed white-noise covariances (k, c, c) [arcsec²].
    """

    start: IntArray
    stop: IntArray
    restart: npt.NDArray[np.bool_]
    static: npt.NDArray[np.bool_]
    duration_s: FloatArray
    y: FloatArray
    h: FloatArray
    cov: FloatArray

    @property
    def n(self) -> int:
        return int(self.start.size)

    @property
    def n_channels(self) -> int:
        return int(self.y.shape[1])


def make_blocks(
    m: IntervalModel,
    arw_rad_sqrt_s: npt.ArrayLike,
    *,
    max_static_block_s: float | None = None,
    max_move_block_s: float = 1.0,
) -> Blocks:
    r"""Cut the valid intervals into blocks: static runs whole (or in pieces of at most
    ``max_static_block_s``), moving runs in pieces of at most ``max_move_block_s``.

    Parameters
    ----------
    m : IntervalModel
        The per-interval measurement model of the run (:mod:`.model`, eq. (4)).
    arw_rad_sqrt_s : array_like
        Angle random walk of each gyro axis [rad/√s] (scalar or (3,)): the white noise
        whose covariance each interval carries.
    max_static_block_s : float or None, optional
        Longest block at rest [s] (default ``None``: each dwell is one block).
    max_move_block_s : float, optional
        Longest block of a rotation [s] (default 1).

    Returns
    -------
    Blocks
        The blocks' index ranges, kinds, durations [s] and their summed measurements
        [arcsec], regressors and white-noise covariances [arcsec²].

    Notes
    -----
    For block :math:`j` and channel :math:`c` the intervals :math:`i` of the block are summed:

    .. math:: Y_{cj} = \sum_i y_{ci} = \Big(\sum_i h_{ci}\Big)\,\theta + W_{cj},
              \qquad \operatorname{cov} W_j = \sum_i \operatorname{cov} w_i

    References
    ----------
    - *A method for separating the combined error coefficients of a ring-laser gyro triad
      based on dual-axis rotation*, Chinese invention patent CN104880182, eq. (4).
    """
    starts: list[int] = []
    stops: list[int] = []
    restart: list[bool] = []
    static: list[bool] = []
    t_cum = np.concatenate([[0.0], np.cumsum(m.dt_s)])
    for a, b in runs(m.valid):
        first = True
        mov = m.moving[a:b]
        edges = np.flatnonzero(np.diff(mov.astype(np.int8))) + 1 + a
        bounds = [a, *edges.tolist(), b]
        for s0, s1 in itertools.pairwise(bounds):
            is_static = not bool(m.moving[s0])
            limit = max_static_block_s if is_static else max_move_block_s
            pieces = [s0, s1]
            if limit is not None and limit > 0:
                dur = t_cum[s1] - t_cum[s0]
                k = int(np.ceil(dur / limit - 1e-9))
                if k > 1:
                    targets = t_cum[s0] + np.arange(1, k) * (dur / k)
                    cuts = np.searchsorted(t_cum, targets)
                    pieces = sorted({s0, s1, *[int(c) for c in cuts if s0 < c < s1]})
            for p0, p1 in itertools.pairwise(pieces):
                starts.append(p0)
                stops.append(p1)
                restart.append(first)
                static.append(is_static)
                first = False
    st = np.asarray(starts, dtype=np.intp)
    sp = np.asarray(stops, dtype=np.intp)
    if st.size == 0:
        raise DesignError("no valid sample intervals to estimate from")
    cov_i = m.channel_cov(arw_rad_sqrt_s)
    idx = np.ravel(np.column_stack([st, sp]))

    def block_sum(x: FloatArray) -> FloatArray:
        """Sums over [start, stop) of each block (np.add.reduceat on start/stop pairs)."""
        xp = np.concatenate([x, np.zeros((1, *x.shape[1:]))])
        out: FloatArray = np.add.reduceat(xp, idx, axis=0)[::2]
        return out

    return Blocks(
        start=st,
        stop=sp,
        restart=np.asarray(restart),
        static=np.asarray(static),
        duration_s=t_cum[sp] - t_cum[st],
        y=block_sum(m.y_arcsec),
        h=block_sum(m.h),
        cov=block_sum(cov_i),
    )


@dataclass(frozen=True)
class LsEstimate:
    """Least-squares estimate of θ (12, units of :mod:`.model`).

    ``cov`` is the covariance (known-noise GLS), ``chi2``/``dof`` the whitened
    residual sum of squares and degrees of freedom, ``singular_values`` of the
    whitened, column-normalised design and ``rank``.

    Attributes
    ----------
    theta : numpy.ndarray, shape (12,)
        The estimate (units of :mod:`.model`).
    cov : numpy.ndarray, shape (12, 12)
        Its covariance (known-noise GLS).
    chi2 : float
        Whitened residual sum of squares [-].
    dof : int
        Degrees of freedom.
    n_blocks : int
        Blocks used.
    singular_values : numpy.ndarray
        Of the whitened, column-normalised design.
    rank : int
        Singular values kept.
    """

    theta: FloatArray
    cov: FloatArray
    chi2: float
    dof: int
    n_blocks: int
    singular_values: FloatArray
    rank: int

    @property
    def sigma(self) -> FloatArray:
        out: FloatArray = np.sqrt(np.diag(self.cov))
        return out


def block_covariance(blocks: Blocks, encoder_noise_arcsec: float = 0.0) -> FloatArray:
    r"""Joint covariance of all block increments, rows ordered (block, channel) [arcsec²].

    A block's start point is the previous block's end point unless the block restarts the
    integration, so the encoder noise correlates the α, β increments of neighbours.

    Parameters
    ----------
    blocks : Blocks
        The blocks (:func:`make_blocks`).
    encoder_noise_arcsec : float, optional
        Encoder reading noise σ_e [arcsec] (default 0: the blocks are independent).

    Returns
    -------
    numpy.ndarray, shape (k·c, k·c)
        The covariance [arcsec²].

    Notes
    -----
    .. math:: C = \operatorname{blockdiag}(\operatorname{cov} W_j)
              + \sigma_e^2 \, (D D^\mathsf{T} \otimes \operatorname{diag}(1, 1[, 0]))

    with :math:`D` the block/end-point incidence matrix.

    References
    ----------
    - S. M. Kay, *Fundamentals of Statistical Signal Processing: Estimation Theory*,
      Prentice Hall, 1993, §4.5 and §8.3.
    """
    k, nc = blocks.n, blocks.n_channels
    c = sla.block_diag(*blocks.cov)
    if encoder_noise_arcsec > 0:
        d = np.zeros((k, k + int(np.count_nonzero(blocks.restart))))
        point = -1
        for j in range(k):
            if blocks.restart[j]:
                point += 1
            d[j, point] = -1.0
            point += 1
            d[j, point] = 1.0
        enc = np.zeros((nc, nc))
        enc[0, 0] = enc[1, 1] = encoder_noise_arcsec**2
        c = c + np.kron(d @ d.T, enc)
    out: FloatArray = c
    return out


def solve_ls(
    blocks: Blocks, *, encoder_noise_arcsec: float = 0.0, rcond: float = 1e-12
) -> LsEstimate:
    r"""Generalised least squares of θ on the block increments of all channels.

    Whitened by the Cholesky factor of :func:`block_covariance`; columns are
    normalised before the SVD; singular values below ``rcond`` × the largest are
    dropped (their directions get an infinite variance).

    Parameters
    ----------
    blocks : Blocks
        The blocks (:func:`make_blocks`).
    encoder_noise_arcsec : float, optional
        Encoder reading noise σ_e [arcsec] (default 0).
    rcond : float, optional
        Relative cut-off of the singular values [-] (default 1e-12).

    Returns
    -------
    LsEstimate
        θ (12: bias [°/h], scale factors [ppm], misalignments [″]), its covariance, the
        whitened χ², degrees of freedom, singular values and rank.

    Notes
    -----
    With :math:`L L^\mathsf{T} = C`, :math:`A = L^{-1} H` and :math:`y = L^{-1} Y`:

    .. math:: \hat\theta = (A^\mathsf{T} A)^{-1} A^\mathsf{T} y, \qquad
              \operatorname{cov}\hat\theta = (H^\mathsf{T} C^{-1} H)^{-1}

    References
    ----------
    - S. M. Kay, *Fundamentals of Statistical Signal Processing: Estimation Theory*,
      Prentice Hall, 1993, §4.5 and §8.3.
    - *A method for separating the combined error coefficients of a ring-laser gyro triad
      based on dual-axis rotation*, Chinese invention patent CN104880182, eq. (4).
    """
    if encoder_noise_arcsec > 0:
        low = sla.cholesky(block_covariance(blocks, encoder_noise_arcsec), lower=True)
        a = sla.solve_triangular(low, blocks.h.reshape(-1, N_COEFFS), lower=True)
        y = sla.solve_triangular(low, blocks.y.reshape(-1), lower=True)
    else:  # blocks independent: whiten each block's channels by its own Cholesky factor
        low_b = np.linalg.cholesky(blocks.cov)
        a = np.linalg.solve(low_b, blocks.h).reshape(-1, N_COEFFS)
        y = np.linalg.solve(low_b, blocks.y[:, :, None]).reshape(-1)
    scale = np.linalg.norm(a, axis=0)
    scale[scale == 0] = 1.0
    an = a / scale
    u, s, vt = np.linalg.svd(an, full_matrices=False)
    keep = s > rcond * s[0]
    inv_s = np.where(keep, 1.0 / np.where(keep, s, 1.0), 0.0)
    theta_n = vt.T @ (inv_s * (u.T @ y))
    theta = theta_n / scale
    vs = vt.T * inv_s
    cov_n = vs @ vs.T
    cov = cov_n / np.outer(scale, scale)
    big = ~keep
    if np.any(big):
        cov = cov + np.inf * (np.abs(vt[big]).T @ np.abs(vt[big]) > 1e-6)
    resid = y - a @ theta
    rank = int(np.count_nonzero(keep))
    return LsEstimate(
        theta=theta,
        cov=cov,
        chi2=float(resid @ resid),
        dof=int(y.size - rank),
        n_blocks=blocks.n,
        singular_values=s,
        rank=rank,
    )
