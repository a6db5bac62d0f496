"""The multi-position part of a triad report: the held-out session's poses on
the sphere and the gravity-magnitude residual of each.

Each still pose's compensated mean specific force, normalised, is the gravity ("up")
direction in body axes: a point on the unit sphere.  The sphere is drawn as its two
hemispheres, ``z ≥ 0`` seen from +z and ``z < 0`` seen from −z, each in the orthographic
projection ``(u_x, u_y)`` (the unit disc), each point coloured by its residual
``|mean f| − g`` after compensation and numbered as in the table.  Poses spread over both
hemispheres are what the gravity-magnitude fit needs (at least 9 distinct poses, not in one
plane; Tedaldi et al. 2014).  matplotlib is imported here only.
"""

from __future__ import annotations

import base64
from collections.abc import Sequence
from typing import Any

import numpy as np


def _png_b64(fig: Any) -> str:
    from thermocal.report.figures import _png

    return "data:image/png;base64," + base64.b64encode(_png(fig)).decode("ascii")


def sphere_figure(up: Any, residual: Any, unit: str) -> str:
    """The poses' up directions ``up`` (m, 3) on the two hemispheres, coloured by
    ``residual`` (m,) [``unit``] (module docstring); a PNG data URI.

    Parameters
    ----------
    up : numpy.ndarray
        Unit gravity directions in body axes (n, 3).
    residual : numpy.ndarray
        Gravity-magnitude residuals (n,) [``unit``].
    unit : str
        The data's unit (``"deg/h"``, ``"mg"``).

    Returns
    -------
    str
        The figure as a PNG data URI.
    """
    import matplotlib

    matplotlib.use("Agg", force=True)
    from matplotlib.figure import Figure

    u = np.asarray(up, dtype=np.float64)
    r = np.asarray(residual, dtype=np.float64)
    lim = float(np.max(np.abs(r))) if r.size and np.max(np.abs(r)) > 0 else 1.0
    fig = Figure(figsize=(9.0, 4.6), dpi=110, layout="constrained")
    axes = fig.subplots(1, 2)
    circle = np.linspace(0, 2 * np.pi, 200)
    sc = None
    for ax, upper in zip(axes, (True, False), strict=True):
        sel = u[:, 2] >= 0 if upper else u[:, 2] < 0
        ax.plot(np.cos(circle), np.sin(circle), color="#888888", linewidth=0.8)
        for rr in (np.sin(np.radians(30)), np.sin(np.radians(60))):
            ax.plot(rr * np.cos(circle), rr * np.sin(circle), color="#dddddd", linewidth=0.5)
        ax.axhline(0, color="#dddddd", linewidth=0.5)
        ax.axvline(0, color="#dddddd", linewidth=0.5)
        # seen from −z the x axis is mirrored so the picture is the sphere's outside
        x = u[sel, 0] if upper else -u[sel, 0]
        sc = ax.scatter(x, u[sel, 1], c=r[sel], cmap="coolwarm", vmin=-lim, vmax=lim,
                        s=60, edgecolors="black", linewidths=0.5)  # fmt: skip
        for k, xi, yi in zip(np.flatnonzero(sel), x, u[sel, 1], strict=True):
            ax.annotate(str(k + 1), (xi, yi), textcoords="offset points", xytext=(5, 4),
                        fontsize=7)  # fmt: skip
        ax.set_aspect("equal")
        ax.set_xlim(-1.1, 1.1)
        ax.set_ylim(-1.1, 1.1)
        ax.set_xlabel("u_x" if upper else "−u_x (seen from −z)", fontsize=8)
        ax.set_ylabel("u_y", fontsize=8)
        ax.set_title(f"{'upper (z ≥ 0)' if upper else 'lower (z < 0)'}: {int(sel.sum())} "
                     "poses", fontsize=9)  # fmt: skip
        ax.tick_params(labelsize=7)
    if sc is not None:
        fig.colorbar(sc, ax=list(axes), label=f"|mean f| − g after [{unit}]", shrink=0.8)
    return _png_b64(fig)


def pose_section(validation: Sequence[Any] | None) -> dict[str, Any] | None:
    """The report's poses section from the held-out validation
    (:class:`thermocal.multipos.calibrate.MultiposValidation` with ``per_pose``), None
    when there is none: the figure and the table rows (pose, samples, direction,
    residual before and after, in the accelerometer's unit).

    Parameters
    ----------
    validation : sequence, optional
        The held-out validation results.

    Returns
    -------
    dict or None
        The section's context, or None without held-out poses.
    """
    val = next((v for v in validation or () if getattr(v, "per_pose", ())), None)
    if val is None:
        return None
    rows = np.asarray(val.per_pose, dtype=np.float64)
    img = sphere_figure(rows[:, 2:5], rows[:, 6], val.unit)
    return {
        "img": img,
        "unit": val.unit,
        "triad": val.triad,
        "rows": [
            {"k": k + 1, "start": int(r[0]), "end": int(r[1]),
             "u": ", ".join(f"{v:+.4f}" for v in r[2:5]),
             "before": f"{r[5]:.4g}", "after": f"{r[6]:.4g}"}
            for k, r in enumerate(rows)
        ],
    }  # fmt: skip


__all__ = ["pose_section", "sphere_figure"]
