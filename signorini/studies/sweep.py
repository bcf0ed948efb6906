"""Load sweeps at the cost of back-solves: one factorisation and one Delassus operator for all loads.

For a body pushed by ``s`` times its prescribed displacement, ``b(s) = s b₁ + b₀``
with ``b₁ = N K⁻¹ f₁ − d₁`` and ``b₀ = P N K⁻¹ f_load − d₀`` (``f_load`` the
traction of a unit load P on a cut, when the scene loads the body so). Each load level is then a small
dense problem on the candidates (:func:`signorini.numerics.push.push_for_load_condensed`)
and one back-solve for the displacement.

Every level is judged as ``solve`` judges a method's answer
(:func:`signorini.solvers.base.judge`): the KKT certificate with the forward error of
its contact force (the sweep's factorisation and Delassus operator reused: a few
back-solves, no factorisation), then the boundary beyond the candidates
(:mod:`signorini.certification.adequacy`): a level whose contact reached the edge of the candidates
or beyond is ``model_inadequate``, not ``converged``.
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass
from typing import Callable

import numpy as np

from signorini.errors import InputError
from signorini.certification.inverse import WithDelassus
from signorini.certification.kkt import certificate
from signorini.numerics.lcp import delassus
from signorini.numerics.push import push_for_load_condensed
from signorini.output.plots import axes as _axes
from signorini.references.pressure import compare_hertz, contact_half_width, contact_profile
from signorini.problem.contact import ContactProblem, ContactSolution
from signorini.solvers.base import judge

log = logging.getLogger(__name__)

#: the accepted relative residuals and force error of a level (the condensed method's default)
SWEEP_TOL = 1e-9


@dataclass(frozen=True)
class SweepLevel:
    """One load level: target and reached load (physical), push, and the contact measures."""

    load: float
    total_force: float
    delta: float
    a: float
    p0: float
    a_ref: float | None
    p0_ref: float | None
    status: str = "converged"
    message: str = ""
    force_error: float = float("nan")


#: most loads one sweep solves
MAX_LOADS = 1000


def parse_loads(text: str) -> np.ndarray:
    """``P1:P2:n`` → n loads from P1 to P2 (linearly spaced)."""
    parts = text.split(":")
    try:
        first, last, count = float(parts[0]), float(parts[1]), int(parts[2])
        if len(parts) != 3:
            raise ValueError
    except (ValueError, IndexError):
        raise InputError(f"--load {text!r} is not P1:P2:n, e.g. --load 0.001:0.004:8") from None
    if not (np.isfinite(first) and np.isfinite(last) and 0 < first <= last and count >= 1):
        raise InputError(f"--load {text!r} needs 0 < P1 ≤ P2 and n ≥ 1")
    if count > MAX_LOADS:
        raise InputError(f"--load {text!r} asks for {count} loads: at most {MAX_LOADS} "
                         f"(each is one solve), e.g. --load {parts[0]}:{parts[1]}:{MAX_LOADS}")
    return np.linspace(first, last, count)


def sweep_loads(problem: ContactProblem, loads: np.ndarray,
                progress: Callable[[int, int], None] | None = None) -> list[SweepLevel]:
    """Solve ``problem`` exactly at every load of ``loads`` (physical units, full body), each
    level judged (its ``status``: ``converged`` only when certified and the model adequate)."""
    if problem.model.push is None:
        raise InputError(f"scene {problem.name!r} is not loaded by a prescribed push: "
                         "it cannot be swept over loads")
    start = time.perf_counter()
    factor = problem.factor()
    W = delassus(problem.N, factor)
    pu = problem.model.push
    b1 = problem.N @ factor.solve(pu.f1) - pu.d1
    # a body loaded by a traction on a cut: the traction follows the load, the push is found
    c = problem.N @ factor.solve(pu.f_load) if pu.f_load is not None else np.zeros(problem.m)
    log.info("sweep set-up (factorisation and %d × %d Delassus operator) in %.2f s",
             problem.m, problem.m, time.perf_counter() - start)
    hertz = problem.model.reference is not None and problem.model.reference.R is not None
    levels = []
    for i, load in enumerate(loads):
        target = load / problem.scales.force
        s, lam = push_for_load_condensed(W, b1, target * c - pu.d0, pu.d0, target,
                                         problem.force_multiplicity)
        level_problem = problem.pushed(s, load=target)
        u = factor.solve(level_problem.f - problem.N.T @ lam)
        solution = judge(level_problem, ContactSolution(
            "condensed", u, lam, "converged", factor=WithDelassus(factor, problem.N, W)), SWEEP_TOL)
        if solution.status != "converged":
            log.warning("load %g: %s: %s", load, solution.status, solution.message)
        profile = contact_profile(level_problem, solution)
        ref = compare_hertz(level_problem, solution) if hertz else None
        levels.append(SweepLevel(
            load=float(load), total_force=profile.total_force,
            delta=float(level_problem.model.push.delta or np.nan),
            a=contact_half_width(profile), p0=float(profile.pressure[np.argmin(profile.x)]),
            a_ref=ref.a_ref if ref else None, p0_ref=ref.p0_ref if ref else None,
            status=solution.status, message=solution.message,
            force_error=certificate(level_problem, solution).force_error))
        if progress is not None:
            progress(i + 1, len(loads))
    return levels


def plot_sweep(levels: list[SweepLevel], ax=None):
    """Contact half-width and peak pressure against load, with Hertz's curves (a ∝ √P, p₀ ∝ √P)."""
    axes = _axes(ax)
    loads = np.array([lv.total_force for lv in levels])
    grid = np.linspace(0.0, loads.max() * 1.05, 200)
    twin = axes.twinx()
    axes.plot(loads, [lv.a for lv in levels], "o", color="C0", label="a (numeric)")
    twin.plot(loads, [lv.p0 for lv in levels], "s", color="C1", label="p₀ (numeric)")
    if levels[0].a_ref is not None:
        lv = levels[-1]
        axes.plot(grid, lv.a_ref * np.sqrt(grid / lv.total_force), "-", color="C0", label="Hertz a ∝ √P")
        twin.plot(grid, lv.p0_ref * np.sqrt(grid / lv.total_force), "--", color="C1",
                  label="Hertz p₀ ∝ √P")
    axes.set_xlabel("load P per unit thickness")
    axes.set_ylabel("contact half-width a", color="C0")
    twin.set_ylabel("peak pressure p₀", color="C1")
    lines = axes.get_legend_handles_labels()
    more = twin.get_legend_handles_labels()
    axes.legend(lines[0] + more[0], lines[1] + more[1], fontsize=7, loc="lower right")
    axes.grid(alpha=0.3)
    axes.set_xlim(left=0.0)
    return axes


__all__ = ["SweepLevel", "parse_loads", "sweep_loads", "plot_sweep"]
