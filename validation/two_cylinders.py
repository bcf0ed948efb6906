"""Hertz between two elastic cylinders of unlike materials: the exact answer, the paper's Uzawa,
and the methods that take rows as bounds refusing the pair.

Steel on aluminium in SI units (E1 = 210 GPa, ν1 = 0.3, R1 = 10 mm on
E2 = 70 GPa, ν2 = 0.33, R2 = 20 mm) against two-body Hertz with
``1/E* = (1 − ν1²)/E1 + (1 − ν2²)/E2`` and ``1/R* = 1/R1 + 1/R2``. Run it
(``.venv/bin/python validation/two_cylinders.py``) to print the comparison;
the tests import it and pin its claims.
"""

from __future__ import annotations

import signorini
from signorini.errors import InputError
from signorini.certification.comparison import compare
from signorini.references.pressure import compare_hertz
from signorini.scenes import build_problem
from signorini.solvers.registry import solve

PARAMS = {"E1": 2.1e11, "nu1": 0.3, "R1": 0.01, "E2": 7e10, "nu2": 0.33, "R2": 0.02,
          "a_over_R": 0.05}

problem = signorini.at_load(build_problem("hertz-two-cylinders", params=PARAMS))
exact = solve(problem, "pdas", tol=1e-9)
paper = solve(problem, "uzawa", tol=1e-9)
hertz = compare_hertz(problem, exact)
agreement = compare(problem, exact, paper)
try:
    solve(problem, "pdas-amg")
    refusal = ""
except InputError as exc:  # its rows share the master's dofs: no bound form
    refusal = str(exc)

if __name__ == "__main__":
    print(f"{problem.n} dofs, {problem.m} contact rows ({problem.params['discretisation']})")
    print(f"a  = {hertz.a:.6e} m   (Hertz {hertz.a_ref:.6e}, {100 * hertz.a_rel:.3f} %)")
    print(f"p0 = {hertz.p0:.6e} Pa  (Hertz {hertz.p0_ref:.6e}, {100 * hertz.p0_rel:.3f} %)")
    print(f"uzawa: {paper.status}, {paper.iterations} iterations; vs pdas: λ {agreement.lam_rel:.1e}, "
          f"{agreement.misclassified} nodes misclassified")
    print(f"pdas-amg: {refusal}")
