"""One piece of a PETSc solve, in this process or on an MPI rank: PETSc's bound-constrained
solver (SNES-VI or TAO) on a block of rows, its Krylov solver (MUMPS, or CG with a fresh GAMG
hierarchy per operator), and the stationarity test it stops by.

:func:`pieces` splits a bound form into the jobs; :func:`solve_piece` runs one (the cluster
calls it by name); :mod:`signorini.solvers.petsc_` holds the methods around them.
"""

from __future__ import annotations

import shlex
import time
from typing import Any

import numpy as np

from signorini.solvers.bounds import BoundForm

__all__ = ["PREFIX", "ROUND_OFF_FLOOR", "SAFETY", "SAFETY_RELATIVE", "load_petsc", "near_null_space",
           "pieces", "reason_text", "solve_piece", "unless_given"]

#: how far below the requested tolerance PETSc's own stopping test is set
SAFETY = 1e-5
#: SNES-VI's stationarity target relative to the requested tolerance
SAFETY_RELATIVE = 0.1
PREFIX = "signorini_"
#: the stopping test never asks for less than this relative residual: round-off sits there, and
#: a test just below it can run a solver to its iteration limit (docs/petsc.md)
ROUND_OFF_FLOOR = 1e-12


def load_petsc():
    """petsc4py's PETSc module, initialised once (MPI first, through mpi4py when launched)."""
    import petsc4py  # optional backend (0.3 s, and MPI): only when a petsc method runs

    if not getattr(petsc4py, "_signorini_ready", False):
        try:
            import mpi4py.MPI  # noqa: F401  (MPI initialised by mpi4py, so both share the world)
        except ImportError:
            pass
        # PETSc's signal handlers would turn a closed pipe (`| head`) into MPI_Abort
        petsc4py.init(["signorini", "-no_signal_handler"])
        petsc4py._signorini_ready = True
    from petsc4py import PETSc

    return PETSc


def _split_nodes(count: int, ranks: int) -> np.ndarray:
    """Node offsets of each rank's contiguous block (as even as whole nodes allow)."""
    sizes = np.full(ranks, count // ranks)
    sizes[: count % ranks] += 1
    return np.concatenate([[0], np.cumsum(sizes)])


def pieces(form: BoundForm, ranks: int, x0: np.ndarray, gamg: bool) -> list[dict[str, Any]]:
    """Each rank's rows of the bound form: CSR block, vectors, rigid modes (for GAMG)."""
    offsets = _split_nodes(form.n // form.block, ranks) * form.block
    modes = form.rigid_modes() if gamg else None
    K = form.K
    out = []
    for first, last in zip(offsets[:-1], offsets[1:]):
        lo, hi = K.indptr[first], K.indptr[last]
        out.append({
            "first": int(first), "rows": int(last - first),
            "indptr": K.indptr[first:last + 1] - lo, "indices": K.indices[lo:hi],
            "data": K.data[lo:hi], "f": form.f[first:last], "lower": form.lower[first:last],
            "upper": form.upper[first:last], "x0": x0[first:last],
            "modes": None if modes is None else modes[first:last]})
    return out


def _vec(PETSc, A, values: np.ndarray):
    """A vector in ``A``'s row layout holding this rank's ``values`` (±inf clipped to PETSc's)."""
    vec = A.createVecLeft()
    vec.setArray(np.clip(values, -PETSc.INFINITY, PETSc.INFINITY))
    return vec


def unless_given(PETSc, prefix: str, values: dict[str, str]) -> None:
    """Set the PETSc options ``values`` under ``prefix``, each unless the user already gave it."""
    options = PETSc.Options(prefix)
    for name, value in values.items():
        if not options.hasName(name):
            options.setValue(name, value)


def near_null_space(PETSc, A, modes: np.ndarray):
    """Give ``A`` the columns of ``modes`` (this rank's rows) as near-null space for GAMG."""
    vectors = [_vec(PETSc, A, column) for column in modes.T]
    A.setNearNullSpace(PETSc.NullSpace().create(vectors=vectors, comm=A.getComm()))


class FreshMultigrid:
    """A PETSc python PC: a new GAMG hierarchy for every operator it is given.

    SNES-VI and TAO hand the linear solver the matrix of the free variables,
    whose size changes as the active set does; PETSc 3.18's GAMG fails when
    an existing hierarchy meets a new size ("Cannot change local size of
    Amat after use"), even after a reset. The rigid-body modes restricted to
    the free variables go with each new matrix when the solver says which
    variables are free (SNES-VI's inactive set).
    """

    def __init__(self, PETSc, n: int, modes: np.ndarray | None, first: int, free_set=None):
        self.PETSc, self.n, self.modes, self.first, self.free_set = PETSc, n, modes, first, free_set
        self.inner = None
        self.setups, self.setup_s, self.apply_s = 0, 0.0, 0.0

    def _free_rows(self, P) -> np.ndarray | None:
        """This rank's rows of ``P`` as local indices of the full problem (None when unknown)."""
        if P.getSize()[0] == self.n:
            return np.arange(P.getLocalSize()[0])
        if self.free_set is not None:
            rows = np.asarray(self.free_set()) - self.first
            if rows.size == P.getLocalSize()[0]:
                return rows
        return None

    def setUp(self, pc) -> None:
        start = time.perf_counter()
        A, P = pc.getOperators()
        rows = None if self.modes is None else self._free_rows(P)
        if rows is not None:
            near_null_space(self.PETSc, P, self.modes[rows])
        if self.inner is not None:
            self.inner.destroy()
        self.inner = self.PETSc.PC().create(pc.getComm())
        self.inner.setType("gamg")
        self.inner.setOperators(A, P)
        self.inner.setOptionsPrefix(PREFIX + "mg_")
        self.inner.setFromOptions()
        self.inner.setUp()
        self.setups += 1
        self.setup_s += time.perf_counter() - start

    def apply(self, pc, x, y) -> None:
        start = time.perf_counter()
        self.inner.apply(x, y)
        self.apply_s += time.perf_counter() - start


def _configure_ksp(PETSc, ksp, choice: str, tol: float, multigrid=None) -> None:
    pc = ksp.getPC()
    if choice == "mumps":
        ksp.setType("preonly")
        pc.setType("lu")
        pc.setFactorSolverType("mumps")
    else:
        ksp.setType("cg")
        pc.setType("python")
        pc.setPythonContext(multigrid)
        ksp.setTolerances(rtol=min(1e-10, tol * SAFETY), atol=0.0, max_it=5000)


def _set_options(PETSc, text: str) -> None:
    opts = PETSc.Options(PREFIX)
    words = shlex.split(text)
    for i, word in enumerate(words):
        if not word.startswith("-"):
            continue
        value = words[i + 1] if i + 1 < len(words) and not words[i + 1].startswith("-") else None
        opts.setValue(word[1:], value if value is not None else "")


def _stationarity_test(PETSc, lower, upper, b, job: dict[str, Any]):
    """SNES stops when the residual off the bounds is small against the reactions on them.

    That is the package's own stationarity measure (``‖Ku − f + Nᵀλ‖∞ / ‖Nᵀλ‖∞``):
    an absolute test against ‖f‖ either stopped short on big 3D models (the
    lifted loads dwarf the contact forces) or never fired on small curved ones
    (round-off above it). Target ``SAFETY_RELATIVE · tol``, floored at round-off.
    """
    from mpi4py import MPI  # as above

    reason = PETSc.SNES.ConvergedReason
    lo, hi = lower.getArray(readonly=True), upper.getArray(readonly=True)
    load = MPI.COMM_WORLD.allreduce(float(np.abs(b.getArray(readonly=True)).max(initial=0.0)),
                                    op=MPI.MAX)
    target = max(job["tol"] * SAFETY_RELATIVE, 1e3 * np.finfo(float).eps)

    def test(snes, iteration, norms):
        fnorm = norms[2]
        if not np.isfinite(fnorm):
            return reason.DIVERGED_FNORM_NAN
        if iteration > 0:
            x = snes.getSolution().getArray(readonly=True)
            F = snes.getFunction()[0].getArray(readonly=True)
            width = 1e-12 * np.maximum(1.0, np.abs(x))
            at_lower, at_upper = x <= lo + width, x >= hi - width
            fixed = at_lower & at_upper  # prescribed dofs: any reaction is fine
            at_lower, at_upper = at_lower & ~fixed, at_upper & ~fixed
            free = ~(at_lower | at_upper | fixed)
            # off the bounds F must vanish; on an upper bound F ≤ 0, on a lower one F ≥ 0
            violation = max(float(np.abs(F[free]).max(initial=0.0)),
                            float(np.maximum(F[at_upper], 0.0).max(initial=0.0)),
                            float(np.maximum(-F[at_lower], 0.0).max(initial=0.0)))
            reaction = float(np.abs(F[at_lower | at_upper]).max(initial=0.0))
            both = np.empty(2)
            MPI.COMM_WORLD.Allreduce(np.array([violation, reaction]), both, op=MPI.MAX)
            violation, reaction = both
            if violation <= target * max(reaction, 1e-5 * load):
                return reason.CONVERGED_FNORM_ABS
        if iteration >= job["max_iter"]:
            return reason.DIVERGED_MAX_IT
        return reason.ITERATING

    return test


def solve_piece(job: dict[str, Any], piece: dict[str, Any]) -> dict[str, Any]:
    """Every rank: build its block of the parallel problem and solve it (collectively)."""
    PETSc = load_petsc()
    comm = PETSc.COMM_WORLD
    start = time.perf_counter()
    n, block, rows = job["n"], job["block"], piece["rows"]
    A = PETSc.Mat().createAIJ(size=((rows, n), (rows, n)), bsize=block, comm=comm,
                              csr=(piece["indptr"].astype(PETSc.IntType),
                                   piece["indices"].astype(PETSc.IntType), piece["data"]))
    A.assemble()
    A.setOption(PETSc.Mat.Option.SYMMETRIC, True)
    if piece["modes"] is not None:
        near_null_space(PETSc, A, piece["modes"])
    b, lower, upper = (_vec(PETSc, A, piece[key]) for key in ("f", "lower", "upper"))
    x = _vec(PETSc, A, piece["x0"])
    _set_options(PETSc, job["petsc_options"])
    setup_s = time.perf_counter() - start
    kind, petsc_type = job["kind"]
    if kind == "snes":
        solver = PETSc.SNES().create(comm)
        solver.setType(petsc_type)
        residual = A.createVecLeft()

        def function(snes, v, out):
            A.mult(v, out)
            out.axpy(-1.0, b)

        solver.setFunction(function, residual)
        solver.setConvergenceTest(_stationarity_test(PETSc, lower, upper, b, job))
        solver.setJacobian(lambda *args: None, A, A)
        solver.setVariableBounds(lower, upper)
        unless_given(PETSc, PREFIX, {"snes_linesearch_type": "basic"})
        solver.setTolerances(max_it=job["max_iter"])  # the stopping test is the one above
    else:
        solver = PETSc.TAO().create(comm)
        solver.setType(petsc_type)
        gradient = A.createVecLeft()

        def objective_gradient(tao, v, g):
            A.mult(v, g)
            value = 0.5 * v.dot(g) - b.dot(v)
            g.axpy(-1.0, b)
            return value

        solver.setObjectiveGradient(objective_gradient, gradient)
        solver.setHessian(lambda *args: None, A, A)
        solver.setVariableBounds((lower, upper))
        gatol = max(job["tol"] * SAFETY, ROUND_OFF_FLOOR) * max(job["f_norm"], 1e-300)
        solver.setTolerances(gatol=gatol, grtol=0.0, gttol=0.0)
        solver.setMaximumIterations(job["max_iter"])
    multigrid = None
    if job["ksp"] == "gamg":
        # plain aggregation: with six rigid modes, smoothing the prolongator makes each set-up
        # many times dearer for fewer CG iterations (docs/petsc.md)
        unless_given(PETSc, PREFIX + "mg_", {"pc_gamg_agg_nsmooths": "0"})
        if kind == "snes":
            # Eisenstat-Walker: loose CG solves while the active set still moves, a fraction of
            # the CG iterations for the same final residuals (docs/petsc.md)
            unless_given(PETSc, PREFIX, {"snes_ksp_ew": ""})
        free_set = (lambda: solver.getVIInactiveSet().getIndices()) if kind == "snes" else None
        multigrid = FreshMultigrid(PETSc, n, piece["modes"], piece["first"], free_set)
    _configure_ksp(PETSc, solver.getKSP(), job["ksp"], job["tol"], multigrid)
    solver.setOptionsPrefix(PREFIX)
    solver.setFromOptions()
    solve_start = time.perf_counter()
    solver.solve(None, x) if kind == "snes" else solver.solve(x)
    result = {
        "x": x.getArray().copy(), "reason": int(solver.getConvergedReason()),
        "iterations": int(solver.getIterationNumber()),
        "setup_s": setup_s, "solve_s": time.perf_counter() - solve_start,
        "local_rows": rows, "local_nnz": int(piece["data"].size)}
    if kind == "snes":
        result["linear_iterations"] = int(solver.getLinearSolveIterations())
    if multigrid is not None:
        result.update(multigrid_setups=multigrid.setups, multigrid_setup_s=multigrid.setup_s,
                      multigrid_apply_s=multigrid.apply_s)
    solver.destroy()
    A.destroy()
    return result


def reason_text(kind: str, reason: int) -> str:
    PETSc = load_petsc()
    table = PETSc.SNES.ConvergedReason if kind == "snes" else PETSc.TAO.Reason
    names = {value: name for name, value in vars(table).items()
             if isinstance(value, int) and not name.startswith("_")}
    return names.get(reason, str(reason))
