"""Two elastic bodies in contact, plane strain or axisymmetric: one QP ``min ½uᵀKu − fᵀu, Nu ≤ d``.

The unknown is u = (u¹, u²), each body's free dofs; ``K = diag(K¹, K²)`` and
``f = (f¹, f²)``, each body assembled on its own mesh with its own material
and held by its own Dirichlet conditions. The rows of N couple the slave
face of body 1 to the master face of body 2 (:mod:`signorini.fem.mortar`),
scaled so that λ is a nodal force on the slave face and ``λ / w`` its
pressure. The compliance the contact sees is the sum of the two bodies',

    W = N K⁻¹ Nᵀ = N¹ K¹⁻¹ N¹ᵀ + N² K²⁻¹ N²ᵀ,

springs in series. The two meshes are kept as one mesh of two components
(body 1's nodes first), so a solution expands, exports and plots as one
field.
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import scipy.sparse as sp
from skfem import MeshTri
from skfem.models.elasticity import lame_parameters

from signorini.references.analytic import contact_modulus
from signorini.problem.model import ReferenceData
from signorini.errors import InputError
from signorini.fem.assembly import contact_weights, cut_forces, lame_stiffness, nodal_dofs
from signorini.fem.mortar import Face, couple
from signorini.fem.topology import moved, outward_normals, with_topology
from signorini.fem.model import resolve
from signorini.problem.contact import ContactProblem, Model, Push, Scales, Watch

log = logging.getLogger(__name__)

__all__ = ["Body", "TwoBodyModel", "series_modulus"]


@dataclass(frozen=True)
class Body:
    """One elastic body of a pair, in physical units.

    ``mesh`` a triangle mesh, ``E`` and ``nu`` its material, ``dirichlet`` its
    supports ``(component, nodes, value)`` (component 0 is x, 1 is y),
    ``contact_facets`` the boundary facets of its contact face, ``load_nodes``
    the nodes whose y-reactions make up the applied load (a push towards the
    other body is positive; empty for none), ``volumetric`` how K integrates
    the volumetric strain (:mod:`signorini.fem.volumetric`). ``traction`` is
    ``(facets, direction)``: a cut loaded by a uniform traction along y
    (direction −1 down, +1 up) whose total is the pair's target load, as
    Hertz's theory loads a body (None: no traction).
    """

    mesh: Any
    E: float
    nu: float
    dirichlet: list[tuple[int, np.ndarray, float]]
    contact_facets: np.ndarray
    load_nodes: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int))
    volumetric: str = "auto"
    traction: tuple[np.ndarray, float] | None = None

    def stiffness(self, mesh: Any, stress: float, axisymmetric: bool = False) -> sp.csr_matrix:
        """K of the whole body on ``mesh`` (its nodes scaled), E in units of ``stress``."""
        Lambda, Mu = lame_parameters(self.E / stress, self.nu)
        return lame_stiffness(mesh, Lambda, Mu, axisymmetric=axisymmetric,
                              volumetric=resolve(self.volumetric, self.nu))


#: what to change when the slave's outermost candidate is in contact
EDGE_REMEDY = "raise the scene parameter candidates (the slave's contact face) or lower the load"
#: a boundary facet beyond the contact face faces the other body when its outward normal is within
#: 60° of the face's mean outward normal
FACING = 0.5


def _edge_rows(slave: Body, row_nodes: np.ndarray) -> np.ndarray:
    """The rows whose slave node ends the rows where the slave's boundary goes on facing the
    other body (beyond the candidates, or on candidates the master face does not reach: unseen by
    the QP): in contact, the zone may go on beyond them (:mod:`signorini.certification.adequacy`).
    A face that ends at a side turned away (a block's corner, a symmetry plane) has none."""
    mesh = with_topology(slave.mesh)
    facets = mesh.boundary_facets()
    beyond = facets[~np.isin(mesh.facets[:, facets], row_nodes).all(axis=0)]
    facing = outward_normals(mesh, slave.contact_facets).mean(axis=1)
    facing /= np.linalg.norm(facing)
    turned = facing @ outward_normals(mesh, beyond) > FACING
    return np.flatnonzero(np.isin(row_nodes, mesh.facets[:, beyond[turned]]))


def series_modulus(E1: float, nu1: float, E2: float, nu2: float) -> float:
    """The pair's contact modulus ``E*``: ``1/E* = (1 − ν₁²)/E₁ + (1 − ν₂²)/E₂``."""
    return 1.0 / (1.0 / contact_modulus(E1, nu1) + 1.0 / contact_modulus(E2, nu2))


def _check_held(body: Body, which: str) -> None:
    """Refuse a body whose supports leave a rigid motion free: K would be singular."""
    x, y = body.mesh.p
    rigid = np.stack([np.stack([np.ones_like(x), np.zeros_like(x)]),
                      np.stack([np.zeros_like(x), np.ones_like(x)]),
                      np.stack([-y, x])])  # (3 modes, 2 components, nodes)
    held = [rigid[:, c, np.asarray(nodes, dtype=int)] for c, nodes, _ in body.dirichlet]
    held = np.concatenate(held, axis=1) if held else np.zeros((3, 0))
    if np.linalg.matrix_rank(held.T, tol=1e-9 * max(1.0, np.abs(held).max(initial=0.0))) < 3:
        raise InputError(f"the {which} body floats: its supports leave a rigid motion free (K "
                         "singular); hold it by its own Dirichlet conditions (e.g. a fixed base "
                         "or a pushed top and one roller on a side)")


def _cut_traction(bodies: tuple[Body, Body], offsets: tuple[int, int], L: float,
                  dof_table: np.ndarray, load_dofs: np.ndarray, multiplicity: float,
                  axisymmetric: bool = False) -> tuple[np.ndarray | None, float]:
    """Nodal forces of the bodies' cut tractions per unit load of the full pair (None: no cut
    is loaded), and the part of the applied load the load dofs' reactions do not see.

    Each cut's uniform traction is ``1 / (μ A)`` along its direction, A the cut's length (its
    area per radian when ``axisymmetric``); its
    consistent nodal forces are the lumped weights times it (exact for P1).
    """
    f_load, offset_load, loaded = np.zeros(dof_table.size), 0.0, False
    for body, first in zip(bodies, offsets):
        if body.traction is None:
            continue
        facets, direction = body.traction
        mesh = moved(body.mesh, body.mesh.p / L)
        nodes = np.unique(mesh.facets[:, facets])
        forces, offset = cut_forces(contact_weights(mesh, facets, nodes, axisymmetric),
                                    dof_table[1, nodes + first], direction, multiplicity,
                                    load_dofs, dof_table.size)
        f_load += forces
        loaded = True
        if len(body.load_nodes):  # the traction on the loaded body's other nodes
            offset_load += offset
    return (f_load if loaded else None), offset_load


@dataclass(frozen=True)
class TwoBodyModel:
    """A two-body scene in physical units (``slave`` on ``master``), assembled into one QP by
    :meth:`assemble`: what a two-body scene family's ``build`` returns (a one-body family returns
    a SceneModel)."""

    slave: Body
    master: Body
    discretisation: str
    length_scale: float
    force_multiplicity: float = 1.0
    reference: ReferenceData | None = None
    params: dict[str, Any] = field(default_factory=dict)
    target_load: float | None = None
    predicted: Any = None
    direction: np.ndarray | None = None
    axisymmetric: bool = False

    def assemble(self, nondimensionalise: bool = True) -> ContactProblem:
        """The contact QP of the two bodies: ``K = diag(K¹, K²)``, f, N, d, weights, points, scales.

        The slave carries the rows: one per slave node the master face
        reaches, scaled to nodal forces (:meth:`~signorini.fem.mortar.Coupling.scaled`);
        ``weights`` are ``∫ φₛ ds`` and ``contact_points`` the slave nodes. Units
        as :func:`signorini.fem.assembly.assemble` makes them: lengths by
        ``length_scale``, displacements by the largest prescribed one, stresses
        by the pair's contact modulus E* (:func:`series_modulus`).

        ``target_load`` (the full pair, scene units) leaves the problem pending:
        load control scales the prescribed push until the contact resultant along
        y is that load; ``predicted(points)`` says which slave nodes (physical
        coordinates, (k, 2)) the scene expects in contact, where load control starts.
        ``direction`` fixes the rows' normal (the slave's outward unit normal, e.g.
        the common normal at the first point of contact, along which Hertz's
        theory measures the gap); None: each master segment's normal.
        ``axisymmetric``: both meshes in the meridian half-plane (r, z), K and
        the rows' integrals per radian (weight r), forces in units of E*·U·L.
        """
        start = time.perf_counter()
        slave, master, discretisation = self.slave, self.master, self.discretisation
        length_scale, force_multiplicity = self.length_scale, self.force_multiplicity
        axisymmetric, target_load, predicted = self.axisymmetric, self.target_load, self.predicted
        _check_held(slave, "slave")
        _check_held(master, "master")
        L = length_scale if nondimensionalise else 1.0
        stress = series_modulus(slave.E, slave.nu, master.E, master.nu) if nondimensionalise else 1.0
        values = [abs(v) for body in (slave, master) for _, nodes, v in body.dirichlet if len(nodes)]
        U = (max(values, default=0.0) or length_scale) if nondimensionalise else 1.0
        first = slave.mesh.p.shape[1]
        k = 1 if axisymmetric else 0  # force = E*·U·L^k, weight = L^(k+1)
        mesh = MeshTri(np.hstack([slave.mesh.p, master.mesh.p]) / L,
                       np.hstack([slave.mesh.t, master.mesh.t + first]))
        dof_table = nodal_dofs(mesh)
        K_full = sp.block_diag([body.stiffness(moved(body.mesh, body.mesh.p / L), stress,
                                               axisymmetric) for body in (slave, master)], format="csr")
        n_full = K_full.shape[0]

        prescribed = np.zeros(n_full)
        is_free = np.ones(n_full, dtype=bool)
        for offset, body in ((0, slave), (first, master)):
            for component, nodes, value in body.dirichlet:
                dofs = dof_table[component, np.asarray(nodes, dtype=int) + offset]
                prescribed[dofs] = value / U
                is_free[dofs] = False
        free, fixed = np.flatnonzero(is_free), np.flatnonzero(~is_free)

        slave_face = Face.of(slave.mesh, slave.contact_facets)
        master_face = Face.of(master.mesh, master.contact_facets)
        coupling = couple(slave_face, master_face, discretisation, self.direction, axisymmetric).scaled()
        N_full = coupling.rows(dof_table[:, slave_face.nodes], dof_table[:, master_face.nodes + first],
                               n_full)
        load_dofs = np.concatenate([dof_table[1, slave.load_nodes],
                                    dof_table[1, master.load_nodes + first]]).astype(int)
        load_full = -force_multiplicity * np.asarray(K_full[load_dofs].sum(axis=0)).ravel()

        K_free = K_full[free]
        K_II, K_ID = K_free[:, free], K_free[:, fixed]
        u_D = prescribed[fixed]
        f1 = -(K_ID @ u_D)
        d0 = coupling.gap / U
        d1 = -(N_full[:, fixed] @ u_D)
        offset1 = float(load_full[fixed] @ u_D)
        target = None if target_load is None else target_load / (stress * U * L ** k)
        f_load, offset_load = _cut_traction((slave, master), (0, first), L, dof_table, load_dofs,
                                            force_multiplicity, axisymmetric)
        if f_load is not None and target is None:
            raise InputError("a load applied on a cut needs a target load: give P (or a_over_R)")
        load = 0.0 if f_load is None else target
        f = f1 + (0.0 if f_load is None else load * f_load[free])
        offset = offset1 + load * offset_load
        pushed = [-v for body in (slave, master) for c, nodes, v in body.dirichlet
                  if c == 1 and np.isin(nodes, body.load_nodes).any()]
        points = mesh.p[:, slave_face.nodes[coupling.slave]].T
        # each row's share of the resultant along y: the y-part of its slave normal, reversed
        resultant = -np.asarray(N_full[:, dof_table[1, slave_face.nodes]].sum(axis=1)).ravel()
        push = Push(f1=f1, d0=d0, d1=d1, offset1=offset1, scale=1.0,
                    f_load=None if f_load is None else f_load[free], offset_load=offset_load,
                    load=load, target=target,
                    resultant=None if np.all(resultant == 1.0) else resultant,
                    delta=max(pushed) if pushed else None, P=target_load)
        record = Model(
            mesh=mesh, free_dofs=free, prescribed=prescribed, load_row=load_full[free],
            load_offset=offset, E=float(slave.E), nu=float(slave.nu),
            volumetric=resolve(slave.volumetric, slave.nu), axisymmetric=axisymmetric,
            reference=self.reference,
            materials=tuple((body.mesh.t.shape[1], float(body.E), float(body.nu),
                             resolve(body.volumetric, body.nu)) for body in (slave, master)),
            params=dict(self.params, discretisation=discretisation), push=push,
            predicted_contact=None if predicted is None else np.asarray(predicted(points * L)),
            watch=Watch(sp.csr_matrix((0, n_full)), np.zeros(0), _edge_rows(
                slave, slave_face.nodes[coupling.slave]), np.zeros(0), EDGE_REMEDY),
            pending=target is not None)
        problem = ContactProblem(
            K=K_II, f=f, N=N_full[:, free].tocsr(), d=d0 + d1,
            weights=coupling.weights / L ** (k + 1),
            contact_points=points,
            force_multiplicity=force_multiplicity,
            scales=Scales(length=L, displacement=U, force=stress * U * L ** k, weight=L ** (k + 1)),
            model=record)
        record.assemble_s = time.perf_counter() - start
        log.info("assembled two bodies: %d free dofs, %d %s rows in %.2f s", problem.n, problem.m,
                 discretisation, record.assemble_s)
        return problem
