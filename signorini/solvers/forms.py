"""Formulations of the contact QP handed to a QP backend: primal, shifted, dual.

Every ``qp-*`` method (and ``cvxpy``) takes the option ``form``; the backend
always solves ``min ½xᵀPx + qᵀx`` subject to ``Gx ≤ h`` (or ``x ≥ 0``), and
the answer comes back in the problem's own variables ``(u, λ)``, so that the
package's certificate judges it as it judges every method.

- ``primal``: ``P = ½(K + Kᵀ)``, ``q = −f``, ``G = N``, ``h = d``; ``u = x``,
  ``λ = z`` (qpsolvers' ``z ≥ 0`` of ``Gx ≤ h``). No factorisation.
- ``shifted``: the same QP in ``v = u − u₀`` with ``K u₀ = f``: ``q = 0``,
  ``h = d − N u₀``, so that the objective is the contact's own energy and a
  backend's relative tests speak about the contact rather than about the
  elastic energy of the whole body. Cost: one factorisation of K and one
  back-solve; ``u = u₀ + x``, ``λ = z``.
- ``dual``: the condensed dual over ``λ ≥ 0`` with the Delassus operator
  ``W = N K⁻¹ Nᵀ`` (dense m × m): ``P = W``, ``q = −(N K⁻¹ f − d)``, the very
  problem Uzawa ascends. Cost: one factorisation, m back-solves for W (in
  blocks), one for ``N K⁻¹ f`` and one for ``u = K⁻¹(f − Nᵀλ)``; memory m².
  Refused when m exceeds ``max_dense_dofs`` (default 3000).

The shifted and dual forms keep their factorisation of K on the solution
(:attr:`ContactSolution.factor`) for the certificate's duality gap.

``polish=True`` (:func:`polish`): the active set guessed from the backend's
answer, the equality-constrained KKT system on it solved once (by the form's
factorisation of K when it has one, else one factorisation of K with the
active dofs pinned), and the polished point kept only when its certificate
is better than the backend's; ``extras["polish"]`` records both.
"""

from __future__ import annotations

import contextlib
import logging
import time
import warnings
from dataclasses import dataclass, field
from typing import Any, Iterator

import numpy as np
import scipy.sparse as sp

from signorini.errors import InputError
from signorini.certification.kkt import ACTIVE, certificate, classify
from signorini.numerics.active_set import ActiveSetSolver
from signorini.numerics.factor import counting, factorize
from signorini.numerics.lcp import delassus, forces_on
from signorini.problem.contact import ContactProblem, ContactSolution
from signorini.solvers.base import acceptance

log = logging.getLogger(__name__)

FORMS = ("primal", "shifted", "dual")
#: ``‖K K⁻¹f − f‖∞ / ‖f‖∞`` above this means K is singular (SuperLU does not say so itself)
SINGULAR = 1e-6


@dataclass
class Formulation:
    """One QP for a backend, ``min ½xᵀPx + qᵀx`` s.t. ``Gx ≤ h`` (``G`` None: ``x ≥ 0``).

    ``factor`` is the factorisation of K the form made (None for ``primal``),
    ``u0 = K⁻¹f`` the unconstrained displacement
    (``shifted``, ``dual``), ``b = N u₀ − d`` and ``W`` (``dual``); ``work`` the
    factorisations and back-solves it cost (building it and mapping the answer back),
    ``seconds`` the time to build it and ``note`` why it is not the form asked for.
    """

    name: str
    P: Any
    q: np.ndarray
    G: Any = None
    h: np.ndarray | None = None
    factor: Any = None
    u0: np.ndarray | None = None
    W: np.ndarray | None = None
    b: np.ndarray | None = None
    work: dict[str, int] = field(default_factory=dict)
    seconds: float = 0.0
    note: str = ""

    @property
    def bounds(self) -> bool:
        """The constraint is ``x ≥ 0`` (the dual), not ``Gx ≤ h``."""
        return self.G is None

    def answer(self, problem: ContactProblem, x: np.ndarray,
               z: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
        """``(u, λ)`` of the contact problem from the backend's ``x`` and multiplier ``z``
        of ``Gx ≤ h`` (unused by the dual, whose ``x`` is λ)."""
        x = np.asarray(x, dtype=float).copy()
        if self.name == "dual":  # one more back-solve, counted with the form's work
            self.work["back_solves"] = self.work.get("back_solves", 0) + 1
            return self.factor.solve(problem.f - problem.N.T @ x), x
        z = np.asarray(z, dtype=float).copy()
        return (x + self.u0 if self.name == "shifted" else x), z


@contextlib.contextmanager
def warned(label: str) -> Iterator[list[str]]:
    """The messages of the warnings the block raised (every one, each logged at debug level),
    in the list it is given once the block ends: a backend's warnings travel with its answer."""
    caught: list[str] = []
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always")
        try:
            yield caught
        finally:
            caught += [str(w.message) for w in record]
    for message in caught:
        log.debug("%s warned: %s", label, message)


def resolve(method: str, problem: ContactProblem, given: str | None, default: str,
            limit: int) -> tuple[str, str]:
    """The form to build and why, before any work: ``(form, note)``.

    The dual's dense W is refused above ``limit`` candidates when the caller asked for it (an
    InputError); the method's default dual falls back to ``primal`` there, and ``note`` says so.
    """
    form = default if given is None else given
    if form == "dual" and problem.m > limit and given is None:
        return "primal", (f"the default dual form needs a dense {problem.m} × {problem.m} W, "
                          f"over max_dense_dofs = {limit}: primal form instead")
    if form == "dual" and problem.m > limit:
        raise InputError(
            f"method {method!r} with form='dual' builds the dense m × m Delassus operator "
            f"W = N K⁻¹ Nᵀ ({problem.m} back-solves, {8 * problem.m ** 2 / 1e6:.0f} MB) and "
            f"m = {problem.m} exceeds max_dense_dofs = {limit}: use form=shifted, or raise "
            "the option max_dense_dofs")
    return form, ""


def _unconstrained(problem: ContactProblem):
    """A factorisation of K and ``u₀ = K⁻¹f``; LinAlgError when K is singular.

    CHOLMOD and PARDISO refuse a singular K; SuperLU may not, so ``K u₀ = f``
    is checked (one product).
    """
    try:
        factor = factorize(problem.K)
    except Exception as exc:  # CHOLMOD's LinAlgError, PARDISO's PyPardisoError
        raise np.linalg.LinAlgError(f"K cannot be factorised ({exc})") from exc
    u0 = factor.solve(problem.f)
    scale = max(float(np.max(np.abs(problem.f), initial=0.0)), 1e-300)
    if not np.all(np.isfinite(u0)) or np.max(np.abs(problem.K @ u0 - problem.f)) > SINGULAR * scale:
        raise np.linalg.LinAlgError("K is singular (K⁻¹f does not solve K u = f)")
    return factor, u0


def formulate(problem: ContactProblem, form: str, dense: bool = False,
              fallback: bool = False) -> Formulation:
    """The QP of ``form`` for ``problem``; ``dense`` gives numpy arrays instead of csc matrices.

    The shifted and dual forms need K⁻¹: on a singular K (a body held by
    contact alone) they raise LinAlgError, or with ``fallback`` give the primal
    form with a ``note`` saying why.
    """
    start = time.perf_counter()
    with counting() as work:
        K = sp.csc_matrix(0.5 * (problem.K + problem.K.T))
        note = ""
        if form != "primal":
            try:
                factor, u0 = _unconstrained(problem)
            except np.linalg.LinAlgError as exc:
                if not fallback:
                    raise np.linalg.LinAlgError(f"form={form!r} needs K⁻¹: {exc}; the primal "
                                                "form needs none (form=primal)") from exc
                note = f"the default {form} form needs K⁻¹: {exc}; primal form instead"
                form = "primal"
        out: Formulation
        if form == "primal":
            out = Formulation(form, K, -problem.f, sp.csc_matrix(problem.N), problem.d.copy())
        elif form == "shifted":
            out = Formulation(form, K, np.zeros(problem.n), sp.csc_matrix(problem.N),
                              problem.d - problem.N @ u0, factor=factor, u0=u0)
        else:
            W = delassus(problem.N, factor)
            b = problem.N @ u0 - problem.d
            out = Formulation(form, W if dense else sp.csc_matrix(W), -b, factor=factor,
                              u0=u0, W=W, b=b)
        out.note = note
        if dense and sp.issparse(out.P):
            out.P = out.P.toarray()
        if dense and out.G is not None:
            out.G = out.G.toarray()
    out.work = {"factorisations": work.factorisations, "back_solves": work.back_solves}
    out.seconds = time.perf_counter() - start
    return out


def _kkt_on(problem: ContactProblem, form: Formulation, active: np.ndarray):
    """``(u, λ, factor)`` of the equality-constrained KKT system on ``active``.

    The dual holds W: ``W_AA λ_A = b_A`` and one back-solve. The other forms
    factorise K once with the active dofs pinned (the saddle-point matrix when
    a row of N bounds more than one dof): cheaper than the |A| back-solves of a
    Schur complement on the shifted form's factor (docs/calibration.md).
    """
    if form.W is None:
        solver = ActiveSetSolver(problem.K, problem.N)
        u, lam = solver.solve(active, problem.f, problem.d)
        return u, lam, solver.factor or form.factor
    lam = forces_on(form.W, form.b, active)  # W is symmetric (delassus)
    return form.factor.solve(problem.f - problem.N.T @ lam), lam, form.factor


def polish(problem: ContactProblem, form: Formulation, raw: ContactSolution,
           tol: float | None) -> ContactSolution:
    """The backend's answer polished on its guessed active set, when that certifies better.

    The polished point replaces the raw one only when its worst certificate
    residual is smaller; a polished point within the tolerance the registry
    accepts is claimed ``converged`` (the registry's judge checks it again). Both
    certificates and which answer is returned go to ``extras["polish"]``.
    """
    if not (np.all(np.isfinite(raw.u)) and np.all(np.isfinite(raw.lam))):
        raw.extras["polish"] = {"kept": False, "reason": "no finite answer to polish"}
        return raw
    start = time.perf_counter()
    active = classify(problem, raw) == ACTIVE
    u, lam, factor = _kkt_on(problem, form, active)
    polished = ContactSolution(method=raw.method, u=u, lam=lam, status="converged",
                               factor=factor)
    raw.factor = factor
    raw_cert, new_cert = certificate(problem, raw), certificate(problem, polished)
    raw_worst, new_worst = raw_cert.worst()[1], new_cert.worst()[1]
    # a polished point that pulls a node (tension) is a wrong active set, whatever else it fixes
    pulls = new_cert.as_dict()["dual_sign"] > max(tol or 0.0, raw_cert.as_dict()["dual_sign"])
    kept = bool(new_worst < raw_worst and not pulls)
    record = {"kept": kept, "active": int(active.sum()), "raw_status": raw.status,
              "raw": raw_cert.as_dict(), "polished": new_cert.as_dict(),
              "seconds": time.perf_counter() - start}
    raw.extras["polish"] = record
    raw.factor = factor
    if not kept:
        raw.message += f"; polish on {int(active.sum())} active nodes did not improve the " \
                       f"certificate ({new_worst:.1e} ≥ {raw_worst:.1e}): the backend's answer"
        return raw
    raw.u, raw.lam = u, lam
    certified = new_worst <= acceptance(tol)
    if certified:
        raw.status = "converged"
    raw.message += f"; polished on {int(active.sum())} active nodes (certificate " \
                   f"{raw_worst:.1e} → {new_worst:.1e}): the polished answer" + \
                   ("" if certified else f", still {raw.status} (above {acceptance(tol):.0e})")
    return raw


def solution_from(problem: ContactProblem, form: Formulation, method: str, status: str, x: Any,
                  z: Any, *, said_by: str, extras: dict[str, Any], note: str | None,
                  iterations: Any, build_time: float, solve_time: float, tol: float | None,
                  polishing: bool) -> ContactSolution:
    """A backend's ``x`` and ``z`` in ``form`` as the problem's solution: a failure when it gave
    none, polished on its active set when ``polishing``; the message opens with ``said_by`` and
    ``extras`` gain the form's record."""
    note = note or form.note
    extras = {**extras, "form": form.name, "form_work": form.work, "form_s": form.seconds,
              "form_note": note}
    said = f" ({note})" if note else "" if form.name == "primal" else f" ({form.name} form)"
    common = dict(message=said_by + said, iterations=int(iterations or 0),
                  build_time=build_time, solve_time=solve_time, extras=extras)
    if x is None or (z is None and not form.bounds):
        return ContactSolution.failure(method, problem, "failed" if status == "converged" else status,
                                       **common)
    u, lam = form.answer(problem, x, z)
    solution = ContactSolution(method=method, u=u, lam=lam, status=status, factor=form.factor,
                               **common)
    return polish(problem, form, solution, tol) if polishing else solution


__all__ = ["Formulation", "warned", "resolve", "formulate", "polish", "solution_from", "FORMS"]
