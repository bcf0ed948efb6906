"""Figures of solves and benchmarks. Every function takes ``ax=None`` and returns the Axes.

The atlas's figures are in :mod:`signorini.studies.atlas.figures`; the tutorials draw their own.
"""

from __future__ import annotations

from typing import Any, Iterable

import numpy as np

from signorini.problem.contact import ContactProblem, ContactSolution
from signorini.references.analytic import hertz_pressure, punch_pressure
from signorini.references.pressure import compare_punch, contact_profile


#: markers that go with the ten default colours (eleven: see :func:`series_style`)
MARKERS = "osD^v<>phP*"


def series_style(i: int) -> tuple[str, str]:
    """The colour and marker of a figure's ``i``-th series.

    Colours cycle through the ten default ones and markers through the eleven
    of :data:`MARKERS` together, so the first 110 series all differ in
    colour-and-marker (two series that share a colour never share a marker).
    """
    return f"C{i % 10}", MARKERS[i % len(MARKERS)]


def axes(ax, size: tuple[float, float] = (6.4, 4.2)):
    """``ax``, or the Axes of a new figure of ``size`` inches (pyplot's global state untouched)."""
    if ax is None:
        from matplotlib.figure import Figure  # matplotlib (0.4 s to import): only when a figure is drawn
        ax = Figure(figsize=size, layout="constrained").add_subplot()
    return ax


def framed(ax, xlabel: str, ylabel: str, which: str = "major", **legend: Any):
    """``ax`` with its axis labels, a light grid at the ``which`` ticks and a legend (``legend``
    its keywords, font size 7 unless given); returned."""
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.grid(alpha=0.3, which=which)
    ax.legend(**{"fontsize": 7, **legend})
    return ax


def pressure_profile(x: np.ndarray, pressure: np.ndarray, *, a_ref: float | None = None,
                     p0_ref: float | None = None, label: str = "numeric", ax=None,
                     others: Iterable[tuple[str, np.ndarray]] = ()):
    """Nodal pressure against x, with Hertz's ``p₀√(1 − x²/a²)`` when ``a_ref`` is given.

    Lengths are shown in units of ``a_ref`` and pressures in units of
    ``p0_ref`` when both are given. ``others`` adds ``(label, pressure)``
    series at the same x (other methods), drawn as markers.
    """
    ax = axes(ax)
    xs = 1.0 if a_ref is None else a_ref
    ps = 1.0 if p0_ref is None else p0_ref
    if a_ref is not None and p0_ref is not None:
        grid = np.linspace(0.0, float(x.max()), 800)
        ax.plot(grid / xs, hertz_pressure(grid, a_ref, p0_ref) / ps, "k-", lw=1.5, label="Hertz")
    ax.plot(x / xs, pressure / ps, series_style(0)[1], color=series_style(0)[0], ms=3, mfc="none",
            label=label)
    for i, (name, values) in enumerate(others, start=1):  # series 0 is the numeric one above
        colour, marker = series_style(i)
        ax.plot(x / xs, values / ps, marker, color=colour, ms=3, mfc="none", label=name,
                alpha=0.7, zorder=2 + i)
    ax.set_xlim(left=0.0)
    return framed(ax, "x / a (Hertz)" if a_ref is not None else "x",
                  "p / p₀ (Hertz)" if p0_ref is not None else "p", ncol=2)


def kkt_against_time(rows: list[dict], *, ax=None, title: str = ""):
    """Worst relative KKT residual against solve time, one marker per run (log–log).

    Each run has its own colour-and-marker (:func:`series_style`); filled where the
    package says converged, hollow otherwise.
    """
    ax = axes(ax)
    shown = [row for row in rows if np.isfinite(row["kkt_worst"]) and row["kkt_worst"] > 0
             and row["time_s"] > 0]
    for i, row in enumerate(shown):
        colour, marker = series_style(i)
        ax.loglog(row["time_s"], max(row["kkt_worst"], 1e-17), marker, color=colour, ms=6,
                  mfc=colour if row["status"] == "converged" else "none",
                  label=f"{row['label']} ({row['status']})")
    ax.set_xlabel("build + solve time [s]")
    ax.set_ylabel("worst relative KKT residual")
    ax.grid(alpha=0.3, which="both")
    if shown:  # no run measured (every one timed out or failed): no legend to draw
        ax.legend(fontsize=6, ncol=2)
    else:
        ax.text(0.5, 0.5, "no run has a measured residual", transform=ax.transAxes, ha="center")
    if title:
        ax.set_title(title, fontsize=9)
    return ax


def bench_speed_accuracy(rows: list[dict], *, metric: str = "kkt_worst", ax=None):
    """Benchmark runs: time against an accuracy measure, one marker per method and tolerance.

    One colour per method (twenty), one marker per tolerance level; filled
    markers are runs the package calls ``converged``; the lower-left envelope
    is the Pareto front.
    """
    import matplotlib  # as in axes(): only when a figure is drawn

    ax = axes(ax, (10, 5))
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
                      color=matplotlib.colormaps["tab20"](i % 20), mfc=None if all(ok) else "none",
                      label=f"{method} @ {tolerance}", ms=5)
    ax.set_xlabel("time [s]")
    ax.set_ylabel({"kkt_worst": "worst relative KKT residual",
                   "p0_rel": "Hertz p₀ relative error"}.get(metric, metric))
    ax.grid(alpha=0.3, which="both")
    if ax.get_legend_handles_labels()[0]:  # no run has the metric: a problem without a reference
        ax.legend(fontsize=5, ncol=2, loc="upper left", bbox_to_anchor=(1.01, 1.0))  # off the front
    else:
        ax.text(0.5, 0.5, f"no run has {metric}", ha="center", transform=ax.transAxes)
    return ax


def bench_time_vs_dofs(rows: list[dict], *, axes=None):
    """Time (left) and ratio to one factorisation (right) against dofs, log–log, per method.

    Each method at its own default tolerance (exact methods: their one run); filled markers
    where the answer passed the certificate, hollow where not (a timeout has no point).
    Returns the left Axes and the fitted slopes ``{label: slope}`` of time against dofs.
    """
    if axes is None:
        from matplotlib.figure import Figure  # as above
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
    import matplotlib  # as above

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


def peer_times(rows: list[dict], *, by: str = "wall_s", label: str = "wall time [s]",
               targets: Iterable[float] = (0.003, 0.001), names: dict[str, str] | None = None,
               ax=None):
    """Wall time ``by`` against accuracy, max(|p₀ error|, |a error|), one colour per code.

    ``rows`` are the peer benchmark's (:mod:`signorini.studies.peer`): ``code``,
    ``dofs``, ``status``, ``error`` (the larger relative error against Hertz) and
    the time ``by`` (``wall_s`` whole process, ``in_process_s`` in process; rows
    without it are left out). Points join in the order of the code's ladder (dofs),
    each marked with its dofs; hollow where the code did not report convergence;
    dotted lines at the ``targets``; ``names`` the codes' names in the legend.
    Down and to the left is faster and closer.
    """
    from matplotlib.ticker import NullFormatter  # as above

    ax, names = axes(ax), names or {}
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.xaxis.set_minor_formatter(NullFormatter())
    for target in targets:
        ax.axvline(target, color="0.5", ls=":", lw=1)
    drawn = False
    for i, code in enumerate(sorted({r["code"] for r in rows})):
        mine = sorted((r for r in rows if r["code"] == code and r.get(by) is not None
                       and np.isfinite(r["error"])), key=lambda r: r["dofs"])
        if not mine:
            continue
        drawn = True
        colour, marker = series_style(i)
        errors = np.maximum([r["error"] for r in mine], 1e-6)
        times = np.array([r[by] for r in mine], dtype=float)
        good = np.array([r["status"] == "converged" for r in mine])
        ax.plot(errors, times, "-", marker=marker, color=colour, lw=1, ms=5, label=names.get(code, code))
        ax.plot(errors[~good], times[~good], marker, mfc="white", color=colour, ms=5)
        for error, seconds, row in zip(errors, times, mine):
            ax.annotate(f"{row['dofs'] / 1000:.3g}k", (error, seconds), textcoords="offset points",
                        xytext=(4, 3), fontsize=6, color=colour)
    ax.margins(x=0.1)  # room for the dofs beside the outermost points
    if not drawn:
        ax.text(0.5, 0.5, "not measured", ha="center", va="center", transform=ax.transAxes)
    ax.set_xlabel("max(|p₀ error|, |a error|) against Hertz")
    ax.set_ylabel(label)
    ax.grid(alpha=0.3, which="both")
    if drawn:
        ax.legend(fontsize=7)
    return ax


def deformed_bodies(points: np.ndarray, elements: np.ndarray, displacement: np.ndarray,
                    body: np.ndarray, contact: np.ndarray, pressure: np.ndarray, *,
                    magnify: float | None = None, ax=None):
    """The deformed meshes of one or more bodies, each in its colour, and the contact pressure.

    ``points`` (2, k) and ``displacement`` (k, 2) are the nodes and their
    displacements, ``elements`` (3, e) the triangles and ``body`` (e,) the body of
    each (1, 2, ...); ``contact`` indexes the contact nodes and ``pressure`` is
    theirs, drawn as coloured dots on the deformed face. Displacements are
    magnified by ``magnify`` (None: so that the largest is a tenth of the extent).
    """
    ax = axes(ax)
    extent = float(np.ptp(points, axis=1).max())
    largest = float(np.abs(displacement).max())
    if magnify is None:
        magnify = 0.1 * extent / largest if largest > 0 else 1.0
    x, y = points + magnify * np.asarray(displacement).T
    for i, which in enumerate(np.unique(body)):
        ax.triplot(x, y, elements[:, body == which].T, color=series_style(i)[0], lw=0.3,
                   label=f"body {which}")
    dots = ax.scatter(x[contact], y[contact], c=pressure, s=8, cmap="viridis", zorder=3,
                      vmin=0.0, vmax=max(float(np.max(pressure, initial=0.0)), 1e-300))
    ax.figure.colorbar(dots, ax=ax, label="contact pressure")
    ax.set_aspect("equal")
    ax.set_title(f"deformed (displacements × {magnify:.3g})", fontsize=9)
    ax.legend(fontsize=7)
    return ax


# --- the punch's edge ---------------------------------------------------------------------


def _punch(problem: ContactProblem, solution: ContactSolution):
    """The punch comparison, the pressure profile and the pressure unit ``P/(πa)``."""
    comparison = compare_punch(problem, solution)
    return comparison, contact_profile(problem, solution), comparison.load / (np.pi * comparison.a)


def plot_punch_pressure(problem: ContactProblem, solution: ContactSolution, ax=None):
    """Nodal pressure under the punch against ``P/(π√(a² − x²))``, in units of ``P/(πa)``."""
    ax = axes(ax)
    comparison, profile, scale = _punch(problem, solution)
    a, P = comparison.a, comparison.load
    x, p = np.abs(profile.x), profile.pressure
    order = np.argsort(x)
    grid = np.linspace(0.0, a * (1 - 1e-4), 2000)
    ax.plot(grid / a, punch_pressure(grid, a, P) / scale, "k-", lw=1.2, label="P / (π√(a² − x²))")
    ax.plot(x[order] / a, p[order] / scale, "o", ms=3, mfc="none", label=f"{solution.method}")
    ax.axvspan(0, comparison.inner, color="0.9", zorder=0, label=f"compared (|x| ≤ {comparison.inner:g}a)")
    ax.set_ylim(0, max(4.0, float(np.max(p) / scale) * 1.05))
    return framed(ax, "x / a", "p / (P / πa)")


def plot_punch_edge(problem: ContactProblem, solution: ContactSolution, ax=None):
    """Pressure against the distance ``a − |x|`` to the edge (log–log): slope −½ is the singularity."""
    ax = axes(ax)
    comparison, profile, scale = _punch(problem, solution)
    a, P = comparison.a, comparison.load
    distance = a - np.abs(profile.x)
    under = distance >= -1e-12 * a
    grid = np.geomspace(1e-4 * a, a, 400)
    ax.loglog(grid / a, punch_pressure(a - grid, a, P) / scale, "k-", lw=1.2, label="P / (π√(a² − x²))")
    positive = under & (distance > 0)
    ax.loglog(distance[positive] / a, profile.pressure[positive] / scale, "o", ms=3, mfc="none",
              label=f"{solution.method}, h = {comparison.edge_h / a:.2g} a")
    edge = under & (distance <= 1e-12 * a)
    if np.any(edge):
        ax.axhline(float(profile.pressure[edge][0]) / scale, color="C3", lw=0.8, ls="--",
                   label="edge node (x = a)")
    return framed(ax, "(a − |x|) / a", "p / (P / πa)", "both")


__all__ = ["series_style", "axes", "framed", "pressure_profile", "kkt_against_time", "bench_speed_accuracy",
           "bench_time_vs_dofs", "peer_times", "deformed_bodies", "plot_punch_pressure",
           "plot_punch_edge"]
