"""The contact QP on PETSc: SNES-VI and TAO on the bound form, serial or under MPI.

The constraints become bounds (:mod:`signorini.solvers.bounds`: each contact node's dofs
rotated into its obstacle's normal–tangent frame), and PETSc solves
``min ½ vᵀ K v − fᵀ v`` subject to ``lower ≤ v ≤ upper`` by one of

* ``petsc-vi``: SNES ``vinewtonrsls``, reduced-space semismooth Newton for the variational
  inequality ``K v − f ⟂ bounds``, with a full-step line search (on a QP a full Newton step
  is exact on the set it guesses);
* ``petsc-tron``: TAO ``tron``, trust-region Newton with gradients projected onto the bounds;
* ``petsc-gpcg``: TAO ``gpcg``, gradient projection with conjugate gradients.

The linear solves are MUMPS's parallel LU (``ksp=mumps``) or CG preconditioned by PETSc's
GAMG with the rigid-body modes as near-null space (``ksp=gamg``); ``ksp=auto`` takes GAMG for
3D problems from :data:`GAMG_FROM_DOFS` dofs and MUMPS otherwise (docs/petsc.md). Under
``mpirun -n N`` rank 0 assembles, rotates and splits the rows by whole nodes
(:mod:`signorini.solvers.cluster`); each rank builds its block of a parallel AIJ matrix, and
rank 0 gathers the answer and recovers the contact forces as the reactions on the active
bounds. Extra PETSc options go through ``petsc_options`` ("-snes_monitor -ksp_view …").
"""

from __future__ import annotations

import functools
import time
from typing import Any

import numpy as np

from signorini.problem.contact import ContactProblem, ContactSolution
from signorini.solvers import cluster
from signorini.solvers.base import Method
from signorini.solvers.bounds import NoBoundForm, bound_form
from signorini.solvers.options import Option, declare, resolved, take_options
from signorini.solvers.petsc_piece import pieces, reason_text

KSP_CHOICES = ("auto", "mumps", "gamg")
DEFAULTS = declare(Option("ksp", "choice", "auto", choices=KSP_CHOICES),
                   Option("petsc_options", "text", ""))
#: ``ksp=auto`` uses GAMG for 3D problems of at least this many dofs (MUMPS below, and in 2D)
GAMG_FROM_DOFS = 20_000
#: each method's PETSc solver kind and type, whether it is exact (a Newton method that ends on
#: the active set's KKT system), and its summary
KINDS = {
    "petsc-vi": ("snes", "vinewtonrsls", True, "PETSc SNES vinewtonrsls (semismooth Newton on "
                                               "the bounds), MUMPS or CG+GAMG; MPI"),
    "petsc-tron": ("tao", "tron", False, "PETSc TAO tron (trust-region Newton on the bounds), "
                                         "MUMPS or CG+GAMG; MPI"),
    "petsc-gpcg": ("tao", "gpcg", False, "PETSc TAO gpcg (gradient projection + CG on the "
                                         "bounds); MPI"),
}


def solve_petsc(problem: ContactProblem, method: str, *, tol: float | None = None,
          max_iter: int | None = None, **options: Any) -> ContactSolution:
    """PETSc's solver of ``method`` (a key of :data:`KINDS`) on the bound form."""
    opts = take_options(method, options, DEFAULTS)
    kind, petsc_type, _, _ = KINDS[method]
    tol, max_iter = resolved(method, "petsc", tol, max_iter)
    ksp = opts["ksp"]
    start = time.perf_counter()
    try:
        form = bound_form(problem)
    except NoBoundForm as exc:
        return ContactSolution.failure(method, problem, exc.status, str(exc),
                                       solve_time=time.perf_counter() - start)
    x0 = np.clip(np.zeros(form.n), form.lower, form.upper)
    if ksp == "auto":
        ksp = "gamg" if form.block == 3 and form.n >= GAMG_FROM_DOFS else "mumps"
    ranks = cluster.size()
    job = {"run": "signorini.solvers.petsc_piece:solve_piece", "n": form.n, "block": form.block,
           "kind": (kind, petsc_type), "ksp": ksp, "tol": tol, "max_iter": max_iter,
           "f_norm": float(np.linalg.norm(form.f)), "petsc_options": opts["petsc_options"]}
    parts = pieces(form, ranks, x0, gamg=ksp == "gamg")
    build_time = time.perf_counter() - start
    results = cluster.distribute(job, parts)
    del parts
    per_rank = [{key: r[key] for key in ("rank", "local_rows", "local_nnz", "setup_s", "solve_s",
                                         "rank_s", "peak_memory_mb", "multigrid_setups",
                                         "multigrid_setup_s", "multigrid_apply_s", "error")
                 if key in r}
                for r in results]
    extras = {"ranks": ranks, "per_rank": per_rank, "petsc_type": petsc_type, "ksp": ksp}
    errors = [r["error"] for r in results if "error" in r]
    if errors:
        return ContactSolution.failure(method, problem, "failed", "; ".join(errors),
                                       build_time=build_time, extras=extras,
                                       solve_time=time.perf_counter() - start)
    v = np.concatenate([r["x"] for r in results])
    reason = results[0]["reason"]
    iterations = results[0]["iterations"]
    if "linear_iterations" in results[0]:
        extras["linear_iterations"] = results[0]["linear_iterations"]
    text = reason_text(kind, reason)
    status = "converged" if reason > 0 else ("max_iter" if "MAXIT" in text.upper() else "failed")
    message = (f"{petsc_type} with {ksp} on {ranks} rank{'s' if ranks > 1 else ''}: "
               f"{text} after {iterations} iterations")
    return ContactSolution(method=method, u=form.displacement(v), lam=form.multipliers(v),
                           status=status, message=message, iterations=iterations,
                           build_time=build_time, solve_time=time.perf_counter() - start,
                           extras=extras)


METHODS = tuple(
    Method(name=name, function=functools.partial(solve_petsc, method=name), summary=summary,
           requires=("petsc4py", "mpi4py"), extra="petsc", family="petsc",
           exact=exact, typed_options=DEFAULTS, bound_rows=True)
    for name, (_, _, exact, summary) in KINDS.items())


__all__ = ["solve_petsc", "METHODS"]
