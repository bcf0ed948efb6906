"""Where a contact problem came from: the scene's mesh and model, and what varies with the push.

:class:`Discretisation` rides beside the QP of a
:class:`~signorini.problem.contact.ContactProblem`: the mesh, the material, how the
free dofs expand to the full vector, how f, d and the load depend on the push
(:class:`Push`), the boundary watched beyond the candidates (:class:`Watch`)
and the typed record a scene hands its analytic reference
(:class:`ReferenceData`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
import scipy.sparse as sp

__all__ = ["Discretisation", "Push", "ReferenceData", "Watch"]


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
    None; ``pending`` says that no push has been matched to it yet: the
    problem is at a nominal push, and load control
    (:func:`signorini.load_control.match`) finds the push whose load is the target.
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
    pending: bool = False
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
        return self.gaps - self.rows @ problem.expand(u)


@dataclass
class Discretisation:
    """Where a problem came from: the mesh and the model a scene assembled it from.

    ``mesh`` is in dimensionless coordinates; the full dof vector is the free
    dofs ``free_dofs`` and the prescribed values ``prescribed`` (zero on free
    dofs). The applied load of the full body is ``load_row @ u + load_offset``
    (a reaction on the loaded boundary). ``E`` and ``nu`` are the material in
    the scene's units, ``volumetric`` how K integrates the volumetric strain,
    ``axisymmetric`` says the mesh is the meridian half-plane (r, z) of a body
    of revolution (forces and weights per radian). ``reference`` is what the
    scene hands its analytic reference (:class:`ReferenceData`, None for none)
    and ``params`` records the scene's parameters as built (for reports and
    rebuilding; code reads the typed fields). ``push``
    says how f, d and the load depend on the prescribed push (load control,
    :mod:`signorini.load_control`), ``predicted_contact`` which candidates the
    scene expects in contact (where load control starts), ``watch`` the
    boundary beyond the candidates (see :class:`Watch`). ``mesh_s`` and
    ``assemble_s`` are the seconds spent building the scene's mesh and model,
    and assembling the QP from it. ``materials`` lists, for a mesh of
    several bodies (:mod:`signorini.fem.two_bodies`), each body's ``(elements, E, nu,
    volumetric)`` in the mesh's order (``E``, ``nu`` and ``volumetric`` are then the first
    body's); empty for one body.
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

    def element_materials(self) -> tuple[Any, Any]:
        """``(E, nu)`` of the model: two numbers, or one per element for several bodies."""
        if not self.materials:
            return self.E, self.nu
        counts, E, nu, _ = (np.array(column) for column in zip(*self.materials))
        return np.repeat(E.astype(float), counts), np.repeat(nu.astype(float), counts)
