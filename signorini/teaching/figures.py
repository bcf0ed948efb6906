"""The tutorials' figures (docs/tutorials/): the dual function, Uzawa's projections, histories.

Every function takes ``ax=None`` and returns the Axes it drew on.
:func:`~signorini.output.plots.pressure_profile` is re-exported for the
tutorials' pressure plots.
"""

from __future__ import annotations

from typing import Iterable

import numpy as np

from signorini.output.plots import axes, pressure_profile
from signorini.teaching.synthetic import bogie_deflection

__all__ = ["active_set_history", "bogie_shape", "complementarity_by_node", "dual_landscape",
           "duality_gap_history", "nodal_values", "objectives_against_iteration",
           "pressure_profile", "projection_steps", "residual_history"]


def residual_history(history: dict[str, list[float]], *, ax=None, keys: Iterable[str] | None = None):
    """Residuals recorded per iteration by a solver (semilog)."""
    ax = axes(ax)
    for key in keys or history:
        values = np.asarray(history[key], dtype=float)
        if values.size:
            ax.semilogy(np.arange(1, values.size + 1), np.maximum(values, 1e-18), label=key)
    ax.set_xlabel("iteration")
    ax.set_ylabel("relative residual")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7)
    return ax


def _dual_window(points: list[np.ndarray]) -> tuple[tuple[float, float], tuple[float, float]]:
    """A window framing ``points`` and the origin, with room on the infeasible side."""
    stacked = np.vstack([np.zeros(2)] + [np.asarray(p, dtype=float).reshape(2) for p in points])
    hi = np.max(stacked, axis=0)
    lo = np.min(stacked, axis=0)
    span = max(float(np.max(hi - lo)), 1e-12)
    hi = np.maximum(hi, 0.0) + 0.5 * span
    lo = np.minimum(lo, 0.0) - 0.25 * span
    return (float(lo[0]), float(hi[0])), (float(lo[1]), float(hi[1]))


def dual_landscape(dual, *, window=None, maximiser=None, unconstrained=None,
                   paths: Iterable[tuple[str, np.ndarray]] = (),
                   points: Iterable[tuple[str, np.ndarray]] = (), levels: int = 20,
                   resolution: int = 201, colorbar: bool = True, ax=None):
    """Contours of a dual function ``D(λ₁, λ₂)`` over a window, with the quadrant ``λ ≥ 0``.

    ``dual`` maps an array of shape (..., 2) to values of shape (...) (a
    :class:`signorini.teaching.dual.DenseDual` of a two-candidate problem does). The
    region outside ``λ ≥ 0`` is shaded. ``maximiser`` (the maximiser over
    ``λ ≥ 0``) is drawn as a star and ``unconstrained`` (``W⁻¹b``) as a cross.
    ``paths`` are ``(label, (k, 2) iterates)`` drawn as lines with markers in
    the colours C0, C1, … (as :func:`residual_history` draws series), the
    start circled; ``points`` are ``(label, (2,) point)`` single markers (what
    solvers returned), drawn large to small so that coinciding ones stay
    visible. ``window`` is ``((λ₁_lo, λ₁_hi), (λ₂_lo, λ₂_hi))``; by default it
    frames the origin and the marked points.
    """
    ax = axes(ax)
    paths, points = list(paths), list(points)
    marked = [p for p in (maximiser, unconstrained) if p is not None] + [p for _, p in points]
    (lo1, hi1), (lo2, hi2) = window if window is not None else _dual_window(marked)
    grid1, grid2 = np.meshgrid(np.linspace(lo1, hi1, resolution), np.linspace(lo2, hi2, resolution))
    values = np.asarray(dual(np.stack([grid1, grid2], axis=-1)), dtype=float)
    contours = ax.contour(grid1, grid2, values, levels=levels, cmap="viridis", linewidths=0.8)
    if colorbar:
        ax.figure.colorbar(contours, ax=ax, label="D(λ)", shrink=0.85)
    outside = np.array([[lo1, lo2], [hi1, lo2], [hi1, 0.0], [0.0, 0.0], [0.0, hi2], [lo1, hi2]])
    ax.fill(outside[:, 0], outside[:, 1], facecolor="0.93", edgecolor="0.72", linewidth=0.0,
            hatch="//", zorder=0,
            label="λ ≱ 0 (not dual feasible)" if min(lo1, lo2) < 0 else None)
    ax.axhline(0.0, color="0.3", lw=0.8)
    ax.axvline(0.0, color="0.3", lw=0.8)
    for i, (label, iterates) in enumerate(paths):
        iterates = np.asarray(iterates, dtype=float).reshape(-1, 2)
        color = f"C{i % 10}"
        ax.plot(iterates[:, 0], iterates[:, 1], "-o", color=color, ms=3, lw=1.0, label=label)
        ax.plot(iterates[0, 0], iterates[0, 1], "o", ms=8, mfc="none", color=color)
    markers = ("s", "D", "^", "v", "P", "h", "<", ">")
    for i, (label, point) in enumerate(points):
        point = np.asarray(point, dtype=float).reshape(2)
        ax.plot(point[0], point[1], markers[i % len(markers)], mfc="none", mew=1.4,
                ms=max(14 - 2.5 * i, 4), color=f"C{(i + 4) % 10}", label=label, zorder=5)
    if unconstrained is not None:
        u = np.asarray(unconstrained, dtype=float).reshape(2)
        ax.plot(u[0], u[1], "x", color="k", ms=9, mew=2, label="unconstrained maximiser W⁻¹b",
                zorder=6)
    if maximiser is not None:
        m = np.asarray(maximiser, dtype=float).reshape(2)
        ax.plot(m[0], m[1], "*", color="crimson", ms=15, mec="k", label="maximiser over λ ≥ 0",
                zorder=4)
    ax.set_xlim(lo1, hi1)
    ax.set_ylim(lo2, hi2)
    ax.set_xlabel("λ₁ (force on candidate 1)")
    ax.set_ylabel("λ₂ (force on candidate 2)")
    ax.set_aspect("equal", adjustable="box")
    ax.legend(fontsize=7, loc="upper right", framealpha=0.9)
    return ax


def projection_steps(multipliers: np.ndarray, trial: np.ndarray, *, count: int | None = None,
                     color: str = "C3", ax=None):
    """Uzawa's projected steps in the (λ₁, λ₂) plane.

    For every step ``j`` whose trial point ``λ_j + ρ∇D(λ_j)`` (row ``j`` of
    ``trial``) left the quadrant, a dashed arrow shows the gradient step from
    ``λ_j`` to the trial point and a dotted arrow the projection
    ``max(0, ·)`` back to ``λ_{j+1}`` (rows of ``multipliers``). ``count``
    limits the drawing to the first ``count`` such steps.
    """
    ax = axes(ax)
    multipliers = np.asarray(multipliers, dtype=float).reshape(-1, 2)
    trial = np.asarray(trial, dtype=float).reshape(-1, 2)
    steps = [j for j in range(min(len(trial), len(multipliers) - 1)) if np.any(trial[j] < 0)]
    for n, j in enumerate(steps[:count]):
        start, out, back = multipliers[j], trial[j], multipliers[j + 1]
        ax.annotate("", xy=out, xytext=start,
                    arrowprops=dict(arrowstyle="->", color=color, ls="--", lw=1.2))
        ax.annotate("", xy=back, xytext=out,
                    arrowprops=dict(arrowstyle="->", color=color, ls=":", lw=1.5))
        ax.plot(*out, "o", mfc="white", color=color, ms=5,
                label="gradient step, then projection onto λ ≥ 0" if n == 0 else None)
    if steps:
        ax.legend(fontsize=7, loc="upper right", framealpha=0.9)
    return ax


def objectives_against_iteration(histories: Iterable[tuple[str, object]], *, optimum: float,
                                 free_energy: float | None = None,
                                 final_points: Iterable[tuple[str, int, float, float]] = (),
                                 ax=None):
    """Primal ``J(u_k)`` (solid) and dual ``D(λ_k)`` (dashed) objectives against iteration.

    ``histories`` are ``(label, IterationHistory)`` pairs (see
    :mod:`signorini.teaching.dual`). Values are shown as ``(value − J*)/(J* − D(0))``
    when ``free_energy = D(0)`` (the unconstrained minimum ``−½fᵀK⁻¹f``) is
    given, so that 0 is the optimum ``J*`` and −1 the energy without any
    contact; otherwise as ``value − J*``. ``final_points`` are
    ``(label, iteration, primal, dual)`` of methods that report only their
    final point (a QP solver), drawn as markers. The iteration axis is
    logarithmic.
    """
    ax = axes(ax)
    scale = 1.0 if free_energy is None else float(optimum - free_energy) or 1.0
    for i, (label, history) in enumerate(histories):
        color = f"C{i % 10}"
        ax.plot(history.iteration, (history.primal - optimum) / scale, "-", color=color,
                label=f"{label}: primal J(u_k)")
        ax.plot(history.iteration, (history.dual - optimum) / scale, "--", color=color,
                label=f"{label}: dual D(λ_k)")
    for j, (label, iteration, primal, dual) in enumerate(final_points):
        color = f"C{(j + 6) % 10}"
        x = max(int(iteration), 1)
        ax.plot(x, (primal - optimum) / scale, "s", color=color, ms=8,
                label=f"{label}: final J(u)")
        ax.plot(x, (dual - optimum) / scale, "D", mfc="none", color=color, ms=8,
                label=f"{label}: final D(λ)")
    ax.axhline(0.0, color="k", lw=0.8)
    ax.set_xscale("log")
    ax.set_xlabel("iteration")
    ax.set_ylabel("(objective − J*) / (J* − D(0))" if free_energy is not None else "objective − J*")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7, ncol=2)
    return ax


def duality_gap_history(histories: Iterable[tuple[str, object]], *, scale: float = 1.0,
                        infeasibility: bool = True, ax=None):
    """``|J(u_k) − D(λ_k)| / scale`` (solid) and the relative infeasibilities, per iteration.

    ``histories`` are ``(label, IterationHistory)`` pairs. With ``infeasibility``
    the primal infeasibility ``max((Nu − d)⁺)`` (dotted) and, when it is ever
    non-zero, the dual one ``max((−λ)⁺)`` (dash-dot) are drawn too, both
    relative (see :class:`signorini.teaching.dual.IterationHistory`). Log–log axes;
    zeros are drawn at 1e-17.
    """
    ax = axes(ax)
    floor = 1e-17
    for i, (label, history) in enumerate(histories):
        color = f"C{i % 10}"
        ax.loglog(history.iteration, np.maximum(np.abs(history.gap) / scale, floor), "-",
                  color=color, label=f"{label}: |J − D|")
        if infeasibility:
            ax.loglog(history.iteration, np.maximum(history.primal_infeasibility, floor), ":",
                      color=color, label=f"{label}: primal infeasibility")
            if np.any(history.dual_infeasibility > 0):
                ax.loglog(history.iteration, np.maximum(history.dual_infeasibility, floor), "-.",
                          color=color, label=f"{label}: dual infeasibility (λ < 0)")
    ax.set_xlabel("iteration")
    ax.set_ylabel("relative size")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7)
    return ax


def active_set_history(histories: Iterable[tuple[str, object]], final_active: np.ndarray, *,
                       ax=None):
    """Nodes whose contact state differs from ``final_active``, against iteration.

    ``histories`` are ``(label, IterationHistory)`` pairs; a node counts as in
    contact at iteration k when ``λ_k > 0`` there. Logarithmic iteration axis.
    """
    ax = axes(ax)
    final_active = np.asarray(final_active, dtype=bool)
    for i, (label, history) in enumerate(histories):
        wrong = history.misclassified(final_active)
        found = history.active_set_found_at(final_active)
        suffix = f" (found at iteration {found})" if found is not None else " (not found)"
        ax.step(history.iteration, wrong, where="post", color=f"C{i % 10}", label=label + suffix)
    ax.set_xscale("log")
    ax.set_xlabel("iteration")
    ax.set_ylabel("nodes in the wrong state")
    ax.set_ylim(bottom=0)
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7)
    return ax


def complementarity_by_node(x: np.ndarray, force: np.ndarray, gap: np.ndarray, *,
                            floor: float = 1e-16, title: str = "", ax=None):
    """Force, gap and their product at every contact candidate (log scale).

    Shows ``λ̃ᵢ = λᵢ/‖λ‖∞`` (filled circles), ``g̃ᵢ = gᵢ/‖g‖∞`` (hollow squares)
    and ``λ̃ᵢ g̃ᵢ`` (crosses) against ``x``; complementarity ``λᵢ gᵢ = 0`` means
    that at every node at least one of the first two sits on the floor.
    Negative entries (a pulling force, a penetration) are drawn in red at
    their absolute value.
    """
    ax = axes(ax)
    x = np.asarray(x, dtype=float)
    lam_n = np.asarray(force, dtype=float) / (float(np.max(np.abs(force))) or 1.0)
    gap_n = np.asarray(gap, dtype=float) / (float(np.max(np.abs(gap))) or 1.0)
    product = lam_n * gap_n
    for values, style, label in ((lam_n, dict(marker="o", ls="none", ms=4), "force λᵢ/‖λ‖∞"),
                                 (gap_n, dict(marker="s", ls="none", ms=5, mfc="none"),
                                  "gap gᵢ/‖g‖∞"),
                                 (product, dict(marker="x", ls="none", ms=4), "product")):
        line, = ax.semilogy(x, np.maximum(np.abs(values), floor), label=label, **style)
        negative = values < 0
        if np.any(negative):
            ax.semilogy(x[negative], np.maximum(np.abs(values[negative]), floor), ls="none",
                        marker=style["marker"], ms=9, mfc="none", color="red")
    if np.any(lam_n < 0) or np.any(gap_n < 0):
        ax.plot([], [], "o", mfc="none", color="red", ms=9, label="negative (drawn as |·|)")
    ax.set_xlabel("x")
    ax.set_ylabel("normalised value")
    ax.set_ylim(bottom=floor / 3)
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7)
    if title:
        ax.set_title(title, fontsize=9)
    return ax


def nodal_values(x: np.ndarray, series: Iterable[tuple[str, np.ndarray]], *, ylabel: str,
                 xlabel: str = "x", highlight: np.ndarray | None = None,
                 highlight_label: str = "", log: bool = False, ax=None):
    """One value per contact candidate against ``x``, for one or more series.

    ``series`` are ``(label, values)``; ``highlight`` (a boolean mask) rings
    those nodes of the first series in red, labelled ``highlight_label``.
    """
    ax = axes(ax)
    x = np.asarray(x, dtype=float)
    series = list(series)
    order = np.argsort(x)
    for i, (label, values) in enumerate(series):
        values = np.asarray(values, dtype=float)
        ax.plot(x[order], values[order], "-o" if i == 0 else "--.", ms=3 if i == 0 else 4,
                lw=1.0, label=label, color=f"C{i % 10}")
    if highlight is not None and series and np.any(highlight):
        mask = np.asarray(highlight, dtype=bool)
        first = np.asarray(series[0][1], dtype=float)
        ax.plot(x[mask], first[mask], "o", ms=10, mfc="none", color="red", mew=1.5,
                label=highlight_label or "highlighted")
    if log:
        ax.set_yscale("log")
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7)
    return ax


def bogie_shape(problem, displacements: Iterable[tuple[str, np.ndarray]], *, ax=None):
    """The bogie of :func:`signorini.teaching.synthetic.bogie`: rail, frame at rest and deflected.

    The rail passes ``gᵢ`` below wheel ``i``; the frame at rest is dashed; each
    ``(label, u)`` in ``displacements`` is drawn as a deflected frame with its
    two wheels. A wheel below the rail line penetrates it.
    """
    ax = axes(ax)
    ell = float(problem.contact_points[-1, 0])  # the wheels sit at x = ±ℓ
    g1, g2 = problem.d
    shapes = [(label, *bogie_deflection(problem, u)) for label, u in displacements]
    rail_x = np.array([-1.3 * ell, 1.3 * ell])
    rail_y = -g1 + (rail_x + ell) * (g1 - g2) / (2 * ell)
    bottom = min([float(np.min(rail_y))] + [float(np.min(w)) for _, _, w in shapes]) - 0.2 * ell
    ax.fill_between(rail_x, rail_y, bottom, facecolor="0.85", edgecolor="0.6", hatch="//",
                    label="rail (rigid)")
    ax.plot(rail_x, rail_y, color="0.3", lw=1.5)
    ax.plot([-ell, ell], [0.0, 0.0], "--", color="0.4", lw=1.0, label="frame at rest")
    ax.plot(0.0, 0.0, "v", color="0.4", ms=9)
    for i, (label, x, w) in enumerate(shapes):
        color = f"C{i % 10}"
        ax.plot(x, w, "-", color=color, lw=2, label=label)
        ax.plot(x[[0, -1]], w[[0, -1]], "o", color=color, ms=9, mfc="white", mew=2)
    ax.set_xlabel("x")
    ax.set_ylabel("height (w, up)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    return ax
