"""The discrete Signorini problem and what a solver returns for it.

The problem is one convex QP::

    minimise   ½ uᵀ K u − fᵀ u        (K sparse SPD, n × n)
    subject to N u ≤ d                (N sparse m × n, one row per contact candidate)

with KKT conditions ``K u − f + Nᵀ λ = 0``, ``N u ≤ d``, ``λ ≥ 0``,
``λᵢ (N u − d)ᵢ = 0``. ``λ`` is the nodal contact force (compressive positive).

A QP given as arrays (:meth:`ContactProblem.from_qp`) is held in the units it
was given (identity :class:`Scales`); a scene's is dimensionless, and its
:class:`Scales` turn it back into physical units.
"""

from __future__ import annotations

import dataclasses
import os
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
import scipy.sparse as sp

from signorini.problem.model import Model, Push, ReferenceData, Watch
from signorini.errors import InputError
from signorini.numerics.arrays import (
    multiplicity_argument,
    points_argument,
    sparse_argument,
    symmetric_argument,
    vector_argument,
)
from signorini.numerics.factor import factorize
from signorini.problem import saved as saved_problem
from signorini.problem.scales import Scales
from signorini.reprs import short_repr


__all__ = ["STATUSES", "ContactProblem", "ContactSolution", "Model", "Push", "ReferenceData",
           "Scales", "WarmStart", "Watch"]

#: the statuses a :class:`ContactSolution` can carry
STATUSES = ("converged", "inaccurate", "max_iter", "diverged", "infeasible", "failed",
            "model_inadequate")


@dataclass(frozen=True)
class WarmStart:
    """Where a method may start, given explicitly: ``solve(problem, method, warm_start=...)``.

    ``lam`` and ``u`` are an earlier answer's contact forces and displacement
    (``pdas`` starts from both, ``pdas-amg`` from the active set of ``lam``);
    ``zone_solver`` holds a factorisation of this K around the contact
    ``zone`` (a :class:`~signorini.numerics.zone.ZoneSolver`; ``nested``
    reuses both and costs back-solves only); ``factor`` a factorisation of
    this K with an active set's dofs pinned or of its saddle-point system (load
    control's last), which ``pdas`` reuses
    when its first active set is that one. A method never reads a warm
    start from anywhere else.
    """

    lam: np.ndarray | None = None
    u: np.ndarray | None = None
    zone_solver: Any = None
    zone: Any = None
    factor: Any = None

    @classmethod
    def of(cls, earlier: Any) -> "WarmStart":
        """A warm start from an earlier answer: a WarmStart, a ContactSolution or a Result."""
        if isinstance(earlier, WarmStart):
            return earlier
        solution = getattr(earlier, "solution", earlier)
        if not isinstance(solution, ContactSolution):
            raise InputError(f"warm_start must be an earlier Result, ContactSolution or "
                             f"WarmStart, got {type(earlier).__name__}")
        return cls(lam=solution.lam, u=solution.u)

    def check_fits(self, n: int, m: int) -> "WarmStart":
        """Itself with float arrays, when its ``u`` has ``n`` finite entries and its ``lam``
        ``m``; InputError otherwise."""
        arrays = {}
        for name, value, size in (("u", self.u, n), ("lam", self.lam, m)):
            if value is None:
                continue
            arrays[name] = vector_argument(value, f"warm_start's {name}")
            if arrays[name].shape != (size,):
                raise InputError(f"warm_start: its {name} has shape {np.shape(value)} and this "
                                 f"problem needs ({size},): start from an answer of this problem "
                                 "(the same mesh and candidates), or give no warm_start")
            if not np.all(np.isfinite(arrays[name])):
                raise InputError(f"warm_start: its {name} is not finite (NaN or inf, as a failed "
                                 "run's): start from a finite answer, or give no warm_start")
        return replace(self, **arrays)


@dataclass
class ContactSolution:
    """What a solver returns: ``u`` (free dofs), ``lam`` (contact forces), status.

    ``status`` is one of :data:`STATUSES`. ``converged`` means the solver
    claims success *and* the package's KKT certificate agrees (the wrapper in
    :func:`signorini.solvers.registry.solve` enforces this). ``history`` maps a name to
    one value per iteration (``kkt``, ``primal``, ``dual``...).

    ``u`` and ``lam`` are in the units of the problem's arrays: dimensionless for
    a scene built with ``nondimensionalise=True`` (the default; multiply by
    ``problem.scales``), the user's own for a QP given as arrays; a
    :class:`signorini.result.Result` gives displacements, gaps, forces and
    pressures in the problem's physical units.
    """

    method: str
    u: np.ndarray
    lam: np.ndarray
    status: str
    message: str = ""
    iterations: int = 0
    build_time: float = 0.0
    solve_time: float = 0.0
    history: dict[str, list[float]] = field(default_factory=dict)
    extras: dict[str, Any] = field(default_factory=dict)
    #: the method's own status when the package's certificate disagreed with it ("" otherwise)
    claimed_status: str = ""
    #: a factorisation of the problem's K the method holds (a PinnedFactor, possibly with
    #: contact dofs pinned), which the certificate reuses for its duality gap and then lets go,
    #: unless ``keep_factor`` (asked for by ``signorini.solve(..., keep_factor=True)``: the
    #: first derivative of the answer then reuses it when it pins the final active set)
    factor: Any = field(default=None, repr=False, compare=False)
    keep_factor: bool = field(default=False, repr=False, compare=False)
    #: the work of every stage that ran, by stage ("method", "load_control"): active-set or
    #: load-control steps, factorisations, back-solves, CG iterations
    work: dict[str, dict[str, int]] = field(default_factory=dict)
    #: the wall time of every stage that ran, by stage ("load control", "method",
    #: "certificate"), in seconds (:func:`signorini.numerics.factor.timed`)
    seconds: dict[str, float] = field(default_factory=dict)
    __repr__ = short_repr

    def __post_init__(self) -> None:
        if self.status not in STATUSES:
            raise ValueError(f"status {self.status!r} is not one of {STATUSES}")

    @property
    def contact_force(self) -> np.ndarray:
        return self.lam

    @property
    def own_status(self) -> str:
        """What the method itself said: its claim when the certificate overruled it."""
        return self.claimed_status or self.status

    @property
    def success(self) -> bool:
        return self.status == "converged"

    @classmethod
    def failure(cls, method: str, problem: Any, status: str, message: str,
                **kwargs: Any) -> "ContactSolution":
        """A solution carrying no answer (NaN vectors) and a reason."""
        return cls(method=method, u=np.full(problem.n, np.nan), lam=np.full(problem.m, np.nan),
                   status=status, message=message, **kwargs)


#: from this many dofs :meth:`ContactProblem.inverse_energy` uses CG instead of a factorisation
ITERATIVE_ENERGY_FROM = 300_000
ITERATIVE_ENERGY_RTOL = 1e-6
ITERATIVE_ENERGY_MAX_ITER = 20_000


@dataclass
class ContactProblem:
    """The QP ``min ½uᵀKu − fᵀu  s.t.  Nu ≤ d`` in its ``scales``' units, and what its rows mean.

    Attributes
    ----------
    K : (n, n) sparse SPD stiffness on the free dofs.
    f : (n,) load on the free dofs (includes the lift of prescribed displacements).
    N : (m, n) sparse normal-gap rows, one per contact candidate node.
    d : (m,) initial gaps (lifted by prescribed displacements).
    weights : (m,) lumped boundary weights ``wᵢ = ∫ φᵢ ds`` of the candidates
        (None when unknown: then there is no pressure, only forces).
    contact_points : (m, dim) reference coordinates of the candidates (NaN when unknown).
    force_multiplicity : how many copies of the model make the full body
        (2 for a half model with one symmetry plane; 2π times that for an
        axisymmetric one).
    scales : the units of every array above.
    name : the scene (or the user's name for the problem).
    model : the model that made the QP (:class:`Model`: the mesh, material and load family;
        for a QP given as arrays, :meth:`Model.of_arrays`, with no mesh).
    """

    K: sp.csr_matrix
    f: np.ndarray
    N: sp.csr_matrix
    d: np.ndarray
    weights: np.ndarray | None = None
    contact_points: np.ndarray | None = None
    force_multiplicity: float = 1.0
    scales: Scales = field(default_factory=Scales)
    name: str = ""
    model: Model | None = None

    def __post_init__(self) -> None:
        self.K, self.N = sparse_argument(self.K, "K"), sparse_argument(self.N, "N")
        self.f, self.d = vector_argument(self.f, "f"), vector_argument(self.d, "d")
        if self.weights is not None:
            self.weights = vector_argument(self.weights, "weights")
        n, m = self.K.shape[0], self.N.shape[0]
        if self.K.shape != (n, n):
            raise InputError(f"K must be square, got shape {self.K.shape}")
        if self.f.shape != (n,):
            raise InputError(f"f must have shape ({n},), got {self.f.shape}")
        if self.N.shape != (m, n):
            raise InputError(f"N must have shape (m, {n}), got {self.N.shape}")
        if self.d.shape != (m,):
            raise InputError(f"d must have shape ({m},), got {self.d.shape}")
        if self.weights is not None and self.weights.shape != (m,):
            raise InputError(f"weights must have shape ({m},), got {self.weights.shape}")
        if m == 0:
            raise InputError("the problem has no contact candidates: nothing can touch the obstacle")
        for name in ("f", "d", "weights"):
            if getattr(self, name) is not None and not np.all(np.isfinite(getattr(self, name))):
                raise InputError(f"{name} contains non-finite values")
        if not np.all(np.isfinite(self.K.data)) or not np.all(np.isfinite(self.N.data)):
            raise InputError("K or N contains non-finite values")
        if self.weights is not None and np.any(self.weights <= 0):
            bad = int(np.argmin(self.weights))
            raise InputError(
                f"contact candidate {bad} has weight {self.weights[bad]:g} ≤ 0: "
                "every candidate must lie on a boundary edge of positive length")
        if self.contact_points is None:
            self.contact_points = np.full((m, 2), np.nan)
        if self.model is None:
            self.model = Model.of_arrays(n)
        self._factor = None

    @classmethod
    def from_qp(cls, K: Any, f: Any, N: Any, d: Any, *, weights: Any = None,
                contact_points: Any = None, force_multiplicity: float = 1.0,
                name: str = "") -> "ContactProblem":
        """A problem from the QP's own data, ``min ½uᵀKu − fᵀu  s.t.  Nu ≤ d``, in your units.

        ``K`` (n × n, symmetric positive definite) and ``N`` (m × n) may be
        dense or sparse; every unknown is free (no prescribed dofs, no mesh).
        Without ``weights`` (the lumped boundary weight of each candidate) a
        result has forces but no pressures; without ``contact_points`` no
        positions; there is no analytic reference to compare with. Shapes
        and values are checked (InputError names the array and the fix).

        The problem holds your arrays (as CSR and float arrays, the same
        values) and its ``scales`` are the identity: ``.K``, ``.f``, ``.N``,
        ``.d`` and :meth:`qp` are what you passed, a method of your own is
        handed them, and a :class:`signorini.Result` answers in your units.
        A built-in method that needs numbers of order one works on a scaled
        view of its own (:func:`signorini.solvers.registry.scaled_view`).
        """
        K = symmetric_argument(sparse_argument(K, "K"))
        N = sparse_argument(N if sp.issparse(N) or np.ndim(N) != 1 else np.atleast_2d(N), "N")
        return cls(K=K, f=f, N=N, d=d, weights=weights,
                   contact_points=points_argument(contact_points, N),
                   force_multiplicity=multiplicity_argument(force_multiplicity), name=name)

    @property
    def n(self) -> int:
        """Number of free dofs."""
        return self.K.shape[0]

    @property
    def m(self) -> int:
        """Number of contact candidates."""
        return self.N.shape[0]

    def qp(self) -> tuple[sp.csr_matrix, np.ndarray, sp.csr_matrix, np.ndarray]:
        """``(K, f, N, d)`` in the problem's physical units (its :class:`Scales` undone): for
        :meth:`from_qp`, the arrays you gave, themselves; a scene keeps them dimensionless."""
        s = self.scales
        if s == Scales():
            return self.K, self.f, self.N, self.d
        return (self.K * (s.force / s.displacement), self.f * s.force, self.N,
                self.d * s.displacement)

    def gap(self, u: np.ndarray) -> np.ndarray:
        """``d − N u``: the remaining gap at each candidate (≥ 0 when feasible)."""
        return self.d - self.N @ u

    def energy(self, u: np.ndarray) -> float:
        """Primal objective ``½uᵀKu − fᵀu``."""
        return float(0.5 * u @ (self.K @ u) - self.f @ u)

    def factor(self):
        """A cached factorisation of K (for certificates and dual objectives)."""
        if self._factor is None:
            self._factor = factorize(self.K)
        return self._factor

    cached_factor = property(lambda self: self._factor,
                             doc="The factorisation of K :meth:`factor` made, or None so far.")

    def displacement_for(self, lam: np.ndarray) -> np.ndarray:
        """``u(λ) = K⁻¹ (f − Nᵀλ)``, the minimiser of the Lagrangian."""
        return self.factor().solve(self.f - self.N.T @ lam)

    @property
    def factorises_for_certificates(self) -> bool:
        """Whether a certificate may factorise K when its method held no factorisation: below
        :data:`ITERATIVE_ENERGY_FROM` dofs, and at any size on a 2D mesh (whose factorisation
        fills in little: 10⁶ dofs in seconds, where Jacobi-preconditioned CG converges slowly on
        such stiff, graded meshes)."""
        mesh = self.model.mesh
        return self.n < ITERATIVE_ENERGY_FROM or (mesh is not None and mesh.p.shape[0] == 2)

    def inverse_energy(self, r: np.ndarray) -> float:
        """``rᵀ K⁻¹ r``: by the cached factorisation, or by conjugate gradients on big problems.

        For a certificate whose method held no factorisation of K: unless it
        :attr:`factorises_for_certificates`, Jacobi-preconditioned CG to
        ``ITERATIVE_ENERGY_RTOL`` (the last resort) instead of a serial
        factorisation; without convergence it factorises.
        """
        if self._factor is None and not self.factorises_for_certificates and np.any(r):
            from scipy.sparse.linalg import cg

            diagonal = self.K.diagonal()
            jacobi = sp.diags(1.0 / diagonal)
            z, info = cg(self.K, r, rtol=ITERATIVE_ENERGY_RTOL, atol=0.0, M=jacobi,
                         maxiter=ITERATIVE_ENERGY_MAX_ITER)
            if info == 0:
                return float(r @ z)
        return float(r @ self.factor().solve(r))

    def dual_objective(self, lam: np.ndarray) -> float:
        """``D(λ) = min_u ½uᵀKu − fᵀu + λᵀ(Nu − d)``.

        Equals ``−½ (f − Nᵀλ)ᵀ K⁻¹ (f − Nᵀλ) − λᵀ d``; concave, maximised over ``λ ≥ 0``.
        """
        r = self.f - self.N.T @ lam
        return float(-0.5 * r @ self.factor().solve(r) - lam @ self.d)

    def total_contact_force(self, lam: np.ndarray) -> float:
        """Total contact force of the full body (dimensionless): multiplicity · Σλ."""
        return float(self.force_multiplicity * np.sum(lam))

    def pushed(self, scale: float, load: float | None = None) -> "ContactProblem":
        """The QP of this problem's model at push ``scale`` (:meth:`Model.at_push
        <signorini.problem.model.Model.at_push>`; for a traction on a cut, ``load`` sets it,
        dimensionless, full body). Nothing is pending; K and its cached factorisation are shared."""
        model, f, d = self.model.at_push(scale, load, self.scales.force)
        return self._same_k(f, d, model)

    def with_target(self, P: float, params: dict[str, Any] | None = None,
                    predicted_contact: np.ndarray | None = None) -> "ContactProblem":
        """The QP of this problem's model with the target load ``P`` (the scene's units, full
        body), pending until load control matches it; mesh, K and its factorisation are shared.
        ``params`` are the parameters the model records (default: its own with ``P``),
        ``predicted_contact`` the candidates load control starts from (default: as before)."""
        model, f, d = self.model.with_target(P, self.scales.force, params, predicted_contact)
        return self._same_k(f, d, model)

    def _same_k(self, f: np.ndarray, d: np.ndarray, model: Model) -> "ContactProblem":
        new = dataclasses.replace(self, f=f, d=d, model=model)
        new._factor = self._factor  # K is unchanged
        return new

    def with_data(self, **changes: Any) -> "ContactProblem":
        """A copy with some fields (or fields of its model) replaced.

        The cached factorisation is dropped (it belongs to the old K) unless
        only fields other than K change and the caller restores it.
        """
        own = {name: changes.pop(name) for name in list(changes)
               if name in ContactProblem.__dataclass_fields__}
        if changes:
            own.setdefault("model", self.model.with_basis(**changes))
        return dataclasses.replace(self, **own)

    def save(self, path: str | os.PathLike) -> None:
        """Store the arrays of this problem (and its mesh) in ``path`` (.npz), atomically.

        :meth:`load` gives it back (the cached factorisation is not stored); the format is
        :mod:`signorini.problem.saved`'s.
        """
        saved_problem.save(self, path)

    @classmethod
    def load(cls, path: str | os.PathLike) -> "ContactProblem":
        """The problem :meth:`save` stored in ``path`` (a QP given as arrays in its own units)."""
        return saved_problem.load(path, cls)
