"""The linear algebra of ``pdas-amg``: K with the active dofs pinned, its multigrid and CG.

:class:`PinnedSystem` holds the bound form's matrix and a hierarchy for it (PETSc's GAMG,
:class:`GamgHierarchy`, or pyamg's smoothed aggregation); :class:`PinnedCG` solves with a
final active set pinned, the interface of a factorisation for the certificate.
"""

from __future__ import annotations

import importlib.util
import time

import numpy as np
import scipy.sparse as sp

from signorini.numerics.active_set import selection_dofs
from signorini.numerics.multigrid import PyamgHierarchy, pinned_cg, pinned_matrix, threaded
from signorini.numerics.work import count
from signorini.problem.contact import ContactProblem
from signorini.solvers import petsc_piece
from signorini.solvers.bounds import BoundForm
from signorini.solvers.load_border import rotated

__all__ = ["CERTIFICATE_RTOL", "CG_MAX_ITER", "GAMG_OPTIONS", "GamgHierarchy", "PinnedCG",
           "PinnedSystem"]

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
