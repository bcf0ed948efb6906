"""The volumetric strain averaged at the nodes: P1 simplices that do not lock.

Plain P1 elements integrate ``λ (tr ε)²`` element by element. Each element
then carries its own incompressibility constraint, and as ν → ½ (λ/μ → ∞)
those constraints outnumber what the displacement can satisfy: the mesh
locks, the body turns too stiff and Hertz's p₀ drifts away (docs/accuracy.md,
§4). Averaging the volumetric strain over the elements around each node leaves
one constraint per node — fewer than the two or three displacement dofs of
that node — and the locking goes.

With P1 basis functions φₙ and ``tr ε = ∂ₓuₓ + ∂ᵧuᵧ (+ ∂_z u_z, or + u_r / r
axisymmetric)``, the nodal volumetric strain is

    θₙ(u) = ∫ φₙ tr ε(u) dV / Vₙ,    Vₙ = ∫ φₙ dV       (dV = r dr dz axisymmetric),

and the λ-part of the energy becomes the sum over nodes ``λ Σₙ Vₙ θₙ²``:
``K = K_μ + Gᵀ diag(λ / V) G`` with ``Gₙⱼ = ∫ φₙ tr ε(φⱼ) dV`` (the 2μ ε : ε
part K_μ stays element by element). It is the P1–P1 mixed method with its
pressure mass matrix lumped and the pressure condensed out — for
tetrahedra the "average nodal pressure" element of J. Bonet and A. J.
Burton, *A simple average nodal pressure tetrahedral element for
incompressible and nearly incompressible dynamic explicit applications*,
Commun. Numer. Meth. Engng 14 (1998) 437–449. A uniform strain gives θₙ =
tr ε at every node, so the patch test still passes; K stays symmetric and,
with μ > 0 and the rigid modes held, positive definite. Its stencil reaches
the neighbours' neighbours, so K has 2.7 times the nonzeros of plain P1 on triangles
and 5.2 times on tetrahedra (on the Hertz scenes: docs/accuracy.md, §4).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import scipy.sparse as sp

from signorini.fem.stiffness import barycentric_gradients


def simplex_gradients(mesh: Any) -> tuple[np.ndarray, np.ndarray]:
    """Gradients (elements, d + 1, dim) of every simplex's barycentric coordinates, and ``|det J|``
    of its map from the reference simplex (d! times its measure), in closed form
    (:func:`signorini.fem.stiffness.barycentric_gradients`) laid out by element."""
    gradients, measure = barycentric_gradients(mesh.p, mesh.t)
    return gradients.transpose(2, 1, 0), measure * math.factorial(mesh.p.shape[0])


def averaging(mesh: Any, axisymmetric: bool = False) -> tuple[sp.csr_matrix, np.ndarray]:
    """``G`` (nodes × dofs, ``Gₙⱼ = ∫ φₙ tr ε(φⱼ) dV``) and the nodal volumes ``V`` (nodes).

    Dofs are interleaved by node, as :func:`signorini.fem.assembly.nodal_dofs`
    numbers them. Exact for P1: ``∫_K φₙ dV`` is ``|K| / (d + 1)`` and, with
    the weight r, ``|K| (rₙ + Σ r) / 12``; the hoop term ``∫_K φₙ φⱼ dr dz``
    is ``|K| (1 + δₙⱼ) / 12``.
    """
    p, t = mesh.p, mesh.t
    dim, nodes = p.shape
    corners, elements = t.shape
    gradients, jacobian = simplex_gradients(mesh)
    measure = jacobian / (2.0 if dim == 2 else 6.0)
    if axisymmetric:
        r = p[0, t]  # (3, elements)
        weight = measure * (r + r.sum(axis=0)) / 12.0  # ∫_K φₙ r dA, (3, elements)
    else:
        weight = np.broadcast_to(measure / corners, (corners, elements))
    # G restricted to each element: entry (local node a, local node b, component i)
    local = weight.T[:, :, None, None] * gradients[:, None, :, :]  # (elements, a, b, i)
    if axisymmetric:  # the hoop strain u_r / r times r: ∫_K φₐ φ_b dA on the r component
        local[..., 0] += (measure[:, None, None] / 12.0) * (1.0 + np.eye(corners))[None]
    rows = np.broadcast_to(t.T[:, :, None, None], local.shape)
    cols = dim * t.T[:, None, :, None] + np.arange(dim)[None, None, None, :]
    cols = np.broadcast_to(cols, local.shape)
    G = sp.csr_matrix((local.ravel(), (rows.ravel(), cols.ravel())), shape=(nodes, dim * nodes))
    volumes = np.bincount(t.ravel(), weight.ravel(), minlength=nodes)
    return G, volumes


def volumetric_stiffness(mesh: Any, Lambda: float, axisymmetric: bool = False) -> sp.csr_matrix:
    """The λ-part of K with the volumetric strain averaged at the nodes: ``Gᵀ diag(λ / V) G``."""
    G, volumes = averaging(mesh, axisymmetric)
    scale = np.divide(Lambda, volumes, out=np.zeros_like(volumes), where=volumes > 0)
    return (G.T @ sp.diags(scale) @ G).tocsr()


def nodal_volumetric_strain(mesh: Any, u: np.ndarray, axisymmetric: bool = False) -> np.ndarray:
    """θₙ of the nodal displacement ``u`` (nodes, dim): the volumetric strain each node carries."""
    G, volumes = averaging(mesh, axisymmetric)
    return G @ np.asarray(u, dtype=float).ravel() / np.where(volumes > 0, volumes, 1.0)


__all__ = ["simplex_gradients", "averaging", "volumetric_stiffness", "nodal_volumetric_strain"]
