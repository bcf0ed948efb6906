"""The discrete Signorini problem and what a solver returns for it.

The problem is one convex QP::

    minimise   ½ uᵀ K u − fᵀ u        (K sparse SPD, n × n)
    subject to N u ≤ d                (N sparse m × n, one row per contact candidate)

with KKT conditions ``K u − f + Nᵀ λ = 0``, ``N u ≤ d``, ``λ ≥ 0``,
``λᵢ (N u − d)ᵢ = 0``. ``λ`` is the nodal contact force (compressive positive).

All arrays held by :class:`ContactProblem` are dimensionless; :class:`Scales`
turns them back into physical units.
"""

from __future__ import annotations

import dataclasses
import io
import json
import os
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np
import scipy.sparse as sp
from skfem import MeshTet, MeshTri

from signorini.errors import InputError
from signorini.files import atomic_write_bytes
from signorini.numerics.arrays import (
    multiplicity_argument,
    points_argument,
    sparse_argument,
    vector_argument,
)
from signorini.numerics.factor import factorize
from signorini.numerics.loading import calibrate_push
from signorini.solution import STATUSES, ContactSolution

__all__ = ["STATUSES", "ContactProblem", "ContactSolution", "Push", "Scales", "WarmStart", "Watch"]

#: from this many dofs :meth:`ContactProblem.inverse_energy` uses CG instead of a factorisation
ITERATIVE_ENERGY_FROM = 300_000
ITERATIVE_ENERGY_RTOL = 1e-6
ITERATIVE_ENERGY_MAX_ITER = 20_000


@dataclass(frozen=True)
class Scales:
    """Units that make the problem dimensionless.

    A physical quantity is its dimensionless value times its scale:
    coordinates ``x = length · x̂``, displacements and gaps
    ``u = displacement · û``, contact forces ``λ = force · λ̂``, weights
    ``w = weight · ŵ`` and pressures ``p = λ / w = pressure · p̂`` with
    ``pressure = force / weight``. In 2D (per unit thickness)
    ``force = E · displacement`` and ``weight = length``; in 3D and in
    axisymmetric models ``force = E · displacement · length`` and
    ``weight = length²``. Axisymmetric forces and weights (``∫ φᵢ r ds``) are
    **per radian**; ``force_multiplicity`` (2π times any other copies) turns
    ``Σλ`` into the force on the whole body. Scaling the
    displacement apart from the geometry matters: a Hertz contact at
    a/R = 0.05 moves by about 1e-3 R, and a solver's absolute tolerances
    only mean something when the unknowns are of order one.
    """

    length: float = 1.0
    displacement: float = 1.0
    force: float = 1.0
    weight: float = 1.0

    @property
    def pressure(self) -> float:
        return self.force / self.weight


@dataclass(frozen=True)
class Push:
    """How the load depends on the prescribed push ``s`` (dimensionless).

    ``f(s) = s f1 + P f_load``, ``d(s) = d0 + s d1`` and the applied-load
    offset is ``s · offset1 + P · offset_load``; ``scale`` is the push the
    problem was assembled with and ``load`` the target load P (dimensionless,
    full body) when the load is a traction on a cut (``f_load`` its nodal
    forces per unit P; None when the push alone loads the body). Load
    sweeps and load targeting use it without assembling again.

    ``target`` is the load (dimensionless, full body) that load targeting
    matched, or None; ``pending`` says that it has not matched it yet: the
    problem is at a nominal push and the method (``pdas-amg``) finds the push
    with the answer, or :meth:`ContactProblem.matched` does first.
    """

    f1: np.ndarray
    d0: np.ndarray
    d1: np.ndarray
    offset1: float
    scale: float
    f_load: np.ndarray | None = None
    offset_load: float = 0.0
    load: float = 0.0
    target: float | None = None
    pending: bool = False

    def f(self, scale: float, load: float | None = None) -> np.ndarray:
        """The load vector at push ``scale`` (and target ``load``, default the assembled one)."""
        load = self.load if load is None else load
        return scale * self.f1 + (load * self.f_load if self.f_load is not None else 0.0)

    def offset(self, scale: float, load: float | None = None) -> float:
        load = self.load if load is None else load
        return scale * self.offset1 + load * self.offset_load


@dataclass
class WarmStart:
    """What load targeting learnt about a problem, for a solver to start from.

    ``lam`` are the exact contact forces at the targeted load (None once the
    load changes) and ``u`` the displacement with them (when load targeting
    solved the full system; ``pdas`` starts from both); ``zone_solver`` is the :class:`~signorini.numerics.zone.ZoneSolver`
    that holds K's factorisation with its final ``zone`` (the ``nested``
    method reuses both while K is unchanged).
    """

    lam: np.ndarray | None = None
    zone_solver: Any = None
    zone: Any = None
    u: np.ndarray | None = None


@dataclass(frozen=True)
class Watch:
    """The boundary beyond the contact candidates, checked after every solve.

    ``rows`` (k × all dofs) are the obstacle's normal rows at the k boundary
    nodes that are not candidates and ``gaps`` their initial gaps, so that
    their gaps at a state are ``gaps − rows · expand(u)``; ``edge`` indexes the
    candidates that share a boundary facet facing the obstacle with one of
    them; ``candidate_gaps`` are the candidates' gaps before any push;
    ``remedy`` says what to change when the contact outgrows the candidates
    (see :mod:`signorini.adequacy`).
    """

    rows: sp.csr_matrix
    gaps: np.ndarray
    edge: np.ndarray
    candidate_gaps: np.ndarray
    remedy: str = "extend the scene's contact candidates or lower the load"
    #: the mesh node of each row (adaptive refinement makes the ones that go through candidates)
    nodes: np.ndarray | None = None

    def gap(self, problem: "ContactProblem", u: np.ndarray) -> np.ndarray:
        return self.gaps - self.rows @ problem.expand(u)


@dataclass
class ContactProblem:
    """Data of ``min ½uᵀKu − fᵀu  s.t.  Nu ≤ d`` (dimensionless).

    Attributes
    ----------
    K : (n, n) sparse SPD stiffness on the free dofs.
    f : (n,) load on the free dofs (includes the lift of prescribed displacements).
    N : (m, n) sparse normal-gap rows, one per contact candidate node.
    d : (m,) initial gaps (lifted by prescribed displacements).
    weights : (m,) lumped boundary weights ``wᵢ = ∫ φᵢ ds`` of the candidates
        (None when unknown: then there is no pressure, only forces).
    contact_points : (m, dim) reference coordinates of the candidates (NaN when unknown).
    free_dofs : (n,) indices of the free dofs inside the full dof vector.
    prescribed : (n_full,) full dof vector holding the prescribed values (zero on free dofs).
    load_row, load_offset : the total applied load of the full body is
        ``load_row @ u + load_offset`` (a reaction on the loaded boundary), used
        to check force balance against ``force_multiplicity · Σ λ``.
    force_multiplicity : how many copies of the model make the full body
        (2 for a half model with one symmetry plane).
    scales : the units of every array above.
    scene, params : where the problem came from.
    mesh : the scene's mesh (for plots and export), in dimensionless coordinates.
    push : how f, d and the load offset depend on the prescribed push (or None).
    axisymmetric : the mesh is the meridian half-plane (r, z) of a body of
        revolution; forces and weights are per radian.
    reference : the name of the scene's analytic reference in
        :data:`signorini.references.REFERENCES` ("" for none).
    coarse_model : a function of this problem returning a model of the same
        scene about 16 times coarser (or None), for the ``nested`` method.
    warm_start : what load targeting learnt (see :class:`WarmStart`).
    watch : the boundary beyond the candidates, checked after a solve (see :class:`Watch`).
    """

    K: sp.csr_matrix
    f: np.ndarray
    N: sp.csr_matrix
    d: np.ndarray
    weights: np.ndarray | None
    contact_points: np.ndarray
    free_dofs: np.ndarray
    prescribed: np.ndarray
    load_row: np.ndarray | None = None
    load_offset: float = 0.0
    force_multiplicity: float = 1.0
    scales: Scales = field(default_factory=Scales)
    scene: str = ""
    params: dict[str, Any] = field(default_factory=dict)
    mesh: Any = None
    assemble_time: float = 0.0
    push: Push | None = None
    axisymmetric: bool = False
    reference: str = ""
    coarse_model: Callable[["ContactProblem"], "ContactProblem | None"] | None = None
    warm_start: WarmStart = field(default_factory=WarmStart)
    watch: Watch | None = None

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
        self._factor = None
        self._basis = None

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
        """
        K = sparse_argument(K, "K")
        n = K.shape[0]
        if K.shape[0] != K.shape[1]:
            raise InputError(f"K must be square, got shape {K.shape}")
        if n and abs(K - K.T).max() > 1e-10 * abs(K).max():
            raise InputError("K must be symmetric: pass the stiffness matrix itself, or ½(K + Kᵀ)")
        N = sparse_argument(N if sp.issparse(N) or np.ndim(N) != 1 else np.atleast_2d(N), "N")
        contact_points = points_argument(contact_points, N)
        force_multiplicity = multiplicity_argument(force_multiplicity)
        return cls(K=K, f=f, N=N, d=d, weights=weights,
                   contact_points=np.asarray(contact_points, dtype=float),
                   free_dofs=np.arange(n), prescribed=np.zeros(n),
                   force_multiplicity=force_multiplicity, scene=name)

    @property
    def basis(self):
        """scikit-fem's vector P1 basis on ``mesh`` (built when first asked for)."""
        if self._basis is None and self.mesh is not None:
            from skfem import Basis, ElementVector

            self._basis = Basis(self.mesh, ElementVector(self.mesh.elem()))
        return self._basis

    @basis.setter
    def basis(self, value) -> None:
        self._basis = value

    @property
    def n(self) -> int:
        """Number of free dofs."""
        return self.K.shape[0]

    @property
    def m(self) -> int:
        """Number of contact candidates."""
        return self.N.shape[0]

    def expand(self, u: np.ndarray) -> np.ndarray:
        """Full dof vector (free and prescribed) from the free-dof vector ``u``."""
        full = self.prescribed.copy()
        full[self.free_dofs] = u
        return full

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

    @property
    def cached_factor(self):
        """The factorisation of K :meth:`factor` made, or None when none was asked for yet."""
        return self._factor

    def displacement_for(self, lam: np.ndarray) -> np.ndarray:
        """``u(λ) = K⁻¹ (f − Nᵀλ)``, the minimiser of the Lagrangian."""
        return self.factor().solve(self.f - self.N.T @ lam)

    def inverse_energy(self, r: np.ndarray) -> float:
        """``rᵀ K⁻¹ r``: by the cached factorisation, or by conjugate gradients on big problems.

        The certificate comes here only when the method held no factorisation
        of K (see :func:`signorini.kkt.primal_dual_gap`). From
        :data:`ITERATIVE_ENERGY_FROM` dofs, when no factorisation is at hand
        (a distributed solve never makes one), Jacobi-preconditioned CG to
        ``ITERATIVE_ENERGY_RTOL`` replaces a serial factorisation; it is slow
        on stiff 2D meshes (about 3 minutes on the 1M-dof cylinder), the last
        resort; without convergence it factorises.
        """
        if self._factor is None and self.n >= ITERATIVE_ENERGY_FROM and np.any(r):
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

    def applied_load(self, u: np.ndarray) -> float:
        """Total load the boundary conditions apply to the full body (dimensionless)."""
        if self.load_row is None:
            return float("nan")
        return float(self.load_row @ u + self.load_offset)

    def pushed(self, scale: float, load: float | None = None) -> "ContactProblem":
        """The same body pushed by ``scale`` times the prescribed displacement.

        For a body loaded by a traction on a cut, ``load`` (dimensionless,
        full body) sets the traction; by default it stays as assembled.
        """
        if self.push is None:
            raise ValueError("this problem does not record how its load depends on the push")
        pu = self.push
        ratio = scale / pu.scale
        load = pu.load if load is None else load
        params = dict(self.params)
        if isinstance(params.get("delta"), float):
            params["delta"] *= ratio
        if pu.f_load is not None and isinstance(params.get("P"), float):
            params["P"] = load * self.scales.force
        new = self.with_data(f=pu.f(scale, load), d=pu.d0 + scale * pu.d1,
                             load_offset=pu.offset(scale, load), prescribed=self.prescribed * ratio,
                             params=params,
                             push=dataclasses.replace(pu, scale=scale, load=load, pending=False),
                             warm_start=WarmStart(zone_solver=self.warm_start.zone_solver,
                                                  zone=self.warm_start.zone))
        # K is unchanged: keep its factorisation, its basis and the zone solver (not the forces)
        new._factor, new._basis = self._factor, self._basis
        return new

    @property
    def pending(self) -> bool:
        """The target load is not matched yet (see :class:`Push`): f and d are at a nominal push."""
        return self.push is not None and self.push.pending

    def matched(self) -> "ContactProblem":
        """This problem at the push whose load is the target (itself when nothing is pending).

        One sparse factorisation per active-set step
        (:func:`signorini.numerics.loading.calibrate_push`); the answer it
        found is the warm start of the problem returned.
        """
        if not self.pending:
            return self
        pu = self.push
        f0 = pu.load * pu.f_load if pu.f_load is not None else None
        scale, lam, u = calibrate_push(self.K, self.N, pu.f1, pu.d0, pu.d1, pu.target,
                                       self.force_multiplicity, f0=f0)
        new = self.pushed(scale)
        new.warm_start = WarmStart(lam=lam, u=u)
        return new

    def with_data(self, **changes: Any) -> "ContactProblem":
        """A copy with some fields replaced.

        The cached factorisation and the warm start are dropped (they belong
        to the old data) unless ``warm_start`` is one of the changes.
        """
        changes.setdefault("warm_start", WarmStart())
        return dataclasses.replace(self, **changes)

    def save(self, path: str | os.PathLike) -> None:
        """Store the arrays of this problem (and its mesh) in ``path`` (.npz), atomically.

        :meth:`load` gives it back; the cached factorisation, the warm start
        and the coarse-model factory are not stored.
        """
        K, N = self.K.tocsr(), self.N.tocsr()
        pu = self.push
        arrays = dict(
            K_data=K.data, K_indices=K.indices, K_indptr=K.indptr, N_data=N.data,
            N_indices=N.indices, N_indptr=N.indptr, shape=np.array([self.n, self.m]), f=self.f,
            d=self.d, weights=self.weights if self.weights is not None else np.zeros(0),
            contact_points=self.contact_points,
            free_dofs=self.free_dofs, prescribed=self.prescribed,
            load_row=self.load_row if self.load_row is not None else np.zeros(0))
        if self.mesh is not None:  # node blocks and rigid modes for the petsc methods
            arrays.update(mesh_p=self.mesh.p, mesh_t=self.mesh.t)
        if pu is not None:
            arrays.update(push_f1=pu.f1, push_d0=pu.d0, push_d1=pu.d1)
            if pu.f_load is not None:
                arrays.update(push_f_load=pu.f_load)
        meta = {"scene": self.scene, "params": self.params, "load_offset": self.load_offset,
                "force_multiplicity": self.force_multiplicity, "scales": vars(self.scales),
                "assemble_time": self.assemble_time, "axisymmetric": self.axisymmetric,
                "reference": self.reference,
                "push": None if pu is None else {"offset1": pu.offset1, "scale": pu.scale,
                                                 "offset_load": pu.offset_load, "load": pu.load,
                                                 "target": pu.target, "pending": pu.pending}}
        arrays["meta"] = np.frombuffer(json.dumps(meta).encode(), dtype=np.uint8)
        buffer = io.BytesIO()
        np.savez(buffer, **arrays)
        atomic_write_bytes(path, buffer.getvalue())

    @classmethod
    def load(cls, path: str | os.PathLike) -> "ContactProblem":
        """The problem :meth:`save` stored in ``path``."""
        z = np.load(path)
        meta = json.loads(bytes(z["meta"]).decode())
        n, m = (int(v) for v in z["shape"])
        push = None
        if meta["push"] is not None:
            push = Push(z["push_f1"], z["push_d0"], z["push_d1"], meta["push"]["offset1"],
                        meta["push"]["scale"], z["push_f_load"] if "push_f_load" in z else None,
                        meta["push"].get("offset_load", 0.0), meta["push"].get("load", 0.0),
                        meta["push"].get("target"), meta["push"].get("pending", False))
        mesh = None
        if "mesh_p" in z:
            kind = MeshTri if z["mesh_t"].shape[0] == 3 else MeshTet
            mesh = kind(z["mesh_p"], z["mesh_t"])
        return cls(
            K=sp.csr_matrix((z["K_data"], z["K_indices"], z["K_indptr"]), shape=(n, n)),
            f=z["f"], N=sp.csr_matrix((z["N_data"], z["N_indices"], z["N_indptr"]), shape=(m, n)),
            d=z["d"], weights=z["weights"] if z["weights"].size else None,
            contact_points=z["contact_points"],
            free_dofs=z["free_dofs"], prescribed=z["prescribed"],
            load_row=z["load_row"] if z["load_row"].size else None,
            load_offset=meta["load_offset"], force_multiplicity=meta["force_multiplicity"],
            scales=Scales(**meta["scales"]), scene=meta["scene"], params=meta["params"],
            push=push, mesh=mesh, assemble_time=meta["assemble_time"],
            axisymmetric=meta.get("axisymmetric", False), reference=meta.get("reference", ""))
