"""Sparse linear algebra: factorise once, solve many (the active-set systems built on it are
:mod:`signorini.numerics.active_set`'s).

Backends for the SPD stiffness (one interface, ``factorize(K).solve(b)``):

- ``superlu``: SciPy's SuperLU in symmetric mode; always there.
- ``cholmod``: CHOLMOD's supernodal Cholesky through scikit-sparse (optional).
- ``pardiso``: MKL PARDISO through pypardiso (optional).

``auto`` (the default) takes the first installed of pardiso, cholmod, superlu
(leaving PARDISO, 0.2 s to import, the small matrices where it does not pay:
:data:`PARDISO_OVER_CHOLMOD_FROM`); the environment variable ``SIGNORINI_FACTOR`` overrides it.
docs/speed.md (§1) compares the backends' times and holds the measurements behind the thresholds.

Every factorisation knows the matrix it factorised (``matrix``) and the dofs it
pinned (``fixed``; none for a plain one), so that the certificate can reuse a
method's factorisation of the same K.

Work as data: each factorisation and back-solve (and, elsewhere in the numerics, each multigrid
hierarchy, CG iteration and load-control step) is counted (:func:`count`) into every
:class:`Work` record open in the current context, which a stage opens with :func:`counting`;
:func:`timed` adds a stage's wall time to ``solution.seconds``.
The open records live in a :class:`contextvars.ContextVar` (per thread and per task): two
solves side by side never see each other's work, and outside any ``counting`` block nothing is
kept. Tests count work instead of timing it.
"""

from __future__ import annotations

import importlib.util
import logging
import os
import sys
import time
from contextlib import contextmanager
from contextvars import ContextVar
from dataclasses import dataclass
from typing import Iterator

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from signorini.errors import BackendNotInstalled, InputError, install_hint

log = logging.getLogger(__name__)


@dataclass
class Work:
    """The work of one stage: every count starts at zero."""

    factorisations: int = 0
    back_solves: int = 0
    hierarchies: int = 0
    cg_iterations: int = 0
    load_steps: int = 0

    def listed(self, steps: int | None = None) -> dict[str, int]:
        """The stage as ``solution.work`` lists it: its ``steps`` (given, else load control's
        active-set steps when there were any), factorisations, back-solves, CG iterations and
        hierarchies, the zero counts left out."""
        counts = {"factorisations": self.factorisations, "back_solves": self.back_solves,
                  "cg_iterations": self.cg_iterations, "hierarchies": self.hierarchies}
        listed = {key: value for key, value in counts.items() if value}
        if steps is None and not self.load_steps:
            return listed
        return {"steps": self.load_steps if steps is None else steps, **listed}


_OPEN: ContextVar[tuple[Work, ...]] = ContextVar("signorini_work", default=())


@contextmanager
def counting() -> Iterator[Work]:
    """A new :class:`Work` record that counts what the block does (and its inner stages)."""
    work = Work()
    token = _OPEN.set(_OPEN.get() + (work,))
    try:
        yield work
    finally:
        _OPEN.reset(token)


def count(kind: str, amount: int = 1) -> None:
    """Add ``amount`` of ``kind`` (a field of :class:`Work`) to every record open here."""
    for work in _OPEN.get():
        setattr(work, kind, getattr(work, kind) + amount)


def count_solves(b: np.ndarray) -> np.ndarray:
    """``b`` as floats, its right-hand sides (one, or its columns) counted as back-solves."""
    b = np.asarray(b, dtype=float)
    count("back_solves", 1 if b.ndim == 1 else b.shape[1])
    return b


@contextmanager
def timed(seconds: dict[str, float], stage: str) -> Iterator[None]:
    """Add the wall time of the block to ``seconds[stage]`` (seconds, :func:`time.perf_counter`)."""
    start = time.perf_counter()
    try:
        yield
    finally:
        seconds[stage] = seconds.get(stage, 0.0) + time.perf_counter() - start


BACKENDS = ("pardiso", "cholmod", "superlu")
_MODULES = {"cholmod": "sksparse", "pardiso": "pypardiso", "superlu": "scipy"}
#: the package extra that installs each backend's module (SciPy's SuperLU comes with the package)
EXTRAS = {"cholmod": "fast", "pardiso": "pardiso"}

NO_DOFS = np.zeros(0, dtype=int)


def available_backends() -> list[str]:
    """The factorisation backends installed here, fastest first."""
    return [b for b in BACKENDS if importlib.util.find_spec(_MODULES[b]) is not None]


#: ``auto`` leaves matrices below this many dofs to CHOLMOD or SuperLU: time does not matter
#: there, and on the tutorials' smallest problem PARDISO's solve missed the 1e-12 residual the
#: other two met (docs/speed.md, §1)
PARDISO_FROM = 5_000
#: with CHOLMOD installed, ``auto`` leaves it the matrices below this many dofs: there a whole
#: solve is faster with CHOLMOD, in less memory, than with PARDISO and the cost of importing it
#: (chosen from measurements, docs/speed.md §1)
PARDISO_OVER_CHOLMOD_FROM = 50_000
#: ... counted in nonzeros of K when they are known (a 2D K has about 14 per row, a 3D one 35-80):
#: a 3D K fills in sooner, and PARDISO pays there from far fewer dofs than in 2D (chosen from
#: measurements, docs/speed.md §1)
PARDISO_OVER_CHOLMOD_FROM_NNZ = 750_000


def resolve_backend(backend: str | None = None, n: int | None = None,
                    nnz: int | None = None) -> str:
    """Pick the backend: an explicit name, ``SIGNORINI_FACTOR``, or the first installed; PARDISO
    only from :data:`PARDISO_OVER_CHOLMOD_FROM` dofs (:data:`PARDISO_OVER_CHOLMOD_FROM_NNZ`
    nonzeros of K when given) with CHOLMOD installed, from :data:`PARDISO_FROM` without."""
    name = backend or os.environ.get("SIGNORINI_FACTOR") or "auto"
    if name == "auto":
        installed = available_backends()
        if "cholmod" in installed and nnz is not None:
            small = nnz < PARDISO_OVER_CHOLMOD_FROM_NNZ
        else:
            start = PARDISO_OVER_CHOLMOD_FROM if "cholmod" in installed else PARDISO_FROM
            small = n is not None and n < start
        if small and len(installed) > 1:
            installed = [b for b in installed if b != "pardiso"]
        return installed[0]
    if name not in BACKENDS:  # named as it was given: the argument or the environment variable
        raise InputError(f"{'backend' if backend else 'SIGNORINI_FACTOR'}={name!r} names no "
                         f"factorisation backend: choose auto, {', '.join(BACKENDS)}")
    if name not in available_backends():
        hint = install_hint(EXTRAS.get(name, ""), [_MODULES[name]])
        raise BackendNotInstalled(f"factorisation backend {name!r} needs the module "
                                  f"{_MODULES[name]!r}: {hint}")
    return name


def _factorising(backend: str, K: sp.spmatrix, counted: bool = True) -> None:
    """Say a factorisation of K starts (a progress line) and count it unless ``counted`` is False."""
    log.info("factorising K: %s dofs, %s nonzeros (%s)", f"{K.shape[0]:,}", f"{K.nnz:,}", backend)
    count("factorisations", int(counted))


class Factor:
    """``K⁻¹`` applied to a vector or an (n, k) block of right-hand sides.

    ``matrix`` is K as given (kept by reference: a certificate checks that a factorisation it
    is offered is one of its problem's K); ``fixed`` the pinned dofs, none here (see
    :class:`PinnedFactor`, which solves alike).
    """

    backend = "superlu"
    fixed = NO_DOFS

    def __init__(self, K: sp.spmatrix):
        self.matrix, self.shape = K, K.shape
        _factorising(self.backend, K)
        self._lu = spla.splu(sp.csc_matrix(K), permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                             options={"SymmetricMode": True})

    def solve(self, b: np.ndarray) -> np.ndarray:
        return self._lu.solve(count_solves(b))


#: from this many dofs CHOLMOD orders by nested dissection (METIS) instead of AMD: below it AMD
#: is faster, above it nested dissection's smaller factor wins (chosen from measurements,
#: docs/speed.md §1)
NESTED_DISSECTION_FROM = 100_000


#: from this many dofs CHOLMOD factorises by supernodes; below, simplicially: faster there
#: (measured on the Hertz cylinder's K, docs/performance.md)
SUPERNODAL_FROM = 40_000


#: a pivot of the simplicial LDLᵀ at most this fraction of its row's diagonal entry of K is
#: round-off: the pivot a singular K leaves (a rigid mode held by nothing gave 1.1e-16 of it)
PIVOT_ROUNDOFF = 1e-13


def cholmod_analysis(K: sp.csc_matrix):
    """CHOLMOD's symbolic analysis (ordering, supernodes or not) of the pattern of K."""
    from sksparse.cholmod import analyze  # optional backend: imported when CHOLMOD is used

    mode = "supernodal" if K.shape[0] >= SUPERNODAL_FROM else "simplicial"
    ordering = "nesdis" if K.shape[0] >= NESTED_DISSECTION_FROM else "amd"
    return analyze(K, mode=mode, ordering_method=ordering)


def cholmod_numeric(symbolic, K: sp.csc_matrix):
    """The numeric factorisation of K on a symbolic analysis of its pattern."""
    from sksparse.cholmod import CholmodNotPositiveDefiniteError  # as above

    try:
        factor = symbolic.cholesky(K)
    except CholmodNotPositiveDefiniteError as exc:
        raise np.linalg.LinAlgError(f"K is not positive definite ({exc})") from exc
    # the simplicial factor is LDLᵀ, which an indefinite or singular K passes: each pivot is
    # judged against its own row's diagonal entry (the materials' contrast divides out)
    if not np.all(factor.D() > PIVOT_ROUNDOFF * np.abs(K.diagonal()[factor.P()])):
        raise np.linalg.LinAlgError("K is not positive definite (a pivot of its LDLᵀ is not above "
                                    "round-off: K is singular or indefinite)")
    return factor


class CholmodFactor(Factor):
    """CHOLMOD's supernodal ``K = LLᵀ`` (scikit-sparse), on a given symbolic analysis or its own."""

    backend = "cholmod"

    def __init__(self, K: sp.spmatrix, symbolic=None):
        self.matrix, self.shape = K, K.shape
        K = sp.csc_matrix(K)
        _factorising(self.backend, K)
        self._factor = cholmod_numeric(cholmod_analysis(K) if symbolic is None else symbolic, K)

    def solve(self, b: np.ndarray) -> np.ndarray:
        return self._factor(count_solves(b))


#: PARDISO's settings (iparm, counted from 1 as its manual does): 1 — these, not its defaults;
#: 2 — METIS's nested dissection (its default ordering); 8 — no iterative refinement. By default it
#: refines every solve twice (a product with K and a back-solve each), which costs two to three
#: times the solve and leaves the residual of K u = f at round-off either way (docs/speed.md, §4):
#: a Cholesky factor needs no refinement, and every certificate still checks the answer.
PARDISO_IPARM = {1: 1, 2: 2, 8: 0}
#: the environment variable that caps a factorisation's memory, in GB (default: MemAvailable)
FACTOR_MEMORY_VARIABLE = "SIGNORINI_MAX_FACTOR_GB"


class FactorTooLarge(InputError):
    """A factorisation whose symbolic analysis says it would not fit in memory (refused before
    its numeric phase)."""


def gigabytes_from(variable: str) -> float | None:
    """Bytes from the environment variable ``variable`` given in GB (None when it is not set);
    anything but a positive number is an input error naming it."""
    text = os.environ.get(variable)
    if text is None:
        return None
    try:
        limit = float(text) * 1e9
    except ValueError:
        limit = float("nan")
    if not (limit > 0 and np.isfinite(limit)):
        raise InputError(f"{variable}={text!r} must be a positive number of GB, e.g. {variable}=16")
    return limit


def factor_memory_limit() -> float:
    """Bytes a factorisation may take: ``SIGNORINI_MAX_FACTOR_GB``, else MemAvailable (inf when
    the system does not say)."""
    limit = gigabytes_from(FACTOR_MEMORY_VARIABLE)
    if limit is not None:
        return limit
    try:
        with open("/proc/meminfo", encoding="ascii") as meminfo:
            for line in meminfo:
                if line.startswith("MemAvailable:"):
                    return float(line.split()[1]) * 1024.0
    except OSError:
        pass
    return float("inf")


def pardiso_factor_bytes(iparm: np.ndarray) -> float:
    """The memory PARDISO's analysis says its numeric phase needs: the larger of the analysis's
    peak (iparm 15) and the permanent memory plus the factor's (iparm 16 + 17), in bytes."""
    return 1024.0 * max(float(iparm[14]), float(iparm[15]) + float(iparm[16]))


def _pypardiso():
    """pypardiso, told where a pip-installed MKL is (``<prefix>/lib``) through its documented
    ``PYPARDISO_MKL_RT``: else it searches the whole environment on import and per solver."""
    if "PYPARDISO_MKL_RT" not in os.environ:
        import glob
        import site

        found = [path for lib in (sys.prefix, site.USER_BASE)
                 for path in sorted(glob.glob(f"{lib}/lib/libmkl_rt.*"), key=len)]
        if found:
            os.environ["PYPARDISO_MKL_RT"] = found[0]
    import pypardiso  # MKL: imported only for a matrix PARDISO factorises

    return pypardiso


def upper_csr(K: sp.spmatrix) -> sp.csr_matrix:
    """The upper triangle of K in CSR (PARDISO's input), cut from a CSR K's own arrays."""
    if K.format != "csr":
        return sp.triu(K, format="csr")
    K = K if K.has_sorted_indices else K.sorted_indices()
    row = np.repeat(np.arange(K.shape[0]), np.diff(K.indptr))
    keep = K.indices >= row
    indptr = np.concatenate([[0], np.cumsum(np.bincount(row[keep], minlength=K.shape[0]))])
    return sp.csr_matrix((K.data[keep], K.indices[keep], indptr.astype(K.indptr.dtype)),
                         shape=K.shape)


class PardisoFactor(Factor):
    """MKL PARDISO's symmetric positive definite solver (pypardiso).

    PARDISO reads the upper triangle in CSR: ``upper`` gives it ready made
    (:meth:`Pinning.matrix` builds it without forming the whole matrix), else
    it is cut from K.
    """

    backend = "pardiso"

    def __init__(self, K: sp.spmatrix, upper: sp.csr_matrix | None = None):
        pypardiso = _pypardiso()
        self.matrix, self.shape = K, K.shape
        self._upper = upper_csr(K) if upper is None else upper
        self._solver = solver = pypardiso.PyPardisoSolver(mtype=2)
        os.environ.setdefault("PYPARDISO_MKL_RT", solver.libmkl._name)  # where it found MKL
        for index, value in PARDISO_IPARM.items():
            solver.set_iparm(index, value)
        # pypardiso's factorize() runs PARDISO's phases 11 (analysis) and 22 (numeric) as one;
        # they are run apart here (its own _check_A and _call_pardiso) so that the numeric
        # phase only starts when it fits
        A, rhs = self._upper, np.zeros((K.shape[0], 1))
        solver._check_A(A)
        _factorising(self.backend, K, counted=False)  # the analysis takes about as long
        solver.set_phase(11)
        solver._call_pardiso(A, rhs)
        self.memory = pardiso_factor_bytes(solver.iparm)
        limit = factor_memory_limit()
        if self.memory > limit:
            solver.free_memory(everything=True)
            raise FactorTooLarge(
                f"factorising K ({K.shape[0]:,} dofs) needs about {self.memory / 1e9:,.1f} GB "
                f"(PARDISO's analysis), more than the {limit / 1e9:,.2f} GB available "
                f"({FACTOR_MEMORY_VARIABLE} or MemAvailable): use a method without a "
                "factorisation (--method pdas-amg, or petsc-vi --opt ksp=gamg), a coarser mesh, or "
                "for a 3D scene a push (--set delta=...) instead of a target load")
        count("factorisations")
        solver.set_phase(22)
        solver._call_pardiso(A, rhs)

    def solve(self, b: np.ndarray) -> np.ndarray:
        # PARDISO's solve phase on the factorisation made above (pypardiso's solve() hashes K)
        self._solver.set_phase(33)
        return self._solver._call_pardiso(self._upper, np.asfortranarray(count_solves(b)))

    def __del__(self) -> None:
        # MKL keeps a factorisation until told to drop it: without this every PARDISO factor
        # leaked its memory (docs/speed.md, §1)
        solver = getattr(self, "_solver", None)
        if solver is not None:
            try:
                solver.free_memory(everything=True)
            except Exception:  # interpreter shutdown: MKL may already be gone
                pass


_CLASSES = {"superlu": Factor, "cholmod": CholmodFactor, "pardiso": PardisoFactor}


def factorize(K: sp.spmatrix, backend: str | None = None) -> Factor:
    """Factorise the SPD matrix ``K`` once for repeated solves."""
    return _CLASSES[resolve_backend(backend, K.shape[0], K.nnz)](K)


__all__ = ["available_backends", "resolve_backend", "Factor", "cholmod_analysis",
           "cholmod_numeric", "CholmodFactor", "FactorTooLarge", "gigabytes_from",
           "factor_memory_limit", "pardiso_factor_bytes", "upper_csr", "PardisoFactor",
           "factorize", "BACKENDS", "EXTRAS", "PARDISO_OVER_CHOLMOD_FROM", "FACTOR_MEMORY_VARIABLE",
           "Work", "count", "count_solves", "counting", "timed"]
