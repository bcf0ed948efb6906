"""The contact's parts of the a posteriori estimate (:mod:`signorini.fem.estimate`).

**Contact term.** P1 contact holds the Signorini conditions at the nodes only:
on an edge of the contact boundary from an active node (pressure p > 0, gap
0) to an inactive one (p = 0, gap g > 0) the interpolated pressure and gap
are both positive, and ``∫ p_h g_h ds`` is the energy this mismatch carries.
It is the complementarity term of the residual estimators for Signorini
contact (the term ``∫_Γc λ_h u_hn`` in P. Hild, S. Nicaise, "Residual a
posteriori error estimators for contact problems in elasticity", M2AN 41
(2007) 897–923, written with the gap). It is non-zero only on the edges at
the edge of the contact zone; :func:`contact_term` gives it per edge (2D models), and
:func:`signorini.fem.estimate.estimate` adds it to the element that holds the edge. docs/estimate.md
measures what each part contributes and the estimate's effectivity.

The contact pressure's own estimate (:class:`PressureEstimate`) compares the
multipliers' pressure with the traction of the recovered stress at the candidates.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from signorini.fem.topology import facets_on, outward_normals
from signorini.certification.kkt import active_set
from signorini.problem.contact import ContactProblem, ContactSolution

__all__ = ["PressureEstimate", "boundary_normals", "candidate_edges", "candidate_nodes",
           "contact_term", "pressure_estimate", "unit_normals", "zone_and_neighbours"]


def candidate_nodes(mesh: Any, points: np.ndarray) -> np.ndarray:
    """The mesh node at each contact point (matched by coordinates; ValueError if one is not).

    A built problem's points are its nodes' own coordinates: they are found by sorting the
    nodes. Points that only lie near nodes are matched by a k-d tree within a relative 1e-9.
    """
    nodes = _same_coordinates(mesh.p, points)
    if nodes is not None:
        return nodes
    from scipy.spatial import cKDTree  # on use: scipy.spatial is slow to import

    distance, nodes = cKDTree(mesh.p.T).query(points)
    if np.any(distance > 1e-9 * max(1.0, float(np.max(np.abs(mesh.p))))):
        raise ValueError("a contact candidate is not a mesh node")
    return nodes


def _same_coordinates(p: np.ndarray, points: np.ndarray) -> np.ndarray | None:
    """The column of ``p`` (dim, n) equal to each row of ``points`` (m, dim); None unless all are."""
    dim = p.shape[0]
    points = np.atleast_2d(np.asarray(points, dtype=float))
    if points.shape[1] != dim or p.shape[1] == 0 or points.shape[0] == 0:
        return None
    # only the nodes whose first coordinate is one of the points' can match: sort those alone
    firsts = np.sort(points[:, 0])  # searched, not merged: np.isin would sort every node's too
    near = np.flatnonzero(firsts[np.minimum(np.searchsorted(firsts, p[0]), firsts.size - 1)] == p[0])
    if near.size == 0:
        return None
    row = [("", np.float64)] * dim  # one record per node: records sort and compare by coordinate
    nodes = np.ascontiguousarray(p[:, near].T, dtype=np.float64).view(row).ravel()
    wanted = np.ascontiguousarray(points).view(row).ravel()
    order = np.argsort(nodes, kind="stable")
    at = np.minimum(np.searchsorted(nodes[order], wanted), nodes.size - 1)
    return near[order[at]] if np.all(nodes[order[at]] == wanted) else None


def candidate_edges(mesh: Any, nodes: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The boundary facets of a 2D mesh joining two candidates: facet numbers, their end nodes
    (2, k) and the ends' positions in ``nodes`` (2, k)."""
    facets = facets_on(mesh, nodes)
    ends = mesh.facets[:, facets]
    local = np.full(mesh.p.shape[1], -1)
    local[nodes] = np.arange(len(nodes))
    return facets, ends, local[ends]


def zone_and_neighbours(mesh: Any, nodes: np.ndarray, active: np.ndarray) -> np.ndarray:
    """Candidates in contact (``active``) and those sharing a boundary edge with one (2D)."""
    _, _, (a, b) = candidate_edges(mesh, nodes)
    counted = active.copy()
    counted[a[active[b]]] = True
    counted[b[active[a]]] = True
    return counted


def contact_term(mesh: Any, nodes: np.ndarray, pressure: np.ndarray, gap: np.ndarray,
                 axisymmetric: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """``∫_E p_h g_h ds`` (``× r`` axisymmetric) on the boundary edges between two candidates.

    ``nodes`` are the candidates' mesh nodes, ``pressure`` and ``gap`` their
    nodal values, interpolated linearly along each edge (negative parts cut:
    the term measures where both are positive). Returns the edges' elements
    and the integrals (three-point Gauss, exact for the cubic integrand).
    2D meshes only; 3D models get no contact term.
    """
    if mesh.p.shape[0] != 2:
        return np.zeros(0, dtype=int), np.zeros(0)
    facets, ends, (a, b) = candidate_edges(mesh, nodes)
    pa, pb = np.maximum(pressure[a], 0.0), np.maximum(pressure[b], 0.0)
    ga, gb = np.maximum(gap[a], 0.0), np.maximum(gap[b], 0.0)
    length = np.linalg.norm(mesh.p[:, ends[1]] - mesh.p[:, ends[0]], axis=0)
    s = 0.5 + np.array([-1.0, 0.0, 1.0]) * 0.5 * np.sqrt(0.6)
    w = np.array([5.0, 8.0, 5.0]) / 18.0
    integrand = ((1 - s)[:, None] * pa + s[:, None] * pb) * ((1 - s)[:, None] * ga + s[:, None] * gb)
    if axisymmetric:
        r = mesh.p[0]
        integrand = integrand * ((1 - s)[:, None] * r[ends[0]] + s[:, None] * r[ends[1]])
    return mesh.f2t[0, facets], length * (w @ integrand)



@dataclass(frozen=True)
class PressureEstimate:
    """The contact pressure's error, estimated by the stress the body carries at its contact.

    At the exact solution the normal stress at the contact boundary is minus
    the pressure; the discrete solution has two pressures — ``p_h = λ / w``
    from the multipliers and ``p* = −σ*_n`` from ZZ's recovered stress at the
    candidate nodes — and their distance estimates the error of the pressure
    (the term ``‖λ_h + σ_n(u_h)‖`` of Hild & Nicaise's residual estimator, with
    the recovered stress in place of the element stress).
    ``relative = (Σ w (p_h − p*)² / Σ w p_h²)^½`` (``w`` the contact weights)
    over the candidates in contact and their first free neighbours along the
    boundary (``counted``): further out the exact and the discrete pressure
    are both zero — the contact zone's edge lies between the last node in
    contact and the first free one — and what the recovered stress carries
    there is the recovery's smearing of the edge, not an error of the
    pressure (counted, it overstates the error: docs/estimate.md). ``nodes`` are the candidates' mesh
    nodes, ``active`` those in contact, ``indicators`` their shares
    ``w (p_h − p*)²`` of the numerator (zero where not counted).
    """

    relative: float
    nodes: np.ndarray
    indicators: np.ndarray
    active: np.ndarray


def unit_normals(problem: ContactProblem, dim: int) -> np.ndarray:
    """(m, dim): each candidate's gap direction, read from its row of N (unit length)."""
    N = problem.N.tocsr()
    normals = np.zeros((problem.m, dim))
    rows = np.repeat(np.arange(problem.m), np.diff(N.indptr))
    full = problem.model.free_dofs[N.indices]
    np.add.at(normals, (rows, full % dim), N.data)
    length = np.linalg.norm(normals, axis=1)
    return normals / np.where(length > 0, length, 1.0)[:, None]


def boundary_normals(mesh: Any, nodes: np.ndarray) -> np.ndarray:
    """(2, len(nodes)): the body's outward unit normal at ``nodes``, from the boundary edges
    joining two of them (a corner's other edges, e.g. on a symmetry axis, do not count)."""
    facets, ends, _ = candidate_edges(mesh, nodes)
    normal = outward_normals(mesh, facets, unit=False)  # as long as its edge: a longer one weighs more
    summed = np.zeros((2, mesh.p.shape[1]))
    for end in ends:
        np.add.at(summed.T, end, normal.T)
    summed = summed[:, nodes]
    length = np.linalg.norm(summed, axis=0)
    return summed / np.where(length > 0, length, 1.0)


def pressure_estimate(problem: ContactProblem, solution: ContactSolution, nodal: np.ndarray,
                      Lambda: float, Mu: float,
                      nodal_trace: np.ndarray | None = None) -> PressureEstimate | None:
    """:class:`PressureEstimate` from the recovered nodal strain ``nodal`` (2D models, None else).

    ``p*`` is the traction ``σ* ν`` on the body's curved boundary (outward
    normal ν) along the obstacle's normal — the direction of N's row: on
    Hertz's cylinder at x = 0.7 a, taking ν as the obstacle's normal instead
    biases p* by about 0.2 % of p₀ for any mesh (docs/estimate.md). ``nodal_trace`` is the
    volumetric strain at the nodes when K averages it there (else the recovered strain's trace).
    """
    mesh, dim = problem.model.mesh, problem.model.mesh.p.shape[0]
    if dim != 2 or problem.weights is None or not np.all(np.isfinite(solution.lam)):
        return None
    try:
        nodes = candidate_nodes(mesh, problem.contact_points)
    except ValueError:
        return None
    e = nodal[:, nodes]
    trace = e[0] + e[1] + (e[3] if len(e) > 3 else 0.0) if nodal_trace is None else nodal_trace[nodes]
    sxx, syy, sxy = Lambda * trace + 2.0 * Mu * e[0], Lambda * trace + 2.0 * Mu * e[1], 2.0 * Mu * e[2]
    nu = boundary_normals(mesh, nodes)
    towards = unit_normals(problem, dim).T  # the obstacle's normal, from the body to the obstacle
    traction = np.array([sxx * nu[0] + sxy * nu[1], sxy * nu[0] + syy * nu[1]])
    recovered = -np.sum(traction * towards, axis=0) * np.sign(np.sum(nu * towards, axis=0))
    w = problem.weights
    discrete = solution.lam / w
    scale = float(np.sum(w * discrete ** 2))
    if scale <= 0:
        return None
    active = active_set(problem, solution)
    shares = np.where(zone_and_neighbours(mesh, nodes, active), w * (discrete - recovered) ** 2, 0.0)
    return PressureEstimate(relative=float(np.sqrt(shares.sum() / scale)), nodes=nodes,
                            indicators=shares / scale, active=active)
