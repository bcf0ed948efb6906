"""``auto``: the method picked from the problem's dimension, size and the installed backends.

- 2D and axisymmetric models: ``pdas`` (exact; its sparse factorisations of a
  2D stiffness barely fill in: 1M dofs end to end in about 30 s here);
- 3D models from :data:`AMG_FROM_DOFS` dofs: ``pdas-amg`` (CG + algebraic
  multigrid, no factorisation: ``pdas`` ran out of memory on the 350k-dof
  sphere, its 3D factors fill in like n^(4/3)), when pyamg is installed and
  every contact row bounds its own dofs (rows sharing a dof have no bound
  form); otherwise ``pdas``;
- smaller 3D models: ``pdas``, or ``pdas-amg`` from :data:`PUSHED_AMG_FROM_DOFS` when
  no load targeting has solved the model already (a push: faster there, measured);
- any model whose load targeting already factorised K around a predicted
  contact zone (:class:`~signorini.numerics.zone.ZoneSolver`, kept on the
  problem): ``nested``, which reuses that factorisation and costs back-solves
  only (the 47k-dof 3D sphere: 0.16 s against pdas's 7.8 s and 8 factorisations).
  A scene built for ``auto`` (``build_problem(..., solved_by="auto")``, as the
  API and the command line do) is not load-targeted by factorisation when
  ``pdas-amg`` will be picked: its target load stays pending and ``pdas-amg``
  matches it with the answer (:func:`defers_load_targeting`); a pending
  problem for any other pick is matched first (``problem.matched()``).

The chosen method's name is the solution's ``method``; ``extras["auto"]``
and the message say what was picked and why. Options are passed on to the
chosen method.
"""

from __future__ import annotations

import importlib.util
from typing import Any

import numpy as np

from signorini.problem import ContactProblem, ContactSolution
from signorini.solvers import amg, nested, pdas
from signorini.solvers.base import Method

#: 3D models of at least this many free dofs go to pdas-amg, and a pending target load is left to
#: it (at 350k pdas was killed for memory: 3D factorisations fill in like n^(4/3)). Below, a target
#: load is met by factorisation and nested or pdas confirm it: the default hertz-sphere-3d at
#: 46,964 dofs took 2.2 s whole command so against 2.6 s with pdas-amg, at 11,975 1.2 s both
AMG_FROM_DOFS = 50_000
#: a 3D model with a mesh and no load targeting (a push) goes to pdas-amg from this many dofs:
#: whole commands of the pushed hertz-sphere-3d (delta=0.0025) with pdas and pdas-amg took 1.0 s
#: and 1.0 s at 6,879 dofs, 1.9 s and 1.2 s at 11,935, 4.8 s and 2.6 s at 46,820 (by hand, idle;
#: the method times alone are docs/amg/bench.md's second table)
PUSHED_AMG_FROM_DOFS = 10_000
CHOICES = {"pdas": pdas.solve, "pdas-amg": amg.solve, "nested": nested.solve}


def dimension(problem: ContactProblem) -> int:
    """2 or 3: the mesh's (or, without one, the contact points') dimension."""
    if problem.mesh is not None:
        return int(problem.mesh.p.shape[0])
    return int(np.atleast_2d(problem.contact_points).shape[1])


def _rows_share_a_dof(problem: ContactProblem) -> bool:
    N = problem.N.tocsr()
    return bool(N.nnz and np.bincount(N.indices[N.data != 0], minlength=problem.n).max() > 1)


def choose(problem: ContactProblem, options: Any = ()) -> tuple[str, str]:
    """``(method, why)`` for ``problem`` (and the names of the ``options`` given: nested is
    picked only when it takes them all)."""
    dim, n = dimension(problem), problem.n
    if problem.warm_start.zone_solver is not None and not set(options) - set(nested.DEFAULTS):
        return "nested", (f"K ({n:,} dofs) already factorised by the load targeting around the "
                          "predicted contact zone: nested (exact, back-solves only)")
    if problem.axisymmetric or dim < 3:
        kind = "axisymmetric" if problem.axisymmetric else "2D"
        return "pdas", f"{kind} model: pdas (exact; 2D factorisations are fast)"
    pushed = problem.mesh is not None and problem.warm_start.lam is None and not problem.pending
    least = PUSHED_AMG_FROM_DOFS if pushed else AMG_FROM_DOFS
    if n < least:
        return "pdas", f"3D model of {n:,} dofs < {least:,}: pdas (a factorisation is cheap)"
    if importlib.util.find_spec("pyamg") is None:
        return "pdas", f"3D model of {n:,} dofs, but pyamg is not installed (pip install pyamg): pdas"
    if _rows_share_a_dof(problem):
        return "pdas", f"3D model of {n:,} dofs whose contact rows share dofs (no bound form): pdas"
    return "pdas-amg", (f"3D model of {n:,} dofs ≥ {least:,}: pdas-amg "
                        "(CG + multigrid, no factorisation to fill in)")


def defers_load_targeting(problem: ContactProblem, method: str) -> bool:
    """Whether ``method`` (``auto`` or ``pdas-amg``) matches ``problem``'s pending target load
    itself, so that its assembly need not factorise K for it."""
    if method == "auto" and choose(problem)[0] != "pdas-amg" or method not in ("auto", "pdas-amg"):
        return False
    return amg.border_factor(problem) is not None


def solve(problem: ContactProblem, *, tol: float | None = None, max_iter: int | None = None,
          **options: Any) -> ContactSolution:
    """Solve with the method :func:`choose` picks; say which and why."""
    name, why = choose(problem, options)
    given = problem
    if problem.pending and name != "pdas-amg":  # only pdas-amg matches a target load itself
        problem = problem.matched()
        name, why = choose(problem, options)
    solution = CHOICES[name](problem, tol=tol, max_iter=max_iter, **options)
    if solution.problem is None and problem is not given:
        solution.problem = problem
    solution.method = name
    solution.extras["auto"] = why
    solution.message = f"auto picked {why}; {solution.message}"
    return solution


METHODS = (
    Method(name="auto", function=solve, family="auto", exact=True,
           summary="picks nested (K factorised by load targeting), pdas (2D, small 3D) or pdas-amg "
                   "(large 3D) and says why",
           default_tol=1e-9, targets_load=True,
           options=tuple(sorted(set(pdas.DEFAULTS) | set(amg.DEFAULTS) | set(nested.DEFAULTS)))),
)
