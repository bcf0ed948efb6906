"""Exact contact without a factorisation: PDAS with CG + algebraic multigrid (``pdas-amg``).

The primal-dual active set iteration of :mod:`~signorini.solvers.pdas` on the bound form of the
problem (:mod:`~signorini.solvers.bounds`: each contact row one bound ``aᵢ v_j ≤ dᵢ`` on the
node's rotated dofs, prescribed dofs kept as fixed rows so that node blocks stay whole). An
active set pins its bounded dofs at ``dᵢ/aᵢ``; the pinned SPD system is solved by CG
preconditioned with algebraic multigrid, the rigid-body modes as near-null space
(:mod:`signorini.numerics.multigrid`), never factorised. Then:

- the first active set is given (``active0``: ``signorini.solve`` passes the scene's
  prediction), or comes from a warm start's forces or from a coarse QP (``coarse``);
- a pending target load (``problem.model.pending``, left to this method by load control:
  ``Method.matches_load``) is matched with the answer: the push is one more unknown of every
  CG system (:class:`~signorini.solvers.amg_system.LoadBorder`); the push found is
  ``solution.extras["push"]`` (``push0`` the first guess);
- **one hierarchy** is built, for K with the first active set pinned; later sets differ in a
  few rows and CG pays for them in iterations;
- CG starts from the last step's displacement, and its tolerance follows Eisenstat & Walker
  (1996, choice 2) while the active set still moves: ``η_k = γ (‖r₀,k‖/‖r₀,k−1‖)²`` in
  [:data:`ETA_MIN`, :data:`ETA_MAX`], the first solve at ETA_MIN and the second starting the
  sequence again at ETA_MAX;
- when the set repeats, CG is driven to a stationarity residual of :data:`SAFETY` · tol against
  the contact forces, and the method stops only when the package's certificate is within
  ``tol``; the duality gap is computed with this method's own multigrid solver for K with the
  final set pinned (:class:`~signorini.solvers.amg_system.PinnedCG`).

Multigrid: ``amg=petsc`` (PETSc's GAMG through petsc4py,
:data:`~signorini.solvers.amg_system.GAMG_OPTIONS`), ``amg=pyamg`` (smoothed aggregation) or
``auto``: GAMG when petsc4py is installed (docs/amg/bench.md compares them).
"""

from __future__ import annotations

import logging
import time
from typing import Any

import numpy as np

from signorini.errors import InputError
from signorini.certification.kkt import certificate
from signorini.numerics.push import first_contact
from signorini.numerics.multigrid import pinned_cg
from signorini.numerics.zone import predict_zone
from signorini.problem.contact import ContactProblem, ContactSolution, WarmStart
from signorini.solvers import pdas
from signorini.solvers.bounds import NoBoundForm, bound_form
from signorini.solvers.amg_system import (CG_MAX_ITER, PinnedCG, PinnedSystem, Unknowns,
                                          border_factor, load_border, rotated)
from signorini.solvers.base import Method
from signorini.solvers.options import Option, declare, per_candidate, resolved, take_options

log = logging.getLogger(__name__)

DEFAULTS = declare(
    Option("amg", "choice", "auto", choices=("auto", "petsc", "pyamg")), Option("c", "positive", 1.0),
    Option("active0", "vector"), Option("coarse", "object", types=(ContactProblem,)),
    Option("callback", "callable"), Option("warm_start", "object", types=(WarmStart,)),
    Option("push0", "number"))
#: stationarity is driven to SAFETY · tol so that the certificate's other residuals have room
SAFETY = 0.1
#: Eisenstat–Walker: γ, the exponent, the largest and smallest forcing terms (the first step's
#: is the smallest: the predicted set is nearly right, a loose first solve lost it; module doc)
GAMMA, ALPHA, ETA_MAX, ETA_MIN = 0.9, 2.0, 0.1, 1e-4
#: a coarse model below this many dofs is solved by pdas (a factorisation is cheap there)
DIRECT_BELOW = 30_000
#: a cycling active set is solved tightly and judged by the certificate this many times at most
#: (PDAS cycles where nodes touch with no force; either set is then the answer)
MAX_CYCLES = 2


def _initial_active(problem: ContactProblem, opts: dict[str, Any]) -> tuple[np.ndarray, str]:
    """The first active set and where it came from."""
    if opts["active0"] is not None:
        return per_candidate("pdas-amg", "active0", opts["active0"], problem.m) != 0, "given"
    warm = opts["warm_start"]
    if warm is not None and warm.lam is not None:
        return warm.lam > 0, "the warm start"
    coarse = opts["coarse"]
    if coarse is None:
        return np.zeros(problem.m, dtype=bool), "none (no prediction)"
    if coarse.model.pending:
        raise InputError("method 'pdas-amg': option coarse must be a problem at its load (its "
                         "target is not matched yet: signorini.load_control.match(coarse).problem)")
    solution = pdas.pdas(coarse) if coarse.n < DIRECT_BELOW else pdas_amg(coarse,
                                                                           amg=opts["amg"])
    if solution.status != "converged":
        return np.zeros(problem.m, dtype=bool), "none (the coarse model did not solve)"
    zone = predict_zone(problem.contact_points, coarse.contact_points, solution.lam > 0,
                        neighbours=1)
    return zone.core, f"coarse model of {coarse.n} dofs"


def _forcing(eta: float, r0: float, r0_last: float | None) -> float:
    """Eisenstat–Walker choice 2 with its safeguard, within [ETA_MIN, ETA_MAX] (first step: ``eta``)."""
    if r0_last is None or r0_last <= 0:
        return eta
    new = GAMMA * (r0 / r0_last) ** ALPHA
    if GAMMA * eta ** ALPHA > 0.1:
        new = max(new, GAMMA * eta ** ALPHA)
    return min(max(new, ETA_MIN), ETA_MAX)


def pdas_amg(problem: ContactProblem, *, tol: float | None = None, max_iter: int | None = None,
          **options: Any) -> ContactSolution:
    """PDAS with each pinned system solved by CG + algebraic multigrid (see module doc)."""
    opts = take_options("pdas-amg", options, DEFAULTS)
    c = opts["c"]
    tol, max_iter = resolved("pdas-amg", "active set", tol, max_iter)
    start = time.perf_counter()
    if problem.model.pending and border_factor(problem) is None:
        raise InputError("method 'pdas-amg': the push of this problem does not move one rigid "
                         "set of dofs, so its target load cannot be a CG unknown: match the load "
                         "first (signorini.solve does)")
    try:
        form = bound_form(problem)
    except NoBoundForm as exc:
        return ContactSolution.failure("pdas-amg", problem, exc.status, str(exc),
                                       solve_time=time.perf_counter() - start)
    system, border = PinnedSystem(form), load_border(problem, form)
    active, source = _initial_active(problem, opts)
    active &= system.bounded
    if border is not None and not active.any():  # the push needs a contact to hold the body
        active, source = first_contact(problem.d) & system.bounded, "the first point of contact"
    build_time = time.perf_counter() - start
    system.build(active, opts["amg"])
    hierarchy = system.hierarchy
    unknowns = Unknowns(system, border, opts["push0"])
    x = unknowns.x
    if opts["warm_start"] is not None and opts["warm_start"].u is not None:
        x[:] = rotated(form, opts["warm_start"].u)
    d = problem.d
    floor = 1e-5 * float(np.max(np.abs(problem.f), initial=0.0))
    history: dict[str, list[float]] = {"changes": [], "active": [], "cg_iterations": [],
                                       "eta": []}
    eta, r0_last, final, tighten, cycles = ETA_MIN, None, False, 1.0, 0
    lam = np.zeros(problem.m)
    seen = {active.tobytes()}
    status, message = "max_iter", f"active set still changing after {max_iter} steps"
    step = 0
    for step in range(1, max_iter + 1):
        log.info("pdas-amg step %d: %d candidates in contact", step, int(np.sum(active)))
        free = system.pin(active, d, x)
        force = max(float(np.max(np.abs(lam * system.coef), initial=0.0)), floor, 1e-300)
        target = SAFETY * tighten * tol * force
        forcing: list[float] = []  # this step's η_k, once its first residual is known

        def done(r2: float, rinf: float, r0: float, target=target, final=final,
                 forcing=forcing) -> bool:
            if not forcing:
                forcing.append(0.0 if final else _forcing(eta, r0, r0_last))
            return rinf <= target or (not final and r2 <= forcing[0] * r0)

        result = pinned_cg(unknowns.operator, unknowns.rhs, unknowns.values, unknowns.free(free),
                           unknowns.precondition, done, CG_MAX_ITER, unknowns.weights(force))
        system.f = unknowns.loaded(system.f)
        lam = system.reactions(x, active)
        new_active = (lam + c * system.violation(x, d) > 0) & system.bounded
        changes = int(np.sum(new_active != active))
        history["changes"].append(changes)
        history["active"].append(int(new_active.sum()))
        history["cg_iterations"].append(result.iterations)
        history["eta"].append(forcing[0] if forcing else 0.0)
        if opts["callback"] is not None:
            opts["callback"](step, form.displacement(x), lam)
        repeated = new_active.tobytes() in seen  # a cycle: judged once its set is solved tightly
        if changes == 0 or repeated and final:
            force = max(float(np.max(np.abs(lam * system.coef), initial=0.0)), floor, 1e-300)
            if result.final_inf <= SAFETY * tighten * tol * force:
                candidate = ContactSolution(method="pdas-amg", u=form.displacement(x), lam=lam,
                                            status="converged")
                name, worst = certificate(unknowns.at_push(problem), candidate,
                                          duality_gap=False).worst()
                if worst <= tol:
                    status = "converged"
                    how = "repeated" if changes == 0 else \
                        "cycled (nodes touching with no force: either set is the answer)"
                    message = (f"active set of {int(active.sum())} nodes {how} after {step} "
                               f"steps, certificate {worst:.1e} ({name})")
                    break
                tighten *= 0.1
                if tighten < 1e-4:
                    status, message = "failed", (f"CG cannot bring the certificate's {name} "
                                                 f"residual ({worst:.1e}) under {tol:g}")
                    break
            final = True
            continue
        if repeated and cycles >= MAX_CYCLES:
            status = "failed"
            message = (f"the active set cycled after {step} steps (PDAS with inexact solves): "
                       "use pdas or petsc-vi")
            break
        if repeated:  # solve this set tightly; the certificate then decides (above)
            cycles, final = cycles + 1, True
            continue
        seen.add(new_active.tobytes())
        # the first solve's residual, from far, is no yardstick for the next ones (module doc)
        eta, r0_last = (ETA_MAX, None) if step == 1 else (forcing[0] if forcing else eta,
                                                            result.initial)
        active, final = new_active, False
    cg_iterations = int(sum(history["cg_iterations"]))
    u = form.displacement(x)
    extras = {"amg": hierarchy.backend, "hierarchies": 1,
              "cg_iterations": cg_iterations, "hierarchy_s": hierarchy.setup_s,
              "levels": hierarchy.levels, "first_active": source}
    if unknowns.push is not None:
        extras["push"] = unknowns.push
        message += "; the load matched with the push as one more unknown (no factorisation)"
    return ContactSolution(
        method="pdas-amg", u=u, lam=lam, status=status,
        message=(f"{message}; first active set from {source}; one {hierarchy.backend} hierarchy "
                 f"({hierarchy.setup_s:.2f} s), {cg_iterations} CG iterations"),
        iterations=step, build_time=build_time, solve_time=time.perf_counter() - start - build_time,
        history=history, extras=extras, factor=PinnedCG(unknowns.at_push(problem), system, active))


METHODS = (
    Method(name="pdas-amg", function=pdas_amg, family="active set", exact=True,
           summary="PDAS with CG + algebraic multigrid (one hierarchy), no factorisation: large 3D",
           requires=("pyamg",), extra="", typed_options=DEFAULTS,
           matches_load=lambda problem: border_factor(problem) is not None,
           prediction="active set", bound_rows=True, factor_free_from=0),
)


__all__ = ["pdas_amg", "DEFAULTS", "METHODS"]
