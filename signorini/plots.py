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


# --- duality: the tutorials in docs/tutorials/ -------------------------------------------------


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
    :class:`signorini.dual.DenseDual` of a two-candidate problem does). The
    region outside ``λ ≥ 0`` is shaded. ``maximiser`` (the maximiser over
    ``λ ≥ 0``) is drawn as a star and ``unconstrained`` (``W⁻¹b``) as a cross.
    ``paths`` are ``(label, (k, 2) iterates)`` drawn as lines with markers in
    the colours C0, C1, … (as :func:`residual_history` draws series), the
    start circled; ``points`` are ``(label, (2,) point)`` single markers (what
    solvers returned), drawn large to small so that coinciding ones stay
    visible. ``window`` is ``((λ₁_lo, λ₁_hi), (λ₂_lo, λ₂_hi))``; by default it
    frames the origin and the marked points.
    """
    ax = _axes(ax)
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
    ax = _axes(ax)
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
    :mod:`signorini.dual`). Values are shown as ``(value − J*)/(J* − D(0))``
    when ``free_energy = D(0)`` (the unconstrained minimum ``−½fᵀK⁻¹f``) is
    given, so that 0 is the optimum ``J*`` and −1 the energy without any
    contact; otherwise as ``value − J*``. ``final_points`` are
    ``(label, iteration, primal, dual)`` of methods that report only their
    final point (a QP solver), drawn as markers. The iteration axis is
    logarithmic.
    """
    ax = _axes(ax)
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
    relative (see :class:`signorini.dual.IterationHistory`). Log–log axes;
    zeros are drawn at 1e-17.
    """
    ax = _axes(ax)
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
    ax = _axes(ax)
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
    ax = _axes(ax)
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
    ax = _axes(ax)
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
    """The bogie of :func:`signorini.synthetic.bogie`: rail, frame at rest and deflected.

    The rail passes ``gᵢ`` below wheel ``i``; the frame at rest is dashed; each
    ``(label, u)`` in ``displacements`` is drawn as a deflected frame with its
    two wheels. A wheel below the rail line penetrates it.
    """
    from .synthetic import bogie_deflection

    ax = _axes(ax)
    ell = float(problem.params["half_length"])
    g1, g2 = problem.params["gaps"]
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


def bench_speed_accuracy(rows: list[dict], *, metric: str = "kkt_worst", ax=None):
    """Benchmark runs: time against an accuracy measure, one marker per method and tolerance.

    Filled markers are runs the package calls ``converged``; the lower-left
    envelope is the Pareto front.
    """
    if ax is None:
        from matplotlib.figure import Figure
        ax = Figure(figsize=(10, 5), layout="constrained").add_subplot()
    markers = {"low": "v", "mid": "s", "high": "o", "default": "D"}
    methods = sorted({r["method"] for r in rows})
    for i, method in enumerate(methods):
        for tolerance, marker in markers.items():
            mine = [r for r in rows if r["method"] == method and r["tolerance"] == tolerance
                    and np.isfinite(r[metric]) and r["time_s"] > 0]
            if not mine:
                continue
            ok = [r["status"] == "converged" for r in mine]
            ax.loglog([r["time_s"] for r in mine], [max(r[metric], 1e-16) for r in mine], marker,
                      color=f"C{i % 10}", mfc=None if all(ok) else "none",
                      label=f"{method} @ {tolerance}", ms=5)
    ax.set_xlabel("time [s]")
    ax.set_ylabel({"kkt_worst": "worst relative KKT residual",
                   "p0_rel": "Hertz p₀ relative error"}.get(metric, metric))
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=5, ncol=2, loc="upper left", bbox_to_anchor=(1.01, 1.0))  # off the front
    return ax


def bench_time_vs_dofs(rows: list[dict], *, axes=None):
    """Time (left) and ratio to one factorisation (right) against dofs, log–log, per method.

    Each method at its own default tolerance (exact methods: their one run); filled markers
    where the answer passed the certificate, hollow where not (a timeout has no point).
    Returns the left Axes and the fitted slopes ``{label: slope}`` of time against dofs.
    """
    if axes is None:
        from matplotlib.figure import Figure
        axes = Figure(figsize=(11, 4.4), layout="constrained").subplots(1, 2)
    left, right = axes
    slopes: dict[str, float] = {}
    factor: dict[float, list[float]] = {}
    for r in rows:
        if np.isfinite(r["factor_s"]):
            factor.setdefault(r["dofs"], []).append(r["factor_s"])
    if factor:
        dofs = np.array(sorted(factor))
        series_f = np.array([np.median(factor[d]) for d in dofs])
        left.loglog(dofs, series_f, "k--", label="one factorisation + solve")
        right.axhline(1.0, color="k", ls="--", lw=1)
        if dofs.size >= 2:
            slopes["one factorisation + solve"] = float(np.polyfit(np.log(dofs), np.log(series_f), 1)[0])
    import matplotlib

    for i, method in enumerate(sorted({r["method"] for r in rows})):
        mine = [r for r in rows if r["method"] == method]
        level = "default" if any(r["tolerance"] == "default" for r in mine) else "high"
        mine = sorted((r for r in mine if r["tolerance"] == level and np.isfinite(r["time_s"])),
                      key=lambda r: r["dofs"])
        if not mine:
            continue
        dofs = np.array([r["dofs"] for r in mine])
        times = np.array([r["time_s"] for r in mine])
        ratios = np.array([r["ratio_to_factor"] for r in mine])
        good = np.array([r["status"] == "converged" for r in mine])
        colour = matplotlib.colormaps["tab20"](i % 20)
        marker = "osD^v<>ph"[i % 9]
        for ax, values in ((left, times), (right, ratios)):
            ax.plot(dofs, values, "-", color=colour, lw=1, marker=marker, ms=0,
                    label=method if ax is left else None)
            ax.plot(dofs[good], values[good], marker, color=colour, ms=5)
            ax.plot(dofs[~good], values[~good], marker, mfc="none", color=colour, ms=5)
        if np.unique(dofs).size >= 2:
            slopes[method] = float(np.polyfit(np.log(dofs), np.log(times), 1)[0])
    left.set_xscale("log"), left.set_yscale("log")
    right.set_xscale("log"), right.set_yscale("log")
    left.set_xlabel("dofs"), right.set_xlabel("dofs")
    left.set_ylabel("time at each method's default tolerance [s]")
    right.set_ylabel("time / one factorisation + solve")
    for ax in axes:
        ax.grid(alpha=0.3, which="both")
    left.legend(fontsize=6)
    right.set_title("filled: certificate passed; hollow: not", fontsize=8)
    return left, slopes


# --- the stability atlas (signorini.stability) ---------------------------------------------------

#: colours of the atlas's outcomes
OUTCOME_COLOURS = {"right": "#4daf4a", "conservative": "#a6d96a", "caught": "#fdae61",
                   "failed": "#d9d9d9", "wrong": "#d7191c"}


def atlas_step_sweep(rows: list[dict], *, ax=None):
    """Uzawa: iterations against ``ρ / (2/λ_max(W))``, one line per scene and method.

    ``●`` converged, ``✕`` diverged in a two-step cycle, ``▲`` diverged by
    growth, ``■`` stopped at the iteration limit. The textbook bound
    ``ρ = 2/λ_max(W)`` is the solid vertical line; dotted lines mark
    ``2/λ_max(W_AA)`` on the exact active set A of each scene (the bound the
    iteration sees once the active set has settled).
    """
    ax = _axes(ax)
    groups = sorted({(r["case"], r["method"]) for r in rows})
    for i, (case, method) in enumerate(groups):
        mine = sorted((r for r in rows if (r["case"], r["method"]) == (case, method)),
                      key=lambda r: r["value"])
        colour = f"C{i % 10}"
        ax.plot([r["value"] for r in mine], [max(r["iterations"], 1) for r in mine], "-",
                color=colour, lw=1, alpha=0.6, label=f"{case}, {method}")
        for r in mine:
            message = str(r.get("message", ""))
            marker = {"converged": "o", "max_iter": "s"}.get(r["status"], "^")
            if r["status"] == "diverged" and "cycle" in message:
                marker = "x"
            ax.plot(r["value"], max(r["iterations"], 1), marker, color=colour, ms=5,
                    mfc=colour if r["outcome"] == "right" else "none")
        bounds = [r.get("bound_at_solution") for r in mine]
        bounds = [b for b in bounds if b is not None and np.isfinite(b)]
        if bounds and method == "uzawa" and abs(bounds[0] - 1.0) > 1e-3:
            ax.axvline(bounds[0], color=colour, ls=":", lw=1,
                       label=f"2/λ_max(W_AA) = {bounds[0]:.2f} × bound ({case})")
    ax.axvline(1.0, color="k", lw=1.2, label="ρ = 2/λ_max(W)")
    ax.axvline(0.5, color="0.5", lw=0.8, ls="--", label="ρ = 1/λ_max(W) (FISTA's bound)")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("step ρ / (2/λ_max(W))")
    ax.set_ylabel("iterations (to 1e-8, or until stopped)")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=6)
    return ax


def atlas_series(rows: list[dict], x: str, y: str, *, ax=None, xlabel: str = "",
                 ylabel: str = "", logx: bool = True, logy: bool = True, group: str = "method",
                 floor: float = 1e-16):
    """One line per ``group``: ``y`` against ``x`` over the atlas's runs.

    Filled markers: the package says converged and the answer is right; open
    markers: any other outcome; a red ring: the method claimed success and
    was wrong.
    """
    ax = _axes(ax)
    names = list(dict.fromkeys(r[group] for r in rows))
    for i, name in enumerate(names):
        mine = [r for r in rows if r[group] == name and isinstance(r.get(x), (int, float))
                and isinstance(r.get(y), (int, float)) and np.isfinite(r[x]) and np.isfinite(r[y])]
        if not mine:
            continue
        mine.sort(key=lambda r: r[x])
        colour, marker = f"C{i % 10}", "osv^D<>ph*"[i // 10 % 10]
        values = [max(r[y], floor) if logy else r[y] for r in mine]
        ax.plot([r[x] for r in mine], values, "-", color=colour, lw=1, alpha=0.7, label=name)
        for r, value in zip(mine, values):
            ax.plot(r[x], value, marker, color=colour, ms=4,
                    mfc=colour if r["outcome"] == "right" else "none")
            if not r.get("claim_correct", True):
                ax.plot(r[x], value, "o", ms=9, mfc="none", mec="red", mew=0.8)
    if logx:
        ax.set_xscale("log")
    if logy:
        ax.set_yscale("log")
    ax.set_xlabel(xlabel or x)
    ax.set_ylabel(ylabel or y)
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=5, ncol=2)
    return ax


def atlas_outcomes(rows: list[dict], *, column: str = "case", ax=None, title: str = ""):
    """Methods × ``column``: each cell coloured by the run's outcome and labelled with its status.

    Outcomes: right (converged, agrees with the exact answer), conservative (a
    right answer the certificate turned down), caught (a false claim of
    success the package downgraded), failed (no claim), wrong (the package's
    status was wrong, or it raised).
    """
    ax = _axes(ax)
    methods = list(dict.fromkeys(r["method"] for r in rows))
    columns = list(dict.fromkeys(r[column] for r in rows))
    short = {"converged": "conv", "inaccurate": "inacc", "max_iter": "max it", "diverged": "div",
             "infeasible": "infeas", "failed": "fail", "refused": "n/a", "raised": "RAISED",
             "timeout": "time", "crashed": "crash", "input-error": "error"}
    for r in rows:
        i, j = methods.index(r["method"]), columns.index(r[column])
        colour = OUTCOME_COLOURS.get(r.get("outcome", "failed"), "#ffffff")
        ax.add_patch(_rectangle(j, i, colour))
        ax.text(j + 0.5, i + 0.5, short.get(r["status"], str(r["status"])[:6]), ha="center",
                va="center", fontsize=5)
    ax.set_xlim(0, len(columns))
    ax.set_ylim(len(methods), 0)
    ax.set_xticks(np.arange(len(columns)) + 0.5)
    ax.set_xticklabels([str(c) for c in columns], rotation=30, ha="right", fontsize=6)
    ax.set_yticks(np.arange(len(methods)) + 0.5)
    ax.set_yticklabels(methods, fontsize=6)
    ax.tick_params(length=0)
    if title:
        ax.set_title(title, fontsize=8)
    return ax


def _rectangle(x: float, y: float, colour: str):
    from matplotlib.patches import Rectangle

    return Rectangle((x, y), 1.0, 1.0, facecolor=colour, edgecolor="white", lw=0.8)


def atlas_weak_nodes(rows: list[dict], *, ax=None):
    """Misclassified contact nodes per run: weakly active nodes left out, and counted strictly.

    The comparison of :func:`signorini.kkt.compare` leaves out nodes that touch
    with zero force; counting them as well (weak tolerance 0) shows what a
    comparison without the weak label would have flagged.
    """
    ax = _axes(ax)
    labels = [f"{r['method']} ({r['case']})" for r in rows]
    positions = np.arange(len(rows))
    weak = [r.get("weak", np.nan) for r in rows]
    strict = [r.get("misclassified_strict", np.nan) for r in rows]
    kept = [r.get("misclassified", np.nan) for r in rows]
    ax.bar(positions - 0.27, weak, 0.27, color="#bdbdbd", label="weakly active nodes")
    ax.bar(positions, strict, 0.27, color="#fdae61", label="misclassified, counted strictly (weak tol 0)")
    ax.bar(positions + 0.27, kept, 0.27, color="#4daf4a",
           label="misclassified, weakly active nodes left out (the package's comparison)")
    ax.set_xticks(positions)
    ax.set_xticklabels(labels, rotation=60, ha="right", fontsize=5)
    ax.set_ylabel("misclassified contact nodes")
    ax.grid(alpha=0.3, axis="y")
    ax.legend(fontsize=6)
    return ax
