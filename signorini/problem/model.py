"""The model that makes a QP: a scene's mesh and material, and the load family of its QPs.

A :class:`Model` is a scene instance: the mesh, the material, how the free dofs expand to the
full vector, how f, d and the load depend on the push (:class:`Push`, the affine load family
:meth:`Model.at_push`), the boundary watched beyond the candidates (:class:`Watch`) and the
typed record a scene hands its analytic reference (:class:`ReferenceData`). The QP it makes,
:class:`~signorini.problem.contact.ContactProblem`, records its model; a QP given as arrays has
the empty model :meth:`Model.of_arrays` (no mesh, every unknown free).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import scipy.sparse as sp

from signorini.errors import InputError
from signorini.numerics.arrays import finite_real

__all__ = ["Model", "Push", "ReferenceData", "Watch"]


@dataclass(frozen=True)
class ReferenceData:
    """What an analytic reference (:mod:`signorini.references.catalogue`) reads of the scene, by field.

    Built by the scene family from its checked parameters, in the scene's
    units: ``name`` is the reference in :data:`signorini.references.catalogue.REFERENCES`,
    ``E_star = E / (1 − ν²)`` the contact modulus, ``R`` the radius of the
    cylinder or sphere (Hertz; the rigid cylinder under a block), ``H`` the
    height of a block (uniform pressure ``E* δ / H``), ``a`` the half-width of
    a rigid punch and ``corner_radius`` its corners' radius. A reference reads
    only the fields it needs; the others stay None. The load P and the push δ
    vary with load control: they are on :class:`Push`.
    """

    name: str
    E_star: float | None = None
    R: float | None = None
    H: float | None = None
    a: float | None = None
    corner_radius: float = 0.0


@dataclass(frozen=True)
class Push:
    """How the load depends on the prescribed push ``s`` (dimensionless).

    ``f(s) = s f1 + P f_load``, ``d(s) = d0 + s d1`` and the applied-load
    offset is ``s · offset1 + P · offset_load``; ``scale`` is the push the
    problem was assembled with and ``load`` the target load P (dimensionless,
    full body) when the load is a traction on a cut (``f_load`` its nodal
    forces per unit P; None when the push alone loads the body). Load
    sweeps and load targeting use it without assembling again.

    ``target`` is the load (dimensionless, full body) the scene asks for, or
    None; until a push is matched to it (:attr:`Model.pending`) the QP is at a
    nominal push, and load control (:func:`signorini.load_control.match`) finds
    the push whose load is the target.
    The load is the contact resultant along the push, ``μ Σ cᵢ λᵢ`` with ``cᵢ``
    the cosine of candidate i's normal's tilt (``resultant``; None: all 1).

    In the scene's units, ``delta`` is the push δ of the loaded boundary at
    ``scale`` and ``P`` the target load of the full body (None: the scene
    names none); :meth:`ContactProblem.pushed <signorini.problem.contact.ContactProblem.pushed>`
    keeps them with the push.
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
    resultant: np.ndarray | None = None
    delta: float | None = None
    P: float | None = None

    def f(self, scale: float, load: float | None = None) -> np.ndarray:
        """The load vector at push ``scale`` (and target ``load``, default the assembled one)."""
        load = self.load if load is None else load
        return scale * self.f1 + (load * self.f_load if self.f_load is not None else 0.0)

    def offset(self, scale: float, load: float | None = None) -> float:
        load = self.load if load is None else load
        return scale * self.offset1 + load * self.offset_load


@dataclass(frozen=True)
class Watch:
    """The boundary beyond the contact candidates, checked after every solve.

    ``rows`` (k × all dofs) are the obstacle's normal rows at the k boundary
    nodes that are not candidates and ``gaps`` their initial gaps, so that
    their gaps at a state are ``gaps − rows · expand(u)``; ``edge`` indexes the
    candidates that share a boundary facet facing the obstacle with one of
    them; ``candidate_gaps`` are the candidates' gaps before any push;
    ``remedy`` says what to change when the contact outgrows the candidates
    (see :mod:`signorini.certification.adequacy`).
    """

    rows: sp.csr_matrix
    gaps: np.ndarray
    edge: np.ndarray
    candidate_gaps: np.ndarray
    remedy: str = "extend the scene's contact candidates or lower the load"
    #: the mesh node of each row (adaptive refinement makes the ones that go through candidates)
    nodes: np.ndarray | None = None

    def gap(self, problem: Any, u: np.ndarray) -> np.ndarray:
        """The watched nodes' gaps at the free dofs ``u`` of ``problem`` (a ContactProblem)."""
        return self.gaps - self.rows @ problem.model.expand(u)


@dataclass
class Model:
    """A scene instance: the mesh and the material a QP was assembled from, and its load family.

    ``mesh`` is in dimensionless coordinates (None for a QP given as arrays); the full dof
    vector is the free dofs ``free_dofs`` and the prescribed values ``prescribed`` (zero on free
    dofs). The applied load of the full body is ``load_row @ u + load_offset`` (a reaction on
    the loaded boundary). ``E`` and ``nu`` are the material in the scene's units, ``volumetric``
    how K integrates the volumetric strain, ``axisymmetric`` says the mesh is the meridian
    half-plane (r, z) of a body of revolution (forces and weights per radian). ``reference``
    is what the scene hands its analytic reference (:class:`ReferenceData`, None for none) and
    ``params`` records the scene's parameters as built (for reports and rebuilding; code reads
    the typed fields). ``push`` says how f, d and the load depend on the prescribed push (load
    control, :mod:`signorini.load_control`), ``predicted_contact`` which candidates the scene
    expects in contact (where load control starts), ``watch`` the boundary beyond the
    candidates (see :class:`Watch`). ``mesh_s`` and ``assemble_s`` are the seconds spent
    building the scene's mesh and model, and assembling the QP from it. ``materials`` lists,
    for a mesh of several bodies (:mod:`signorini.fem.two_bodies`), each body's ``(elements,
    E, nu, volumetric)`` in the mesh's order (``E``, ``nu`` and ``volumetric`` are then the
    first body's); empty for one body. ``pending`` says the push's target load is set and not
    matched yet: the QP is at a nominal push (:func:`signorini.load_control.match` finds it).
    """

    mesh: Any
    free_dofs: np.ndarray
    prescribed: np.ndarray
    load_row: np.ndarray | None = None
    load_offset: float = 0.0
    E: float = 1.0
    nu: float = 0.0
    volumetric: str = "element"
    axisymmetric: bool = False
    reference: ReferenceData | None = None
    params: dict[str, Any] = field(default_factory=dict)
    push: Push | None = None
    predicted_contact: np.ndarray | None = None
    watch: Watch | None = None
    mesh_s: float = 0.0
    assemble_s: float = 0.0
    materials: tuple[tuple[int, float, float, str], ...] = ()
    pending: bool = False

    @classmethod
    def of_arrays(cls, n: int) -> "Model":
        """The model of a QP given as arrays: no mesh, no load family, all ``n`` unknowns free."""
        return cls(mesh=None, free_dofs=np.arange(n), prescribed=np.zeros(n))

    def __post_init__(self) -> None:
        self._basis = None

    @property
    def empty(self) -> bool:
        """The model of a QP given as arrays (:meth:`of_arrays`): no mesh, no load family, no
        reference, nothing prescribed."""
        return (self.mesh is None and self.push is None and self.load_row is None
                and self.reference is None and not self.params and not np.any(self.prescribed))

    @property
    def reference_name(self) -> str:
        """The name of the analytic reference the scene declares ("" for none)."""
        return "" if self.reference is None else self.reference.name

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

    def expand(self, u: np.ndarray) -> np.ndarray:
        """The full dof vector (free and prescribed) from the free dofs' values ``u``."""
        full = self.prescribed.copy()
        full[self.free_dofs] = u
        return full

    def dofs(self) -> tuple[int, np.ndarray]:
        """The size of the full dof vector (free and prescribed) and the free dofs' places in it."""
        return self.prescribed.size, self.free_dofs

    def applied_load(self, u: np.ndarray) -> float:
        """The total load the boundary conditions apply to the full body at the free dofs ``u``
        (dimensionless; NaN when the scene records no loaded boundary)."""
        if self.load_row is None:
            return float("nan")
        return float(self.load_row @ u + self.load_offset)

    def element_materials(self) -> tuple[Any, Any]:
        """``(E, nu)`` of the model: two numbers, or one per element for several bodies."""
        if not self.materials:
            return self.E, self.nu
        counts, E, nu, _ = (np.array(column) for column in zip(*self.materials))
        return np.repeat(E.astype(float), counts), np.repeat(nu.astype(float), counts)

    def with_basis(self, **changes: Any) -> "Model":
        """A copy with ``changes``, sharing this model's basis (the mesh is the same)."""
        new = dataclasses.replace(self, **changes)
        new._basis = self._basis
        return new

    def at_push(self, scale: float, load: float | None = None, force_scale: float = 1.0
                ) -> tuple["Model", np.ndarray, np.ndarray]:
        """The load family: the model at push ``scale`` (and, for a traction on a cut, the
        dimensionless ``load``; ``force_scale`` is its unit in the scene's), with its QP's ``f``
        and ``d`` there; nothing is pending."""
        pu = self.push
        if pu is None:
            raise InputError("this model does not record how its load depends on the push (a QP "
                             "given as arrays, or a scene without a push): solve it as it is")
        for name, value in (("scale", scale), ("load", load)):
            if value is not None and not finite_real(value):
                raise InputError(f"at_push: {name}={value!r} must be a finite number (the "
                                 f"push's {name} in the model's units, e.g. {name}={pu.scale:g})")
        ratio = scale / pu.scale
        load = pu.load if load is None else load
        changed: dict[str, float] = {}  # δ and P in the scene's units, where the scene names them
        if pu.delta is not None:
            changed["delta"] = pu.delta * ratio
        if pu.f_load is not None and pu.P is not None:
            changed["P"] = load * force_scale
        model = self.with_basis(
            load_offset=pu.offset(scale, load), prescribed=self.prescribed * ratio,
            params={**self.params, **changed},  # the record of the parameters says the same
            push=dataclasses.replace(pu, scale=scale, load=load, **changed), pending=False)
        return model, pu.f(scale, load), pu.d0 + scale * pu.d1

    def with_target(self, P: float, force_scale: float, params: dict[str, Any] | None = None,
                    predicted_contact: np.ndarray | None = None
                    ) -> tuple["Model", np.ndarray, np.ndarray]:
        """The model with the target load ``P`` (the scene's units; ``force_scale`` its unit in
        them), pending, at its nominal push, with its QP's ``f`` and ``d`` there. Nothing is
        meshed or assembled (``mesh_s`` and ``assemble_s`` are 0)."""
        pu = self.push
        if pu is None or pu.target is None:
            raise InputError("this problem has no target load to change: build the scene with a "
                             "load P (or a_over_R), or build it again with the new load")
        if not (finite_real(P) and P > 0):
            raise InputError(f"the target load P={P!r} must be a finite number > 0 (the scene's "
                             "units, full body), e.g. with_load(problem, P=2.5)")
        target = P / force_scale
        load = target if pu.f_load is not None else pu.load  # a cut's traction is the load itself
        model = self.with_basis(
            load_offset=pu.offset(pu.scale, load), mesh_s=0.0, assemble_s=0.0,
            params=dict(self.params, P=P) if params is None else params,
            predicted_contact=(self.predicted_contact if predicted_contact is None
                               else predicted_contact),
            push=dataclasses.replace(pu, load=load, target=target, P=P), pending=True)
        return model, pu.f(pu.scale, load), pu.d0 + pu.scale * pu.d1
