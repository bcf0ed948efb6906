"""The linear algebra of ``pdas-amg``: K with the active dofs pinned, its multigrid and CG.

:class:`PinnedSystem` holds the bound form's matrix and a hierarchy for it (PETSc's GAMG,
:class:`GamgHierarchy`, or pyamg's smoothed aggregation); :class:`PinnedCG` solves with a
final active set pinned, the interface of a factorisation for the certificate. A pending
target load is one more unknown of the CG systems, so that no factorisation is made
(:class:`LoadBorder`); :class:`Unknowns` is what CG solves for at each active-set step, with
the border or without: the Newton loop of :mod:`signorini.solvers.amg` reads the same either way.
"""

from __future__ import annotations

import importlib.util
import time
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from signorini.numerics.active_set import selection_dofs
from signorini.numerics.multigrid import (Bordered, PyamgHierarchy, pinned_cg, pinned_matrix,
                                          threaded)
from signorini.numerics.factor import count
from signorini.problem.contact import ContactProblem
from signorini.solvers import petsc_piece
from signorini.solvers.bounds import BoundForm

__all__ = ["CERTIFICATE_RTOL", "CG_MAX_ITER", "GAMG_OPTIONS", "GamgHierarchy", "LoadBorder",
           "PinnedCG", "PinnedSystem", "Unknowns", "border_factor", "border_preconditioner",
           "load_border", "rotated"]

#: CG iterations allowed per solve
CG_MAX_ITER = 3000
#: relative residual of the certificate's solve ``e = K̃⁻¹r`` (r: the final stationarity residual).
#: The gap is ``λ̂ᵀ(d − Nu) + ½eᵀKe``: a relative error ε of e in the energy norm moves the
#: quadratic term by about 2ε of itself, so a few digits do, and the forward error's Newton step
#: is good to about 1 %; a tighter solve costs a large part of the method's time at scale, a
#: looser one moves the forward error by several percent (chosen from measurements, docs/amg.md)
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
        PETSc = petsc_piece.load_petsc()
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
            petsc_piece.near_null_space(PETSc, self._A, modes)
        petsc_piece.unless_given(PETSc, "signorini_amg_", {  # see GAMG_OPTIONS
            **GAMG_OPTIONS, **(MUMPS_COARSE_OPTIONS if PETSc.Sys.hasExternalPackage("mumps") else {})})
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

    Has the interface of :class:`~signorini.numerics.active_set.PinnedFactor`:
    ``matrix`` (the problem's K), ``fixed`` (free-dof indices pinned: the
    active rows' dofs when each row bounds one dof, else none) and
    ``solve(rhs)``: u with ``u[fixed] = rhs[fixed]`` and ``(K u)[free] = rhs[free]``, to the
    relative residual :data:`CERTIFICATE_RTOL` (``exact`` is False: the forward error takes
    one Newton step with it, :mod:`signorini.certification.inverse`).
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
        f = rotated(form, rhs)
        x = np.zeros(form.n)
        pinned = system.prescribed.copy()
        if self.fixed.size:  # each row bounds one dof: T is the identity there
            targets = form.free_dofs[self.fixed]
            x[targets], pinned[targets] = rhs[self.fixed], True
        f[pinned] = 0.0
        target = CERTIFICATE_RTOL * max(float(np.linalg.norm(f)), 1e-300)
        result = pinned_cg(system.product, f, x, ~pinned, system.hierarchy.apply,
                           lambda r2, rinf, r0: r2 <= target, CG_MAX_ITER)
        self.iterations += result.iterations
        return form.displacement(x)


# --- a pending target load as one more unknown -----------------------------------------------

@dataclass
class LoadBorder:
    """Load targeting without a factorisation: the push ``s`` as one more unknown.

    The pushed dofs move together, so the load row is parallel to the push's forces,
    ``ℓ = β f₁``, and the target ``ℓ·u + s·o₁ + o₀ = P`` is the last row of the symmetric system
    ``[[K, −f₁], [−f₁ᵀ, −o₁/β]] [u; s] = [f₀; −(P − o₀)/β]``, SPD once the contact holds the
    body (:class:`~signorini.numerics.multigrid.Bordered`), which CG preconditions by block
    elimination (:func:`border_preconditioner`). Arrays are the bound form's (rotated).
    """

    g: np.ndarray  # the push's forces f₁
    k: float  # −o₁/β
    h: float  # −(P − o₀)/β
    f0: np.ndarray  # the load that does not move with the push
    beta: float
    target: float
    push: float  # the nominal push: where CG starts without a better guess


def border_factor(problem: ContactProblem) -> float | None:
    """β of :class:`LoadBorder` for a problem whose target load is pending, or None (nothing
    pending, the pushed dofs do not move together, or the push moves a contact candidate)."""
    pu = problem.model.push
    if not problem.model.pending or problem.model.load_row is None or np.any(pu.d1 != 0):
        return None
    f1, row = pu.f1, problem.model.load_row
    beta = float(row @ f1) / max(float(f1 @ f1), 1e-300)
    if not beta or np.linalg.norm(row - beta * f1) > 1e-9 * np.linalg.norm(row):
        return None
    return beta if -pu.offset1 / beta > 0 else None


def load_border(problem: ContactProblem, form: BoundForm) -> LoadBorder | None:
    """The border of a problem whose target load is pending (see :func:`border_factor`)."""
    beta = border_factor(problem)
    if beta is None:
        return None
    pu = problem.model.push
    fixed = pu.load * pu.f_load if pu.f_load is not None else np.zeros(problem.n)
    return LoadBorder(g=rotated(form, pu.f1), k=-pu.offset1 / beta,
                      h=-(pu.target - pu.load * pu.offset_load) / beta, f0=rotated(form, fixed),
                      beta=beta, target=pu.target, push=pu.scale)


def border_preconditioner(apply, border: LoadBorder):
    """The multigrid ``M ≈ A⁻¹`` extended to the bordered matrix ``[[A, −g], [−gᵀ, k]]``.

    Block elimination with ``w = −M g`` (one V-cycle, once) and the Schur
    complement ``S = k − gᵀ M g``: ``P = Z diag(M, 1/S) Zᵀ``, ``Z = [[I, w], [0, 1]]``,
    symmetric positive definite for any w when S > 0 and the exact inverse
    when M is (what it saves CG is in docs/amg.md). Should S not be clearly positive
    (M too far from A⁻¹), the border's diagonal alone.
    """
    Mg = apply(border.g)
    schur = border.k - float(border.g @ Mg)
    if not schur > 1e-3 * border.k:
        return lambda r: np.append(apply(r[:-1]), r[-1] / border.k)

    def precondition(r: np.ndarray) -> np.ndarray:
        t = (r[-1] + float(Mg @ r[:-1])) / schur
        return np.append(apply(r[:-1]) + Mg * t, t)

    return precondition


def rotated(form: BoundForm, v: np.ndarray) -> np.ndarray:
    """A vector on the problem's free dofs in the bound form's (rotated, full-length) dofs."""
    full = np.zeros(form.T.shape[0])
    full[form.free_dofs] = v
    return form.T.T @ full


class Unknowns:
    """What CG solves for at each active-set step: the bound form's dofs ``x``, and the push
    last when a pending load is bordered (``border``; starting at ``push0``, else the nominal
    push).

    ``system`` is the method's pinned system (its ``form``, ``product`` ``K @ x`` and multigrid
    ``hierarchy``); ``values`` the array CG updates, ``x`` its displacement part.
    """

    def __init__(self, system, border: LoadBorder | None = None, push0: float | None = None):
        self.border, form = border, system.form
        self.values = np.zeros(form.n + (border is not None))
        self.x = self.values[:form.n]
        self.operator, self.rhs = system.product, form.f
        self.precondition = system.hierarchy.apply
        if border is not None:
            self.values[-1] = border.push if push0 is None else float(push0)
            self.operator = Bordered(system.product, border.g, border.k)
            self.rhs = np.append(border.f0, border.h)
            self.precondition = border_preconditioner(system.hierarchy.apply, border)

    @property
    def push(self) -> float | None:
        """The push found with the answer (None without a border)."""
        return None if self.border is None else float(self.values[-1])

    def free(self, free: np.ndarray) -> np.ndarray:
        """CG's free mask: the free dofs, and the push."""
        return free if self.border is None else np.append(free, True)

    def weights(self, force: float) -> np.ndarray | None:
        """The residual's weights: the load row weighed as its relative error times ``force``."""
        if self.border is None:
            return None
        weights = np.ones(self.values.size)
        weights[-1] = abs(self.border.beta) * force / self.border.target
        return weights

    def loaded(self, f: np.ndarray) -> np.ndarray:
        """The bound form's load at the push found (``f`` itself without a border)."""
        return f if self.border is None else self.border.f0 + self.values[-1] * self.border.g

    def at_push(self, problem: ContactProblem) -> ContactProblem:
        """``problem`` at the push found (itself without a border): what the answer solves."""
        return problem if self.border is None else problem.pushed(float(self.values[-1]))
