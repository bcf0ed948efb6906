"""The explorer's figures: each draws one lesson of :mod:`signorini.output.lessons`.

Figures are built with :class:`matplotlib.figure.Figure` (no pyplot state), so that a web app
can draw one per interaction from any thread, with fixed margins (:data:`MARGINS`) rather than
a layout engine's search, which would be redone at every slider move.
"""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure
from matplotlib.ticker import LogFormatter

from signorini.output.lessons import HertzLesson, PricesLesson, RaceRow, UzawaLesson

__all__ = ["hertz_figure", "prices_figure", "race_figure", "uzawa_figure"]

#: the window of the bogie's dual plane drawn (λ₁, λ₂)
DUAL_WINDOW = ((-0.1, 1.2), (-0.1, 1.2))
#: the figures' margins and spacing, as fractions of the figure
MARGINS = {"left": 0.08, "right": 0.98, "bottom": 0.11, "top": 0.93, "wspace": 0.25, "hspace": 0.55}


def uzawa_figure(lesson: UzawaLesson) -> Figure:
    """Contours of ``D(λ)`` with the iterates and λ*, their distance to λ*, and ρ against
    its bound ``2/λ_max(W)``."""
    fig = Figure(figsize=(10, 4.6))
    grid = fig.add_gridspec(2, 2, height_ratios=(6, 1), width_ratios=(1.1, 1), **MARGINS)
    dual, distance, step = fig.add_subplot(grid[0, 0]), fig.add_subplot(grid[0, 1]), fig.add_subplot(grid[1, :])
    (x0, x1), (y0, y1) = DUAL_WINDOW
    plane = np.stack(np.meshgrid(np.linspace(x0, x1, 100), np.linspace(y0, y1, 100)), axis=-1)
    values = (-0.5 * np.einsum("...i,ij,...j->...", plane, lesson.W, plane) + plane @ lesson.b
              + lesson.constant)
    dual.imshow(values, origin="lower", extent=(x0, x1, y0, y1), cmap="Blues", aspect="auto")
    dual.fill_between([x0, x1], y0, 0, color="0.5", alpha=0.35, lw=0)
    dual.fill_betweenx([y0, y1], x0, 0, color="0.5", alpha=0.35, lw=0)
    path = lesson.iterates
    dual.plot(path[:, 0], path[:, 1], ".-", color="C3" if lesson.result.status == "diverged" else "C1",
              lw=1, ms=4, label=f"Uzawa's iterates ({lesson.result.status})")
    dual.plot(*lesson.maximiser, "*", ms=16, color="gold", mec="k", label="maximiser λ*")
    dual.set_xlim(x0, x1), dual.set_ylim(y0, y1), dual.set_xlabel("λ₁"), dual.set_ylabel("λ₂")
    dual.legend(loc="upper right", fontsize=8), dual.set_title("The dual function D(λ) of the bogie")
    gaps = np.linalg.norm(path - lesson.maximiser, axis=1)
    distance.semilogy(np.maximum(gaps, 1e-17), color="C0")
    distance.yaxis.set_major_formatter(LogFormatter())  # plain text: no mathtext per move
    distance.set_xlabel("iteration k"), distance.set_ylabel("‖λᵏ − λ*‖")
    distance.set_title(f"{lesson.result.iterations} iterations, status {lesson.result.status}")
    step.axvspan(0, lesson.bound, color="C2", alpha=0.2, label="converges")
    step.axvspan(lesson.bound, 2 * lesson.bound, color="C3", alpha=0.2, label="diverges")
    step.axvline(lesson.bound, color="k", lw=2)
    step.annotate(f"2/λ_max(W) = {lesson.bound:.4f}", (lesson.bound, 0.72), xytext=(-6, 0),
                  textcoords="offset points", ha="right", va="center", fontsize=9)
    step.plot([lesson.rho], [0.3], "^", ms=12, color="k")
    step.set_xlim(0, 2 * lesson.bound), step.set_ylim(0, 1), step.set_yticks([])
    step.set_xlabel(f"step ρ = {lesson.rho:.4f}")
    return fig


def hertz_figure(lesson: HertzLesson) -> Figure:
    """The nodal pressure against Hertz's curve, the two half-widths, and the active set."""
    fig = Figure(figsize=(10, 4.6))
    grid = fig.add_gridspec(2, 1, height_ratios=(6, 1), **MARGINS)
    ax, nodes = fig.add_subplot(grid[0]), fig.add_subplot(grid[1])
    reach = 1.6 * lesson.a_ref
    shown = lesson.x <= reach
    x = lesson.x[shown]
    smooth = np.linspace(0, reach, 300)
    ax.plot(smooth, lesson.hertz_pressure(smooth), "k-", label="Hertz: p₀ √(1 − x²/a²)")
    ax.plot(x, lesson.pressure[shown], "o", ms=5, color="C0", label="nodal pressure λᵢ / wᵢ")
    ax.axvline(lesson.a_ref, color="k", ls=":", label=f"Hertz's a = {lesson.a_ref:.4g}")
    ax.axvline(lesson.a, color="C1", ls="--", label=f"fitted a = {lesson.a:.4g}")
    ax.set_xlim(0, reach), ax.set_ylabel("pressure"), ax.legend(fontsize=8)
    ax.set_title(f"P = {lesson.P:.4g}, E = {lesson.E:.4g}, ν = {lesson.nu:.3g}: "
                 f"{int(lesson.active.sum())} nodes in contact")
    active = lesson.active[shown]
    nodes.plot(x[active], np.zeros(active.sum()), "s", color="C3", ms=6, label="in contact")
    nodes.plot(x[~active], np.zeros((~active).sum()), "s", mfc="none", color="0.5", ms=6,
               label="open")
    nodes.set_xlim(0, reach), nodes.set_yticks([]), nodes.set_xlabel("x (from the first point of contact)")
    nodes.legend(loc="center right", fontsize=8, ncol=2)
    return fig


def prices_figure(lesson: PricesLesson) -> Figure:
    """``J*(g₂)`` with the tangent of slope ``−λ₂`` at the gap, and λ beside the prices."""
    fig = Figure(figsize=(10, 4.2))
    curve, bars = fig.subplots(1, 2, width_ratios=(1.4, 1), gridspec_kw=MARGINS)
    curve.plot(lesson.curve_gaps, lesson.curve_energy, "C0", lw=2, label="J*(g₂), re-solved")
    run = np.array([-0.4, 0.4])
    curve.plot(lesson.gap + run, lesson.result.energy - lesson.force[1] * run, "k-",
               label=f"tangent of slope −λ₂ = {-lesson.force[1]:.4g}")
    curve.plot([lesson.gap], [lesson.result.energy], "o", ms=9, mfc="white", mec="k", mew=1.5)
    curve.set_xlabel("gap under wheel 2, d₂"), curve.set_ylabel("optimal energy J*")
    curve.legend(fontsize=8), curve.set_title(f"lowering {lesson.lowering:.3g}: the best energy")
    where = np.arange(2)
    bars.bar(where - 0.18, lesson.force, 0.36, label="force λᵢ")
    bars.bar(where + 0.18, lesson.prices, 0.36, label="price −∂J*/∂dᵢ (re-solves)")
    bars.set_xticks(where, ["wheel 1", "wheel 2"]), bars.legend(fontsize=8)
    bars.set_title(f"envelope theorem: miss {lesson.envelope_error:.1e}")
    return fig


def race_figure(rows: list[RaceRow]) -> Figure:
    """Iterations and the worst KKT residual of each method, side by side."""
    fig = Figure(figsize=(10, 3.4))
    iterations, residual = fig.subplots(1, 2, gridspec_kw={**MARGINS, "left": 0.14, "wspace": 0.05})
    names = [row.method for row in rows]
    iterations.barh(names, [max(row.iterations, 1) for row in rows], color="C0")
    iterations.set_xscale("log"), iterations.set_xlabel("iterations")
    iterations.xaxis.set_major_formatter(LogFormatter())
    residual.barh(names, [max(row.worst[1], 1e-17) for row in rows],
                  color=["C2" if row.status == "converged" else "C3" for row in rows])
    residual.set_xscale("log"), residual.set_xlabel("worst KKT residual (green: converged)")
    residual.xaxis.set_major_formatter(LogFormatter())
    residual.set_yticks([])
    return fig
