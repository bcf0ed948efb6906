"""Hertz's cylinder, as in the source paper: the paper's Uzawa iteration against the exact answer.

Run it (``.venv/bin/python validation/hertz_cylinder.py``) to print the
comparison with Hertz and write ``hertz_cylinder.png``; the tests import it
and pin its numbers. Module-level names hold the results.
"""

from __future__ import annotations

from pathlib import Path

import signorini
from signorini.certification.comparison import compare
from signorini.references.pressure import compare_hertz, contact_profile
from signorini.scenes import build_problem
from signorini.solvers.registry import solve

PARAMS = {"a_over_R": 0.05, "E": 2.1e11, "nu": 0.3, "R": 0.01}

problem = signorini.at_load(build_problem("hertz-cylinder", params=PARAMS))
exact = solve(problem, "pdas", tol=1e-9)
paper = solve(problem, "uzawa", tol=1e-9)
hertz = compare_hertz(problem, exact)
hertz_uzawa = compare_hertz(problem, paper)
agreement = compare(problem, exact, paper)


def visualize(path: str | Path = "hertz_cylinder.png") -> Path:
    """Nodal pressures of both methods against Hertz's ellipse."""
    from signorini.files import save_figure
    from signorini.output import plots

    profile = contact_profile(problem, exact)
    ax = plots.pressure_profile(profile.x, profile.pressure, a_ref=hertz.a_ref, p0_ref=hertz.p0_ref,
                                label="pdas (exact)",
                                others=[("uzawa (the paper)", contact_profile(problem, paper).pressure)])
    ax.set_title(f"Hertz cylinder, a/R = {PARAMS['a_over_R']}, {problem.n} dofs", fontsize=9)
    save_figure(ax.figure, path)
    return Path(path)


if __name__ == "__main__":
    print(f"{problem.n} dofs, {problem.m} contact candidates")
    print(f"pdas : {exact.status}, {exact.iterations} steps; uzawa: {paper.status}, "
          f"{paper.iterations} iterations (rho = {paper.extras['rho']:.3g})")
    print(f"a  = {hertz.a:.6e} m   (Hertz {hertz.a_ref:.6e}, {100 * hertz.a_rel:.2f} %)")
    print(f"p0 = {hertz.p0:.6e} Pa  (Hertz {hertz.p0_ref:.6e}, {100 * hertz.p0_rel:.2f} %)")
    print(f"pressure L2 error {100 * hertz.pressure_l2_rel:.2f} %, force balance {hertz.force_balance:.1e}")
    print(f"uzawa vs pdas: λ {agreement.lam_rel:.1e}, {agreement.misclassified} nodes misclassified")
    print(f"figure: {visualize()}")
