"""Exact contact without a factorisation: PDAS with CG + algebraic multigrid (``pdas-amg``).

The primal-dual active set / semismooth Newton iteration of :mod:`~signorini.solvers.pdas`
(Hintermüller, Ito & Kunisch 2002) on the bound form of the problem
(:mod:`~signorini.solvers.bounds`: each contact row one bound ``aᵢ v_j ≤ dᵢ``
on the node's rotated dofs, prescribed dofs kept as fixed rows so that node
blocks stay whole). An active set pins its bounded dofs at ``dᵢ/aᵢ``; the
pinned SPD system is solved by conjugate gradients preconditioned with
algebraic multigrid given the rigid-body modes as near-null space
(:mod:`signorini.numerics.multigrid`), never factorised. Then:

- the first active set is given (``active0``: ``signorini.solve`` passes the
  candidates inside the reference's contact radius when the scene has one at its
  target load, Hertz's, else the set a coarser model of the scene predicts), or
  comes from a warm start's forces or from a coarse QP (``coarse``), so that few
  steps remain;
- a target load that is still pending (``problem.pending``: load control,
  :mod:`signorini.load_control`, leaves it to this method: ``Method.matches_load``) is
  matched with the answer: the push is one more unknown of every CG system, preconditioned
  by block elimination (:mod:`signorini.solvers.load_border`), so no factorisation of K is
  ever made; the push found is ``solution.extras["push"]`` (``push0`` the first guess);
- **one hierarchy** is built, for K with the first active set pinned; later
  sets differ in a few rows and CG pays for them in iterations;
- CG starts from the last step's displacement, and its tolerance follows
  Eisenstat & Walker (1996, choice 2) while the active set still moves:
  ``η_k = γ (‖r₀,k‖/‖r₀,k−1‖)²``, ``γ = 0.9``, in [:data:`ETA_MIN`, :data:`ETA_MAX`]:
  the first solve, from far, at ETA_MIN; the ratio against it would hold every
  later step there, so the second step starts the sequence again at ETA_MAX;
- when the set repeats, CG is driven to a stationarity residual of
  :data:`SAFETY` · tol against the contact forces, and the method stops only
  when the package's certificate (:func:`signorini.certification.kkt.certificate`) is within
  ``tol``; the duality gap is then computed with this method's own
  AMG-preconditioned solver for K with the final set pinned (:class:`PinnedCG`),
  not a serial factorisation.

Multigrid: ``amg=petsc`` (PETSc's GAMG, plain aggregation, through petsc4py,
set up by :data:`GAMG_OPTIONS`), ``amg=pyamg`` (smoothed aggregation) or
``auto``: GAMG when petsc4py is installed. One set-up and a CG solve to 1e-10
of the 350k-dof pushed ``hertz-sphere-3d``'s K, each way, are in docs/amg/bench.md
(``tools/amg_bench.py run --part backends``).
"""

from __future__ import annotations

import importlib.util
import logging
import time
from typing import Any

import numpy as np
import scipy.sparse as sp

from signorini.errors import InputError
from signorini.certification.kkt import certificate
from signorini.numerics.factor import selection_dofs
from signorini.numerics.push import first_contact
from signorini.numerics.multigrid import PyamgHierarchy, pinned_cg, pinned_matrix, threaded
from signorini.numerics.work import count
from signorini.numerics.zone import predict_zone
from signorini.problem.contact import ContactProblem, ContactSolution
from signorini.solvers import pdas, petsc_
from signorini.solvers.bounds import BoundForm, NoBoundForm, bound_form
from signorini.solvers.load_border import Unknowns, border_factor, load_border, rotated
from signorini.solvers.base import Method
from signorini.solvers.options import resolved
from signorini.solvers.options import positive_number, take_options

log = logging.getLogger(__name__)

AMG_CHOICES = ("auto", "petsc", "pyamg")
DEFAULTS = {"amg": "auto", "c": 1.0, "active0": None, "coarse": None, "callback": None,
            "warm_start": None, "push0": None}
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
#: CG iterations allowed per solve
CG_MAX_ITER = 3000
#: relative residual of the certificate's solve ``e = K̃⁻¹r`` (r: the final stationarity residual).
#: The gap is ``λ̂ᵀ(d − Nu) + ½eᵀKe``: a relative error ε of e in the energy norm moves the
#: quadratic term by about 2ε of itself, so a few digits do; a tighter solve costs a large part
#: of the method's time at scale (chosen from measurements, docs/amg.md)
CERTIFICATE_RTOL = 1e-2


#: PETSc options of the GAMG hierarchy (prefix ``signorini_amg_``; PETSC_OPTIONS overrides):
#: plain aggregation, a coarsest level of up to 10,000 equations solved directly and one
#: smoothing step per level: fewer levels and CG iterations than PETSc's defaults on 3D
#: elasticity, for a cheaper set-up than smoothed aggregation (chosen from measurements,
#: docs/amg.md)
GAMG_OPTIONS = {"pc_gamg_agg_nsmooths": "0", "pc_gamg_coarse_eq_limit": "10000",
                "mg_levels_ksp_max_it": "1"}
#: ... and, when PETSc has MUMPS, the coarsest level factorised by it, not PETSc's own LU (faster,
#: the same preconditioner to round-off: docs/amg.md); plain aggregation leaves rows of zeros
#: there (aggregates of fewer dofs than modes), which MUMPS is told to detect as null pivots
MUMPS_COARSE_OPTIONS = {"mg_coarse_sub_pc_factor_mat_solver_type": "mumps",
                        "mg_coarse_sub_mat_mumps_icntl_24": "1"}


class GamgHierarchy:
    """PETSc's GAMG for ``A`` (serial, plain aggregation, rigid-body near-null space)."""

    backend = "petsc"

    def __init__(self, A: sp.csr_matrix, modes: np.ndarray | None, block: int):
        PETSc = petsc_._petsc()
        start = time.perf_counter()
        comm = PETSc.COMM_SELF
        A = sp.csr_matrix(A)
        A.sort_indices()
        block = block if A.shape[0] % block == 0 else 1
        self._A = PETSc.Mat().createAIJWithArrays(A.shape, (
            A.indptr.astype(PETSc.IntType, copy=False), A.indices.astype(PETSc.IntType, copy=False),
            np.ascontiguousarray(A.data, dtype=PETSc.ScalarType)), comm=comm)
        self._A.setBlockSize(block)  # A's arrays not copied: petsc4py holds them for the Mat
        self._A.setOption(PETSc.Mat.Option.SPD, True)
        if modes is not None:
            vectors = []
            for column in modes.T:
                vector = self._A.createVecLeft()
                vector.setArray(column)
                vectors.append(vector)
            self._A.setNearNullSpace(PETSc.NullSpace().create(vectors=vectors, comm=comm))
        options = PETSc.Options("signorini_amg_")
        wanted = {**GAMG_OPTIONS,
                  **(MUMPS_COARSE_OPTIONS if PETSc.Sys.hasExternalPackage("mumps") else {})}
        for name, value in wanted.items():  # see GAMG_OPTIONS; a user's wins
            if not options.hasName(name):
                options.setValue(name, value)
        self._pc = PETSc.PC().create(comm)
        self._pc.setType("gamg")
        self._pc.setOperators(self._A)
        self._pc.setOptionsPrefix("signorini_amg_")
        self._pc.setFromOptions()
        self._pc.setUp()
        self._pc.getMGCoarseSolve().setUpOnBlocks()  # the coarsest level's LU (else: first cycle)
        self._x, self._y = self._A.createVecRight(), self._A.createVecLeft()
        self.levels = [int(self._pc.getMGLevels())]
        self.setup_s = time.perf_counter() - start
        count("hierarchies")

    def apply(self, r: np.ndarray) -> np.ndarray:
        self._x.setArray(r)
        self._pc.apply(self._x, self._y)
        return self._y.getArray().copy()

    def __del__(self) -> None:
        for name in ("_pc", "_A", "_x", "_y"):
            obj = getattr(self, name, None)
            if obj is not None:
                obj.destroy()


def _hierarchy(choice: str, A: sp.csr_matrix, modes: np.ndarray | None, block: int):
    if choice == "auto":
        installed = all(importlib.util.find_spec(m) is not None for m in ("petsc4py", "mpi4py"))
        choice = "petsc" if installed else "pyamg"
    return GamgHierarchy(A, modes, block) if choice == "petsc" else PyamgHierarchy(A, modes, block)


class PinnedSystem:
    """The bound form's K with the prescribed dofs and an active set's bounded dofs pinned."""

    def __init__(self, form: BoundForm):
        self.form, self.K, self.f, self.hierarchy = form, sp.csr_matrix(form.K), form.f, None
        self.product = threaded(self.K)  # K @ x for CG, by rows in threads when K is large
        self.prescribed = form.lower == form.upper
        self.bounded = form.bound_index >= 0
        self.index = np.where(self.bounded, form.bound_index, 0)
        self.coef = form.bound_coef

    def pin(self, active: np.ndarray, d: np.ndarray, x: np.ndarray) -> np.ndarray:
        """Set the pinned values in ``x``; the free mask."""
        on = active & self.bounded
        x[self.prescribed] = 0.0
        x[self.index[on]] = d[on] / self.coef[on]
        free = ~self.prescribed
        free[self.index[on]] = False
        return free

    def reactions(self, x: np.ndarray, active: np.ndarray) -> np.ndarray:
        """Contact forces: ``(f − K x)_j / aᵢ`` on the active rows, zero elsewhere."""
        on = active & self.bounded
        lam = np.zeros(active.size)
        rows = self.index[on]
        lam[on] = (self.f[rows] - self.K[rows] @ x) / self.coef[on]
        return lam

    def violation(self, x: np.ndarray, d: np.ndarray) -> np.ndarray:
        """``aᵢ v_j − dᵢ`` (``Nu − d``) of every row; a row bounding nothing: ``−dᵢ``."""
        return np.where(self.bounded, self.coef * x[self.index], 0.0) - d

    def build(self, active: np.ndarray, choice: str) -> None:
        """The one hierarchy: K with the prescribed dofs and ``active``'s dofs pinned."""
        pinned = self.prescribed.copy()
        pinned[self.index[active & self.bounded]] = True
        self.hierarchy = _hierarchy(choice, pinned_matrix(self.K, pinned),
                                    self.form.rigid_modes(), self.form.block)


class PinnedCG:
    """The certificate's K⁻¹ with some contact dofs pinned, by this method's multigrid.

    Has the interface of :class:`~signorini.numerics.factor.PinnedFactor`:
    ``matrix`` (the problem's K), ``fixed`` (free-dof indices pinned: the
    active rows' dofs when each row bounds one dof, else none) and
    ``solve(rhs)``: u with ``u[fixed] = rhs[fixed]`` and ``(K u)[free] = rhs[free]``, to the
    relative residual :data:`CERTIFICATE_RTOL` (``exact`` is False: the forward error takes
    one Newton step with it, :mod:`signorini.certification.forward_error`).
    """

    exact = False

    def __init__(self, problem: ContactProblem, system: PinnedSystem, active: np.ndarray):
        self.matrix, self.system, self.problem = problem.K, system, problem
        dofs = selection_dofs(problem.N)
        self.fixed = dofs[active] if dofs is not None else np.zeros(0, dtype=int)
        self.n = problem.n
        self.iterations = 0

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        rhs = np.asarray(rhs, dtype=float)
        if rhs.ndim == 2:
            return np.column_stack([self.solve(column) for column in rhs.T])
        system, form = self.system, self.system.form
        full = np.zeros(form.T.shape[0])
        full[form.free_dofs] = rhs
        f = form.T.T @ full
        x = np.zeros(form.n)
        pinned = system.prescribed.copy()
        if self.fixed.size:  # each row bounds one dof: T is the identity there
            targets = form.free_dofs[self.fixed]
            x[targets], pinned[targets] = full[targets], True
        f[pinned] = 0.0
        target = CERTIFICATE_RTOL * max(float(np.linalg.norm(f)), 1e-300)
        result = pinned_cg(system.product, f, x, ~pinned, system.hierarchy.apply,
                           lambda r2, rinf, r0: r2 <= target, CG_MAX_ITER)
        self.iterations += result.iterations
        return form.displacement(x)


def _initial_active(problem: ContactProblem, opts: dict[str, Any]) -> tuple[np.ndarray, str]:
    """The first active set and where it came from."""
    if opts["active0"] is not None:
        active = np.asarray(opts["active0"], dtype=bool)
        if active.shape != (problem.m,):
            raise InputError(f"method 'pdas-amg': option active0 must be {problem.m} booleans")
        return active, "given"
    warm = opts["warm_start"]
    if warm is not None and warm.lam is not None:
        return warm.lam > 0, "the warm start"
    coarse = opts["coarse"]
    if coarse is None:
        return np.zeros(problem.m, dtype=bool), "none (no prediction)"
    if coarse.pending:
        raise InputError("method 'pdas-amg': option coarse must be a problem at its load (its "
                         "target is not matched yet: signorini.load_control.match(coarse).problem)")
    solution = pdas.solve(coarse) if coarse.n < DIRECT_BELOW else solve(coarse,
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


def solve(problem: ContactProblem, *, tol: float | None = None, max_iter: int | None = None,
          **options: Any) -> ContactSolution:
    """PDAS with each pinned system solved by CG + algebraic multigrid (see module doc)."""
    opts = take_options("pdas-amg", options, DEFAULTS)
    if opts["amg"] not in AMG_CHOICES:
        raise InputError(f"method 'pdas-amg': option amg={opts['amg']!r} is not one of "
                         f"{', '.join(AMG_CHOICES)}")
    c = positive_number("pdas-amg", "c", opts["c"])
    tol, max_iter = resolved("pdas-amg", "active set", tol, max_iter)
    start = time.perf_counter()
    if problem.pending and border_factor(problem) is None:
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
    solution = ContactSolution(
        method="pdas-amg", u=u, lam=lam, status=status,
        message=(f"{message}; first active set from {source}; one {hierarchy.backend} hierarchy "
                 f"({hierarchy.setup_s:.2f} s), {cg_iterations} CG iterations"),
        iterations=step, build_time=build_time, solve_time=time.perf_counter() - start - build_time,
        history=history, extras=extras, factor=PinnedCG(unknowns.at_push(problem), system, active))
    return solution


METHODS = (
    Method(name="pdas-amg", function=solve, family="active set", exact=True,
           summary="PDAS with CG + algebraic multigrid (one hierarchy), no factorisation: large 3D",
           requires=("pyamg",), extra="", options=tuple(DEFAULTS),
           matches_load=lambda problem: border_factor(problem) is not None,
           prediction="active set", bound_rows=True, factor_free_from=0),
)
