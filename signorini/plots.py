"""Figures. Every function takes ``ax=None`` and returns the Axes it drew on."""

from __future__ import annotations

from typing import Iterable

import numpy as np

from .analytic import hertz_pressure


def _axes(ax):
    if ax is None:
        from matplotlib.figure import Figure
        ax = Figure(figsize=(6.4, 4.2), layout="constrained").add_subplot()
    return ax


def pressure_profile(x: np.ndarray, pressure: np.ndarray, *, a_ref: float | None = None,
                     p0_ref: float | None = None, label: str = "numeric", ax=None,
                     others: Iterable[tuple[str, np.ndarray]] = ()):
    """Nodal pressure against x, with Hertz's ``p₀√(1 − x²/a²)`` when ``a_ref`` is given.

    Lengths are shown in units of ``a_ref`` and pressures in units of
    ``p0_ref`` when both are given. ``others`` adds ``(label, pressure)``
    series at the same x (other methods), drawn as markers.
    """
    ax = _axes(ax)
    xs = 1.0 if a_ref is None else a_ref
    ps = 1.0 if p0_ref is None else p0_ref
    if a_ref is not None and p0_ref is not None:
        grid = np.linspace(0.0, float(x.max()), 800)
        ax.plot(grid / xs, hertz_pressure(grid, a_ref, p0_ref) / ps, "k-", lw=1.5, label="Hertz")
    ax.plot(x / xs, pressure / ps, "o", ms=3, mfc="none", label=label)
    for i, (name, values) in enumerate(others):
        ax.plot(x / xs, values / ps, ".", ms=2, label=name, alpha=0.7, zorder=2 + i)
    ax.set_xlabel("x / a (Hertz)" if a_ref is not None else "x")
    ax.set_ylabel("p / p₀ (Hertz)" if p0_ref is not None else "p")
    ax.set_xlim(left=0.0)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, ncol=2)
    return ax


def kkt_against_time(rows: list[dict], *, ax=None, title: str = ""):
    """Worst relative KKT residual against solve time, one marker per run (log–log)."""
    ax = _axes(ax)
    for row in rows:
        time_s, kkt = row["time_s"], row["kkt_worst"]
        if not (np.isfinite(kkt) and kkt > 0 and time_s > 0):
            continue
        marker = "o" if row["status"] == "converged" else "x"
        ax.loglog(time_s, max(kkt, 1e-17), marker, label=f"{row['label']} ({row['status']})")
    ax.set_xlabel("build + solve time [s]")
    ax.set_ylabel("worst relative KKT residual")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=6, ncol=2)
    if title:
        ax.set_title(title, fontsize=9)
    return ax


def residual_history(history: dict[str, list[float]], *, ax=None, keys: Iterable[str] | None = None):
    """Residuals recorded per iteration by a solver (semilog)."""
    ax = _axes(ax)
    for key in keys or history:
        values = np.asarray(history[key], dtype=float)
        if values.size:
            ax.semilogy(np.arange(1, values.size + 1), np.maximum(values, 1e-18), label=key)
    ax.set_xlabel("iteration")
    ax.set_ylabel("relative residual")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7)
    return ax
