"""``auto``: the method picked from the problem's dimension, size, warm start and backends.

- a warm start holding a factorisation of K around the contact zone (load control leaves
  one): ``nested``, which reuses it and costs back-solves only;
- 2D and axisymmetric models: ``pdas`` (a 2D stiffness barely fills in);
- 3D models from :data:`AMG_FROM_DOFS` dofs (:data:`PUSHED_AMG_FROM_DOFS` when no load control
  precedes the method): ``pdas-amg`` (no factorisation: 3D factors fill in like n^(4/3)), when
  pyamg is installed and no two contact rows share a dof; otherwise ``pdas``.

The chosen method's name is the solution's ``method``; ``extras["auto"]`` and the message say
what was picked and why; options and the warm start go to the chosen method. The thresholds
were chosen on the Hertz sphere (docs/amg.md).
"""

from __future__ import annotations

import importlib.util
from typing import Any

import numpy as np

from signorini.numerics.multigrid import AMG_FROM_DOFS
from signorini.problem.contact import ContactProblem, ContactSolution, WarmStart
from signorini.solvers import amg, nested, pdas
from signorini.solvers.base import Method, rows_share_dofs

#: a 3D model with a mesh and nothing to match (a push) goes to pdas-amg from this many dofs
PUSHED_AMG_FROM_DOFS = 10_000
#: the methods auto picks from, by name
CHOICES = {method.name: method for method in (*pdas.METHODS, *amg.METHODS, *nested.METHODS)}


def dimension(problem: ContactProblem) -> int:
    """2 or 3: the mesh's (or, without one, the contact points') dimension."""
    if problem.model.mesh is not None:
        return int(problem.model.mesh.p.shape[0])
    return int(np.atleast_2d(problem.contact_points).shape[1])


def choose(problem: ContactProblem, options: Any = (),
           warm_start: WarmStart | None = None) -> tuple[str, str]:
    """``(method, why)`` for ``problem`` (the names of the ``options`` given: nested is picked
    only when it takes them all) and the ``warm_start`` it will be given."""
    dim, n = dimension(problem), problem.n
    if warm_start is not None and warm_start.zone_solver is not None \
            and not set(options) - set(nested.DEFAULTS):
        return "nested", (f"K ({n:,} dofs) already factorised around the contact zone (the "
                          "warm start): nested (exact, back-solves only)")
    if problem.model.axisymmetric or dim < 3:
        kind = "axisymmetric" if problem.model.axisymmetric else "2D"
        return "pdas", f"{kind} model: pdas (exact; 2D factorisations are fast)"
    pushed = problem.model.mesh is not None and (warm_start is None or warm_start.lam is None) \
        and not problem.model.pending
    least = PUSHED_AMG_FROM_DOFS if pushed else AMG_FROM_DOFS
    if n < least:
        return "pdas", f"3D model of {n:,} dofs < {least:,}: pdas (a factorisation is cheap)"
    if importlib.util.find_spec("pyamg") is None:
        return "pdas", f"3D model of {n:,} dofs, but pyamg is not installed (pip install pyamg): pdas"
    if rows_share_dofs(problem.N):
        return "pdas", f"3D model of {n:,} dofs whose contact rows share dofs (no bound form): pdas"
    return "pdas-amg", (f"3D model of {n:,} dofs ≥ {least:,}: pdas-amg "
                        "(CG + multigrid, no factorisation to fill in)")


def auto(problem: ContactProblem, *, tol: float | None = None, max_iter: int | None = None,
          **options: Any) -> ContactSolution:
    """Solve with the method :func:`choose` picks; say which and why."""
    name, why = choose(problem, options, options.get("warm_start"))
    if options.get("warm_start") is None:
        options.pop("warm_start", None)
    solution = CHOICES[name].function(problem, tol=tol, max_iter=max_iter, **options)
    solution.method = name
    solution.extras["auto"] = why
    solution.message = f"auto picked {why}; {solution.message}"
    return solution


METHODS = (
    Method(name="auto", function=auto, family="auto", exact=True,
           summary="picks nested (K factorised by load control), pdas (2D, small 3D) or pdas-amg "
                   "(large 3D) and says why",
           warm_from_load=True, factor_free_from=AMG_FROM_DOFS,
           chooses=lambda problem, options, warm_start: CHOICES[choose(problem, options,
                                                                       warm_start)[0]],
           typed_options={**nested.DEFAULTS, **amg.DEFAULTS, **pdas.DEFAULTS}),
)


__all__ = ["dimension", "choose", "auto", "METHODS"]
