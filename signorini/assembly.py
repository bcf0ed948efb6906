"""Scene → :class:`ContactProblem`: stiffness, load, gap rows, weights and scales.

The elastic form is scikit-fem's ``linear_elasticity`` with plane-strain Lamé
parameters. Prescribed dofs are condensed out (``K_II u_I = f_I − K_ID u_D``),
one gap row per contact candidate node is ``nᵢ · uᵢ ≤ gᵢ`` with ``nᵢ`` the
body's outward normal towards the obstacle. With ``nondimensionalise`` the
mesh is divided by the scene's length L and E by itself, so every solver sees
numbers of order one whatever the user's units: coordinates are divided by
the scene's length L, displacements and gaps by a displacement scale U (the
largest prescribed displacement, else the largest initial gap), E by itself;
contact forces then come in units of E·U (per unit thickness).
"""

from __future__ import annotations

import logging
import time
from typing import Any

import numpy as np
import scipy.sparse as sp
from scipy.optimize import brentq
from skfem import Basis, ElementTriP1, ElementVector, asm
from skfem.models.elasticity import lame_parameters, linear_elasticity

from .condensed import delassus, solve_lcp
from .errors import InputError
from .linalg import factorize
from .problem import ContactProblem, Scales
from .scenes.base import SceneModel

log = logging.getLogger(__name__)


def boundary_weights(mesh: Any, facets: np.ndarray, nodes: np.ndarray) -> np.ndarray:
    """Lumped weights ``wᵢ = ∫_Γ φᵢ ds`` of ``nodes`` over the boundary ``facets`` (2D)."""
    ends = mesh.facets[:, facets]
    lengths = np.linalg.norm(mesh.p[:, ends[0]] - mesh.p[:, ends[1]], axis=0)
    per_node = np.zeros(mesh.p.shape[1])
    np.add.at(per_node, ends[0], 0.5 * lengths)
    np.add.at(per_node, ends[1], 0.5 * lengths)
    return per_node[nodes]


def displacement_scale(model: SceneModel) -> float:
    """The largest prescribed displacement, else the largest initial gap, else the length."""
    largest = max((abs(value) for _, nodes, value in model.dirichlet if len(nodes)), default=0.0)
    if largest == 0.0:
        _, gaps = model.obstacle.normals_and_gaps(model.mesh.p[:, model.contact_nodes].T)
        largest = float(np.max(np.abs(gaps))) if len(gaps) else 0.0
    return largest if largest > 0 else model.length_scale


def assemble(model: SceneModel, nondimensionalise: bool = True) -> ContactProblem:
    """Assemble the contact QP of ``model``; adjust δ first when a target load is set."""
    start = time.perf_counter()
    L = model.length_scale if nondimensionalise else 1.0
    stress = model.E if nondimensionalise else 1.0
    U = displacement_scale(model) if nondimensionalise else 1.0
    mesh = type(model.mesh)(model.mesh.p / L, model.mesh.t)
    basis = Basis(mesh, ElementVector(ElementTriP1()))
    K_full = asm(linear_elasticity(*lame_parameters(model.E / stress, model.nu)), basis).tocsr()
    n_full = K_full.shape[0]

    prescribed = np.zeros(n_full)
    fixed = []
    for component, nodes, value in model.dirichlet:
        dofs = basis.nodal_dofs[component, nodes]
        prescribed[dofs] = value / U
        fixed.append(dofs)
    fixed = np.unique(np.concatenate(fixed))
    free = np.setdiff1d(np.arange(n_full), fixed)

    nodes = model.contact_nodes
    normals, gaps = model.obstacle.normals_and_gaps(mesh.p[:, nodes].T)
    gaps = gaps * (L / U)
    m = len(nodes)
    rows = np.repeat(np.arange(m), 2)
    cols = basis.nodal_dofs[:, nodes].T.ravel()
    N_full = sp.csr_matrix((normals.ravel(), (rows, cols)), shape=(m, n_full))

    component, load_nodes = model.load_dofs
    load_dofs = basis.nodal_dofs[component, load_nodes]
    # applied load = −Σ reactions on the loaded dofs (a push towards the obstacle is positive)
    load_full = -model.force_multiplicity * np.asarray(K_full[load_dofs].sum(axis=0)).ravel()

    K_II = K_full[free][:, free].tocsr()
    K_ID = K_full[free][:, fixed]
    N_free = N_full[:, free].tocsr()

    def lifted(scale: float) -> tuple[np.ndarray, np.ndarray, float, np.ndarray]:
        u_D = prescribed[fixed] * scale
        full = np.zeros(n_full)
        full[fixed] = u_D
        return -(K_ID @ u_D), gaps - N_full[:, fixed] @ u_D, float(load_full[fixed] @ u_D), full

    scale = 1.0
    if model.target_load is not None:
        scale = _calibrate(K_II, N_free, lifted, model.target_load / (stress * U),
                           model.force_multiplicity)
    f, d, load_offset, full = lifted(scale)
    params = dict(model.params)
    if model.target_load is not None:
        delta_nominal = -min(v for c, _, v in model.dirichlet if c == model.load_dofs[0])
        params["delta"] = delta_nominal * scale
    weights = boundary_weights(mesh, model.contact_facets, nodes)
    problem = ContactProblem(
        K=K_II, f=f, N=N_free, d=d, weights=weights, contact_points=mesh.p[:, nodes].T,
        free_dofs=free, prescribed=full, load_row=load_full[free], load_offset=load_offset,
        force_multiplicity=model.force_multiplicity,
        scales=Scales(length=L, displacement=U, force=stress * U, weight=L),
        params=params, mesh=mesh)
    problem.basis = basis
    problem.assemble_time = time.perf_counter() - start
    log.info("assembled %d free dofs, %d contact candidates in %.2f s",
             problem.n, problem.m, problem.assemble_time)
    return problem


def _calibrate(K: sp.csr_matrix, N: sp.csr_matrix, lifted, target: float,
               multiplicity: float) -> float:
    """The factor on the prescribed displacement whose contact force is ``target``.

    The force is increasing in the factor; each trial is an exact condensed
    solve (one factorisation and one Delassus operator for all trials).
    """
    if not np.isfinite(target) or target <= 0:
        raise InputError(f"the target load must be positive, got {target:g}")
    factor = factorize(K)
    W, K_inv_NT = delassus(N, factor)

    def force(scale: float) -> float:
        f, d, _, _ = lifted(scale)
        lam, _ = solve_lcp(W, N @ factor.solve(f) - d)
        return multiplicity * float(lam.sum())

    upper = 1.0
    for _ in range(60):
        if force(upper) >= target:
            break
        upper *= 2.0
    else:
        raise InputError("the target load cannot be reached by pushing the body onto the obstacle")
    lower = upper / 2.0
    while force(lower) > target and lower > 1e-12:
        lower /= 2.0
    return brentq(lambda s: force(s) - target, lower, upper, xtol=1e-14, rtol=1e-12)
