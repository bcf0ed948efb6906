"""Scene → :class:`ContactProblem`: stiffness, load, gap rows, weights and scales.

Three kinds of model are assembled with P1 elements, K in closed form on
triangles and tetrahedra (:mod:`signorini.fem.stiffness`: the matrices
scikit-fem assembles from the forms named below, which tests hold them to, and
scikit-fem itself on other elements):

- **plane strain** (triangles): scikit-fem's ``linear_elasticity`` with the
  Lamé parameters; quantities are per unit thickness;
- **axisymmetric** (triangles in the meridian half-plane (r, z), r ≥ 0):
  the strain has the hoop component ``ε_θθ = u_r / r`` and every integral
  carries the weight r (:func:`axisymmetric_elasticity`); quantities are
  **per radian**: K, f and the contact forces λ are those of a one-radian
  wedge, the weights are ``wᵢ = ∫ φᵢ r ds`` and the pressure ``λᵢ / wᵢ`` is
  a true pressure. The scene sets ``force_multiplicity = 2π`` (times the
  copies from other symmetries), so ``total_contact_force`` and
  ``applied_load`` are those of the full body of revolution;
- **3D** (tetrahedra): ``linear_elasticity`` with three-component normals;
  weights ``wᵢ = ∫ φᵢ dA``.

Prescribed dofs are condensed out (``K_II u_I = f_I − K_ID u_D``), one gap
row per contact candidate node is ``nᵢ · uᵢ ≤ gᵢ`` with ``nᵢ`` the body's
outward normal towards the obstacle. With ``nondimensionalise`` every solver
sees numbers of order one whatever the user's units: coordinates are divided
by the scene's length L, displacements and gaps by a displacement scale U
(the largest prescribed displacement, else the largest initial gap), E by
itself. Contact forces then come in units of E·U per unit thickness in plane
strain, and of E·U·L (per radian, or for the 3D model) otherwise; weights in
units of L and L² respectively (see :class:`~signorini.problem.contact.Scales`).
"""

from __future__ import annotations

import logging
import time
from typing import Any

import numpy as np
import scipy.sparse as sp
from skfem import Basis, BilinearForm, ElementVector, asm
from skfem.helpers import ddot, sym_grad, trace
from skfem.models.elasticity import lame_parameters, linear_elasticity

from signorini.errors import InputError
from signorini.fem.model import SceneModel
from signorini.fem.stiffness import simplex_stiffness
from signorini.fem.topology import moved, outward_normals
from signorini.fem.volumetric import volumetric_stiffness
from signorini.problem.contact import ContactProblem, Model, Push, Scales, Watch

log = logging.getLogger(__name__)


def axisymmetric_elasticity(Lambda: float = 1.0, Mu: float = 1.0) -> BilinearForm:
    """Weak form of axisymmetric linear elasticity, per radian.

    In the meridian half-plane (r, z) with ``u = (u_r, u_z)`` the strain has
    the in-plane part ``ε = sym ∇u`` and the hoop part ``ε_θθ = u_r / r``;
    with ``tr ε = ∂_r u_r + ∂_z u_z + u_r / r`` the form is

        a(u, v) = ∫ [2μ (ε(u) : ε(v) + u_r v_r / r²) + λ tr ε(u) tr ε(v)] r dr dz,

    the elastic energy of a one-radian wedge (multiply by 2π for the full
    body). Quadrature points lie inside the elements, so r > 0 wherever the
    integrand is evaluated; nodes on the axis need ``u_r = 0``.
    """

    @BilinearForm
    def weakform(u, v, w):
        r = w.x[0]
        hoop_u, hoop_v = u[0] / r, v[0] / r
        trace_u = trace(sym_grad(u)) + hoop_u
        trace_v = trace(sym_grad(v)) + hoop_v
        return (2.0 * Mu * (ddot(sym_grad(u), sym_grad(v)) + hoop_u * hoop_v)
                + Lambda * trace_u * trace_v) * r

    return weakform


def segment_weights(points: np.ndarray, ends: np.ndarray, radial: bool = False) -> np.ndarray:
    """Lumped weights ``∫ φᵢ ds`` of the ``points`` (2, k) over the segments ``ends`` (2, e):
    ``ℓ/2`` to each end of a segment of length ℓ, or (``radial``: ``∫ φᵢ r ds``, r the first
    coordinate) ``ℓ (2 rᵢ + rⱼ)/6``."""
    lengths = np.linalg.norm(points[:, ends[0]] - points[:, ends[1]], axis=0)
    r0, r1 = points[0, ends]
    shares = ((lengths * (2 * r0 + r1) / 6, lengths * (2 * r1 + r0) / 6) if radial
              else (0.5 * lengths, 0.5 * lengths))
    per_node = np.zeros(points.shape[1])
    for end, share in zip(ends, shares):
        np.add.at(per_node, end, share)
    return per_node


def contact_weights(mesh: Any, facets: np.ndarray, nodes: np.ndarray,
                    axisymmetric: bool = False) -> np.ndarray:
    """Lumped weights ``wᵢ = ∫_Γ φᵢ ds`` (``∫_Γ φᵢ r ds`` when axisymmetric) of ``nodes``.

    In closed form per boundary facet: on 2D meshes per edge (:func:`segment_weights`), in 3D
    per triangle of area A ``A/3`` to each corner (scikit-fem's facet quadrature gives the same
    to round-off, 25 times slower at 1M dofs).
    """
    if mesh.p.shape[0] == 2:
        return segment_weights(mesh.p, mesh.facets[:, facets], axisymmetric)[nodes]
    corners = mesh.facets[:, facets]  # (3, k)
    edges = mesh.p[:, corners[1:]] - mesh.p[:, corners[:1]]  # (3, 2, k)
    area = 0.5 * np.linalg.norm(np.cross(edges[:, 0], edges[:, 1], axis=0), axis=0)
    per_node = np.bincount(corners.ravel(), np.tile(area / 3.0, 3), minlength=mesh.p.shape[1])
    return per_node[nodes]


def stiffness_form(model: SceneModel, Lambda: float, Mu: float) -> BilinearForm:
    """The elastic bilinear form of ``model``: plane strain or 3D, or axisymmetric."""
    if model.axisymmetric:
        if model.mesh.p.shape[0] != 2:
            raise InputError("an axisymmetric scene needs a 2D mesh in (r, z)")
        if np.min(model.mesh.p[0]) < -1e-12 * model.length_scale:
            raise InputError("an axisymmetric mesh must lie in r >= 0")
        return axisymmetric_elasticity(Lambda, Mu)
    return linear_elasticity(Lambda, Mu)


def stiffness(model: SceneModel, mesh: Any, E: float) -> sp.csr_matrix:
    """K of the whole mesh (no boundary conditions), dofs interleaved by node.

    With ``model.volumetric == "nodal"`` the λ-part averages the volumetric
    strain at the nodes (:mod:`signorini.fem.volumetric`: P1 without locking).
    """
    stiffness_form(model, 1.0, 1.0)  # the model's checks
    return lame_stiffness(mesh, *lame_parameters(E, model.nu), axisymmetric=model.axisymmetric,
                          volumetric=model.volumetric)


def lame_stiffness(mesh: Any, Lambda: float, Mu: float, *, axisymmetric: bool = False,
                   volumetric: str = "element") -> sp.csr_matrix:
    """``K = Λ K_Λ + μ K_μ`` of the whole mesh, for Lamé parameters ``Λ`` and ``μ``.

    K is linear in the pair, so ``lame_stiffness(mesh, 1, 0)`` and
    ``lame_stiffness(mesh, 0, 1)`` are its two parts (what ∂K/∂ν is made of).
    """
    if volumetric == "nodal":
        return (_elastic_stiffness(mesh, 0.0, Mu, axisymmetric)
                + volumetric_stiffness(mesh, Lambda, axisymmetric)).tocsr()
    return _elastic_stiffness(mesh, Lambda, Mu, axisymmetric)


def _elastic_stiffness(mesh: Any, Lambda: float, Mu: float, axisymmetric: bool) -> sp.csr_matrix:
    if mesh.t.shape[0] == mesh.p.shape[0] + 1 and (mesh.p.shape[0] == 2 or not axisymmetric):
        return simplex_stiffness(mesh, Lambda, Mu, axisymmetric)  # triangles or tetrahedra
    basis = Basis(mesh, ElementVector(mesh.elem()))
    form = axisymmetric_elasticity(Lambda, Mu) if axisymmetric else linear_elasticity(Lambda, Mu)
    return asm(form, basis).tocsr()


def nodal_dofs(mesh: Any) -> np.ndarray:
    """(dim, nodes) dof numbers of vector P1: interleaved, as scikit-fem numbers them."""
    dim, count = mesh.p.shape
    return np.arange(dim * count).reshape(count, dim).T


def force_exponent(model: SceneModel) -> int:
    """k in ``force = E·U·L^k``, ``weight = L^(k+1)``: 0 in plane strain, 1 axisymmetric or 3D."""
    return 1 if (model.axisymmetric or model.mesh.p.shape[0] == 3) else 0


def displacement_scale(model: SceneModel) -> float:
    """The largest prescribed displacement, else the largest initial gap, else the length."""
    largest = max((abs(value) for _, nodes, value in model.dirichlet if len(nodes)), default=0.0)
    if largest == 0.0:
        _, gaps = model.obstacle.normals_and_gaps(model.mesh.p[:, model.contact_nodes].T)
        largest = float(np.max(np.abs(gaps))) if len(gaps) else 0.0
    return largest if largest > 0 else model.length_scale


def assemble(model: SceneModel, nondimensionalise: bool = True) -> ContactProblem:
    """The contact QP of ``model`` at its nominal push: K, f, N, d, weights, points, scales.

    Pure linear algebra: no contact is solved here. A scene with a target
    load gets a problem whose target is pending (``problem.model.pending``): f and
    d are at the nominal push, and load control (:mod:`signorini.load_control`)
    finds the push whose load is the target, from ``problem.model.push``.
    """
    start = time.perf_counter()
    log.info("assembling K: %s nodes, %s elements", f"{model.mesh.p.shape[1]:,}",
             f"{model.mesh.t.shape[1]:,}")
    L = model.length_scale if nondimensionalise else 1.0
    stress = model.E if nondimensionalise else 1.0
    U = displacement_scale(model) if nondimensionalise else 1.0
    axisymmetric = bool(model.axisymmetric)
    k = force_exponent(model)
    force_unit = stress * U * L ** k
    mesh = moved(model.mesh, model.mesh.p / L)  # its facets kept: no second search for them
    dim = mesh.p.shape[0]
    dof_table = nodal_dofs(mesh)
    K_full = stiffness(model, mesh, model.E / stress)
    n_full = K_full.shape[0]

    prescribed = np.zeros(n_full)
    fixed = []
    for component, nodes, value in model.dirichlet:
        dofs = dof_table[component, nodes]
        prescribed[dofs] = value / U
        fixed.append(dofs)
    fixed = np.unique(np.concatenate(fixed))
    is_free = np.ones(n_full, dtype=bool)
    is_free[fixed] = False
    free = np.flatnonzero(is_free)

    nodes = model.contact_nodes
    # the obstacle is asked at physical coordinates and answers physical gaps
    normals, gaps = model.obstacle.normals_and_gaps(model.mesh.p[:, nodes].T)
    gaps = gaps / U
    m = len(nodes)
    rows = np.repeat(np.arange(m), dim)
    cols = dof_table[:, nodes].T.ravel()
    N_full = sp.csr_matrix((normals.ravel(), (rows, cols)), shape=(m, n_full))

    component, load_nodes = model.load_dofs
    load_dofs = dof_table[component, load_nodes]
    # applied load = −Σ reactions on the loaded dofs (a push towards the obstacle is positive)
    load_full = -model.force_multiplicity * np.asarray(K_full[load_dofs].sum(axis=0)).ravel()

    K_free = K_full[free]  # the free rows, once: then their free columns
    K_II = K_free[:, free]
    N_free = N_full[:, free].tocsr()
    target = None if model.target_load is None else model.target_load / force_unit
    f_load, offset_load = cut_traction(model, mesh, dof_table, load_dofs)
    if f_load is not None and target is None:
        raise InputError("a load applied on a cut needs a target load: give P (or a_over_R)")

    def lifted(scale: float) -> tuple[np.ndarray, np.ndarray, float, np.ndarray]:
        u_D = prescribed[fixed] * scale
        full = np.zeros(n_full)
        full[fixed] = u_D
        f = -(K_free @ full)  # K_ID u_D, the same sums: the free columns add exact zeros
        offset = float(load_full[fixed] @ u_D)
        if f_load is not None:  # the traction of the target load (fixed while the push varies)
            f = f + target * f_load[free]
            offset += target * offset_load
        return f, gaps - N_full[:, fixed] @ u_D, offset, full

    f, d, load_offset, full = lifted(1.0)
    params = dict(model.params, volumetric=model.volumetric)  # auto resolved: what K integrates
    delta = model.delta
    if model.target_load is not None:  # the nominal push that load control scales
        delta = params["delta"] = -min(v for c, _, v in model.dirichlet if c == model.load_dofs[0])
    made = Model(
        mesh=mesh, free_dofs=free, prescribed=full, load_row=load_full[free],
        load_offset=load_offset, E=float(model.E), nu=float(model.nu),
        volumetric=model.volumetric, axisymmetric=axisymmetric, reference=model.reference,
        params=params,
        push=_push(lifted, 1.0, None if f_load is None else f_load[free], offset_load, target,
                   _resultant(N_full, np.sort(dof_table[component][is_free[dof_table[component]]])),
                   delta=delta, P=model.target_load),
        predicted_contact=model.predicted_contact, watch=boundary_watch(model, dof_table, U),
        pending=target is not None)
    problem = ContactProblem(
        K=K_II, f=f, N=N_free, d=d, weights=contact_weights(mesh, model.contact_facets, nodes,
                                                            axisymmetric),
        contact_points=mesh.p[:, nodes].T, force_multiplicity=model.force_multiplicity,
        scales=Scales(length=L, displacement=U, force=force_unit, weight=L ** (k + 1)),
        model=made)
    made.assemble_s = time.perf_counter() - start
    log.info("assembled %d free dofs, %d contact candidates in %.2f s",
             problem.n, problem.m, made.assemble_s)
    return problem


def cut_traction(model: SceneModel, mesh: Any, dof_table: np.ndarray,
                 load_dofs: np.ndarray) -> tuple[np.ndarray | None, float]:
    """Nodal forces of the cut's uniform traction per unit load of the full body, and its offset.

    The traction is ``1 / (μ A)`` with A the cut's area (``∫ r ds`` per radian
    in axisymmetric models), pointing towards the obstacle; its consistent
    nodal forces are the cut's lumped weights times it (exact for P1 and a
    uniform traction). The offset is the part of the load that the load
    dofs' reactions do not see: the traction on every other node.
    """
    cut = model.cut_load
    if cut is None:
        return None, 0.0
    weights = contact_weights(mesh, cut.facets, cut.nodes, bool(model.axisymmetric))
    if not weights.sum() > 0:
        raise InputError("the loaded cut has no area: check the scene's cut facets")
    return cut_forces(weights, dof_table[cut.component, cut.nodes], -1.0, model.force_multiplicity,
                      load_dofs, dof_table.size)


def cut_forces(weights: np.ndarray, dofs: np.ndarray, direction: float, multiplicity: float,
               load_dofs: np.ndarray, size: int) -> tuple[np.ndarray, float]:
    """Nodal forces (``size`` dofs) of a uniform traction along ``direction`` (±1) on a cut whose
    nodes have the lumped weights ``weights`` and the ``dofs`` along it, per unit load of the
    full body (``multiplicity`` copies of the model), and the part of that load the reactions
    of ``load_dofs`` do not see: the traction on the cut's other nodes."""
    f_load = np.zeros(size)
    f_load[dofs] = direction * weights / (multiplicity * weights.sum())
    others = ~np.isin(dofs, load_dofs)
    return f_load, float(multiplicity * direction * f_load[dofs[others]].sum())


def boundary_watch(model: SceneModel, dof_table: np.ndarray, U: float) -> Watch | None:
    """The boundary nodes beyond the candidates and the candidates at their edge (see Watch).

    Gaps are asked of the obstacle at the physical coordinates (a scene-unit
    wrapper is unwrapped); an obstacle that cannot answer there leaves the
    problem unwatched.
    """
    mesh = model.mesh
    facets = mesh.boundary_facets()
    nodes = np.unique(mesh.facets[:, facets])
    watched = np.setdiff1d(nodes, model.contact_nodes)
    obstacle = getattr(model.obstacle, "obstacle", model.obstacle)
    try:
        normals, gaps = obstacle.normals_and_gaps(mesh.p[:, watched].T)
        _, candidate_gaps = obstacle.normals_and_gaps(mesh.p[:, model.contact_nodes].T)
    except (ValueError, TypeError):
        return None
    dim = mesh.p.shape[0]
    rows = sp.csr_matrix((np.asarray(normals, dtype=float).ravel(),
                          (np.repeat(np.arange(len(watched)), dim), dof_table[:, watched].T.ravel())),
                         shape=(len(watched), dof_table.size))
    # candidates on a facet that faces the obstacle and reaches a node beyond the candidates
    is_candidate = np.zeros(mesh.p.shape[1], dtype=bool)
    is_candidate[model.contact_nodes] = True
    ends = mesh.facets[:, facets]
    mixed = is_candidate[ends].any(axis=0) & ~is_candidate[ends].all(axis=0)
    edge_nodes = np.array([], dtype=int)
    if mixed.any():
        outward = outward_normals(mesh, facets[mixed])
        towards, _ = obstacle.normals_and_gaps(mesh.p[:, ends[:, mixed]].mean(axis=1).T)
        facing = np.einsum("ij,ji->i", np.asarray(towards, dtype=float), outward) > 0.1
        edge_nodes = np.unique(ends[:, mixed][:, facing])
    edge = np.nonzero(np.isin(model.contact_nodes, edge_nodes))[0]
    return Watch(rows=rows, gaps=np.asarray(gaps, dtype=float) / U, edge=edge,
                 candidate_gaps=np.asarray(candidate_gaps, dtype=float) / U,
                 remedy=model.candidate_remedy, nodes=watched)


def _resultant(N_full: sp.csr_matrix, axis_dofs: np.ndarray) -> np.ndarray | None:
    """Each candidate's share of the contact resultant along the push axis, ``cᵢ = −nᵢ·e``
    (the free dofs ``axis_dofs`` of that axis); None when every ``cᵢ`` is exactly 1 (a flat
    obstacle across the push: the resultant is ``Σλ``)."""
    weights = -np.asarray(N_full[:, axis_dofs].sum(axis=1)).ravel()
    return None if np.all(weights == 1.0) else weights


def _push(lifted, scale: float, f_load: np.ndarray | None, offset_load: float,
          load: float | None, resultant: np.ndarray | None, *, delta: float | None = None,
          P: float | None = None) -> Push:
    """How f, d and the load offset depend on the push and the load (they are affine in both);
    ``delta`` and ``P`` are the push and the target load in the scene's units."""
    f0, d0, offset0, _ = lifted(0.0)
    f1, d_one, offset_one, _ = lifted(1.0)
    return Push(f1=f1 - f0, d0=d0, d1=d_one - d0, offset1=offset_one - offset0, scale=scale,
                f_load=f_load, offset_load=offset_load if f_load is not None else 0.0,
                load=load if f_load is not None else 0.0, target=load,
                resultant=resultant, delta=delta, P=P)


__all__ = ["axisymmetric_elasticity", "contact_weights", "cut_forces", "segment_weights", "stiffness_form",
           "stiffness", "lame_stiffness", "nodal_dofs", "force_exponent", "displacement_scale",
           "assemble", "cut_traction", "boundary_watch"]
