"""P1 fields from a mesh to its refinement: every new node is the midpoint of an old edge.

Uniform refinement (:func:`signorini.scenes.meshing.refine_uniformly`) and
scikit-fem's conforming ``MeshTri.refined(marked)`` both add nodes at edge
midpoints after the old ones, so a P1 field moves to the finer mesh by
averaging each new node's two parents. Nodes later moved onto a curved
boundary keep that average (the coarse field carried along with the node).
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any

import numpy as np
import scipy.sparse as sp

from signorini.fem.obstacles import ScaledQuery
from signorini.fem.topology import edge_keys, facets_on


def split_uniformly(t: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    """One uniform refinement of the triangles ``t`` over ``n`` nodes: the parents (2, edges) of
    the nodes it adds, edge k in sorted key order becoming node ``n + k``, and the triangles
    (children at the edge midpoints), from one sort of integer edge keys."""
    keys = np.concatenate([edge_keys(t[i], t[j], n) for i, j in ((0, 1), (1, 2), (2, 0))])
    edges, inverse = np.unique(keys, return_inverse=True)
    m01, m12, m20 = n + inverse.reshape(3, -1)  # midpoint of edges 01, 12, 20 of each triangle
    return np.array([edges // n, edges % n]), np.hstack([
        np.vstack([t[0], m01, m20]), np.vstack([t[1], m12, m01]),
        np.vstack([t[2], m20, m12]), np.vstack([m01, m12, m20])])


def prolongation(n_old: int, parents: np.ndarray) -> sp.csr_matrix:
    """The (n_old + k) × n_old matrix that keeps old nodal values and averages each new node's
    two ``parents`` (2, k)."""
    k = parents.shape[1]
    rows = np.concatenate([np.arange(n_old), np.repeat(n_old + np.arange(k), 2)])
    cols = np.concatenate([np.arange(n_old), parents.T.ravel()])
    values = np.concatenate([np.ones(n_old), np.full(2 * k, 0.5)])
    return sp.csr_matrix((values, (rows, cols)), shape=(n_old + k, n_old))


def uniform_prolongation(t: np.ndarray, n: int, times: int = 1) -> sp.csr_matrix:
    """The prolongation of ``times`` uniform refinements of the triangles ``t`` over ``n`` nodes."""
    P = sp.identity(n, format="csr")
    for _ in range(times):
        parents, t = split_uniformly(t, n)
        step = prolongation(n, parents)
        P = step @ P
        n = step.shape[0]
    return P


# --- a scene's model carried onto a refinement of its mesh --------------------------------------


def boundary_children(old: Any, new: Any) -> tuple[np.ndarray, np.ndarray]:
    """The new nodes of ``new`` (a conforming refinement of the 2D mesh ``old``) that lie on an
    old boundary facet, and that facet's two ends (2, k)."""
    from scipy.spatial import cKDTree  # on use: scipy.spatial is slow to import

    n_old = old.p.shape[1]
    fresh = np.arange(n_old, new.p.shape[1])
    ends = old.facets[:, old.boundary_facets()]
    if fresh.size == 0 or ends.size == 0:
        return np.zeros(0, dtype=np.int64), np.zeros((2, 0), dtype=np.int64)
    middles = 0.5 * (old.p[:, ends[0]] + old.p[:, ends[1]])
    distance, index = cKDTree(middles.T).query(new.p[:, fresh].T)
    on = distance <= 1e-9 * max(float(np.max(np.abs(old.p))), 1e-300)
    return fresh[on], ends[:, index[on]]


def extend_nodes(nodes: np.ndarray, n_old: int, children: np.ndarray, parents: np.ndarray) -> np.ndarray:
    """``nodes`` (of the old mesh) and the new boundary nodes both of whose parents are among
    them, in the old order with each new node after the earlier of its parents."""
    member = np.zeros(n_old, dtype=bool)
    member[nodes] = True
    inside = member[parents].all(axis=0)
    if not inside.any():
        return np.asarray(nodes)
    position = np.full(n_old, -1)
    position[nodes] = np.arange(len(nodes))
    after = np.minimum(*position[parents[:, inside]]) + 0.5
    order = np.argsort(np.concatenate([np.arange(len(nodes), dtype=float), after]), kind="stable")
    return np.concatenate([nodes, children[inside]])[order]


def refined_model(model: Any, mesh: Any, in_contact: np.ndarray | None = None,
                  snap: Any = None) -> Any:
    """``model`` (a :class:`signorini.fem.model.SceneModel`) on ``mesh``, a conforming refinement
    of its 2D mesh (old nodes keep their numbers, new ones are edge midpoints).

    Every node set — prescribed displacements, contact candidates, load dofs,
    a loaded cut — takes the new boundary nodes between two of its nodes;
    contact facets and the cut's facets are the new boundary facets within
    their node sets. ``in_contact`` (per old candidate) marks where load
    targeting starts on the new mesh (a new candidate between two in
    contact). ``snap`` (a function of a mesh) then moves nodes onto a curved
    boundary; an obstacle that answers at the candidates only
    (:class:`signorini.fem.obstacles.ScaledQuery`) is asked at their new places.
    """
    old, n_old = model.mesh, model.mesh.p.shape[1]
    children, parents = boundary_children(old, mesh)

    def extend(nodes: np.ndarray) -> np.ndarray:
        return extend_nodes(np.asarray(nodes), n_old, children, parents)

    candidates = extend(model.contact_nodes)
    on_contact_facets = extend(np.unique(old.facets[:, model.contact_facets]))
    if snap is not None:
        mesh = snap(mesh)
    changes: dict[str, Any] = {
        "mesh": mesh, "contact_nodes": candidates,
        "contact_facets": facets_on(mesh, on_contact_facets),
        "dirichlet": [(c, extend(nodes), value) for c, nodes, value in model.dirichlet],
        "load_dofs": (model.load_dofs[0], extend(model.load_dofs[1])),
    }
    _ask_at(changes, model.obstacle, mesh, candidates)
    if model.cut_load is not None:
        nodes = extend(model.cut_load.nodes)
        changes["cut_load"] = replace(model.cut_load, nodes=nodes, facets=facets_on(mesh, nodes))
    if in_contact is not None:
        touching = extend(np.asarray(model.contact_nodes)[np.asarray(in_contact, dtype=bool)])
        changes["predicted_contact"] = np.isin(candidates, touching)
    return replace(model, **changes)


def _ask_at(changes: dict[str, Any], obstacle: Any, mesh: Any, candidates: np.ndarray) -> None:
    """An obstacle that answers at the candidates only, asked at their (new) places."""
    if isinstance(obstacle, ScaledQuery):
        changes["obstacle"] = replace(obstacle, physical_points=mesh.p[:, candidates].T)


def with_candidates(model: Any, extra: np.ndarray, in_contact: np.ndarray | None = None) -> Any:
    """``model`` with the boundary nodes ``extra`` as contact candidates too, and the boundary
    facets that reach them as contact facets (their weights). Candidates sorted along x stay
    sorted; ``in_contact`` (per old candidate) marks where load targeting starts."""
    mesh, old = model.mesh, np.asarray(model.contact_nodes)
    extra = np.setdiff1d(extra, old)
    candidates = np.concatenate([old, extra])
    if np.all(np.diff(mesh.p[0, old]) >= 0):
        candidates = candidates[np.argsort(mesh.p[0, candidates], kind="stable")]
    facets = mesh.boundary_facets()
    reaching = np.isin(mesh.facets[:, facets], extra).any(axis=0)
    changes: dict[str, Any] = {"contact_nodes": candidates,
                               "contact_facets": np.union1d(model.contact_facets, facets[reaching])}
    _ask_at(changes, model.obstacle, mesh, candidates)
    if in_contact is not None:
        changes["predicted_contact"] = np.isin(candidates, old[np.asarray(in_contact, dtype=bool)])
    return replace(model, **changes)


__all__ = ["split_uniformly", "prolongation", "uniform_prolongation",
           "boundary_children", "extend_nodes", "refined_model", "with_candidates"]
