"""Two P1 boundary faces in 2D coupled by contact rows: node-to-segment or mortar.

The slave face Γ¹ and the master face Γ² are chains of straight segments
(plane strain). Each slave node s gets one row of the contact constraint

    Σₖ Dₛₖ nₛ·u¹ₖ − Σⱼ Mₛⱼ nₛ·u²ⱼ ≤ gₛ,

with n the slave's outward normal (towards the master), so that ``N u ≤ d``
keeps the package's one sign convention and ``λ ≥ 0`` is compressive.

- **Node-to-segment** (one pass, :func:`node_to_segment`): the slave node is
  projected along the master segment's normal onto the master face at ξₛ;
  D = I, Mₛⱼ = φⱼ(ξₛ) and gₛ the normal distance to the projection.
- **Mortar** (:func:`mortar`): the same constraint weighted by a multiplier
  function ψₛ and integrated over the slave face, ∫ ψₛ [(u¹ − u²)·n − g] ds ≤ 0.
  Each master segment is projected onto each slave segment along the slave
  normal; on each overlap piece a two-point Gauss rule is exact (the integrands
  are quadratic in the slave coordinate), and n is the master segment's normal
  reversed, as node-to-segment takes it (on curved faces the direction of the
  rows is then the same in both, and the rows of a body on a flat are those of
  a rigid flat's). ``Dₛₖ = ∫ ψₛ φ¹ₖ``,
  ``Mₛⱼ = ∫ ψₛ φ²ⱼ`` and the weighted gap ``g̃ₛ = ∫ ψₛ g``. The standard basis
  ψₛ = φₛ has D lumped to ``diag(∫ φₛ)``; the dual (biorthogonal) basis
  ψₛ = 2φₛ − φₒ on each slave segment (o the segment's other node; in an
  axisymmetric face, weighted by r, its own combination :func:`_dual`) has
  ``∫ ψₛ φₖ = δₛₖ ∫ φₛ``, so D is diagonal without lumping.

The weight of a row is ``wₛ = ∫ φₛ ds`` over the part of the slave face the
rows cover; :meth:`Coupling.scaled` divides each row and its gap by its own
coefficient ``Dₛₛ`` (1 for node-to-segment, ``wₛ`` for mortar), so that the
multiplier λₛ of a scaled row is a nodal force and ``λₛ / wₛ`` the contact
pressure. On matching meshes the scaled dual mortar rows are the
node-to-segment rows (node to node).
"""

from __future__ import annotations

import dataclasses
import logging
from dataclasses import dataclass
from typing import Any

import numpy as np
import scipy.sparse as sp

from signorini.errors import InputError
from signorini.fem.assembly import segment_weights
from signorini.fem.topology import outward_normals, with_topology

log = logging.getLogger(__name__)

__all__ = ["DISCRETISATIONS", "Coupling", "Face", "couple", "mortar", "node_to_segment"]

#: the contact discretisations between two faces: dual mortar, standard (lumped) mortar,
#: node-to-segment
DISCRETISATIONS = ("mortar", "mortar-standard", "nts")

#: a projection this far outside a segment (in its own parameter) still lands on it
END_TOLERANCE = 1e-9

#: Gauss-Legendre points and weights on [0, 1]: two points integrate cubics exactly
GAUSS_POINTS = 0.5 + 0.5 * np.polynomial.legendre.leggauss(2)[0]
GAUSS_WEIGHTS = 0.5 * np.polynomial.legendre.leggauss(2)[1]


@dataclass(frozen=True)
class Face:
    """A P1 boundary face in 2D: its nodes, their coordinates, segments and outward normals.

    ``nodes`` (k,) are the mesh's node numbers (in order along the face when it is one open
    chain of segments, else by number), ``points`` (2, k) their
    coordinates, ``segments`` (2, e) index ``nodes`` and ``normals`` (2, e)
    are the segments' outward unit normals (out of the body).
    """

    nodes: np.ndarray
    points: np.ndarray
    segments: np.ndarray
    normals: np.ndarray

    @classmethod
    def of(cls, mesh: Any, facets: np.ndarray) -> "Face":
        """The face made of the boundary ``facets`` of a triangle ``mesh``."""
        facets = np.asarray(facets, dtype=int)
        if mesh.p.shape[0] != 2 or facets.size == 0:
            raise InputError("a contact face needs boundary facets (edges) of a 2D mesh")
        ends = with_topology(mesh).facets[:, facets]
        nodes = _along(ends)
        local = np.searchsorted(np.sort(nodes), ends)
        local = np.argsort(nodes)[local]
        return cls(nodes=nodes, points=mesh.p[:, nodes], segments=local.reshape(ends.shape),
                   normals=outward_normals(mesh, facets))

    def weights(self, radial: bool = False) -> np.ndarray:
        """Lumped weights ``∫ φₛ ds`` of the face's nodes (k,), or ``∫ φₛ r ds`` when ``radial``
        (an axisymmetric face, r = x): :func:`~signorini.fem.assembly.segment_weights`."""
        return segment_weights(self.points, self.segments, radial)


def _along(ends: np.ndarray) -> np.ndarray:
    """The nodes of segments ``ends`` (2, e) in order along them when they make one open chain
    (from the end with the smaller node number), else sorted by number."""
    nodes, counts = np.unique(ends, return_counts=True)
    if nodes.size != ends.shape[1] + 1 or np.count_nonzero(counts == 1) != 2 or counts.max() > 2:
        return nodes
    neighbours: dict[int, list[int]] = {int(n): [] for n in nodes}
    for a, b in ends.T:
        neighbours[int(a)].append(int(b))
        neighbours[int(b)].append(int(a))
    chain = [int(nodes[counts == 1][0])]
    while len(chain) < nodes.size:
        step = [n for n in neighbours[chain[-1]] if len(chain) < 2 or n != chain[-2]]
        chain.append(step[0])
    return np.array(chain)


@dataclass(frozen=True)
class Coupling:
    """The contact rows between a slave and a master face, one per slave node that has one.

    ``slave`` (m,) indexes the slave face's nodes of the rows; ``D`` (m, k¹)
    and ``M`` (m, k²) are the scalar coupling matrices; ``slave_rows``
    (m, 2k¹) and ``master_rows`` (m, 2k²) the rows on the faces' dofs
    (node-major, x then y: ``D n`` and ``−M n``, n the master segment's normal reversed);
    ``gap`` the (weighted) initial gaps and ``weights`` ``∫ φₛ ds``.
    """

    kind: str
    slave: np.ndarray
    D: sp.csr_matrix
    M: sp.csr_matrix
    slave_rows: sp.csr_matrix
    master_rows: sp.csr_matrix
    gap: np.ndarray
    weights: np.ndarray

    @property
    def m(self) -> int:
        """The number of rows."""
        return self.slave.size

    def scaled(self) -> "Coupling":
        """Each row and its gap divided by its slave node's own coefficient ``Dₛₛ`` (1 for
        node-to-segment, ``∫ φₛ ds`` for mortar): λ is then a nodal force, λ / w a pressure."""
        own = np.asarray(self.D[np.arange(self.m), self.slave]).ravel()
        inverse = sp.diags(1.0 / own)
        return dataclasses.replace(
            self, D=(inverse @ self.D).tocsr(), M=(inverse @ self.M).tocsr(),
            slave_rows=(inverse @ self.slave_rows).tocsr(),
            master_rows=(inverse @ self.master_rows).tocsr(), gap=self.gap / own)

    def rows(self, slave_dofs: np.ndarray, master_dofs: np.ndarray, n: int) -> sp.csr_matrix:
        """The rows on a global dof vector of size ``n``: ``slave_dofs`` (2, k¹) and
        ``master_dofs`` (2, k²) are the faces' nodes' (x, y) dofs in it."""
        local = sp.hstack([self.slave_rows, self.master_rows]).tocoo()
        places = np.concatenate([slave_dofs.T.ravel(), master_dofs.T.ravel()])
        return sp.csr_matrix((local.data, (local.row, places[local.col])), shape=(self.m, n))


def _summed(rows, cols, vals, shape: tuple[int, int]) -> sp.csr_matrix:
    """A sparse matrix from (row, column, value) arrays (broadcast), summed where they repeat."""
    rows, cols, vals = np.broadcast_arrays(rows, cols, vals)
    return sp.csr_matrix((vals.ravel(), (rows.ravel(), cols.ravel())), shape=shape)


def _kept(coupling: Coupling, keep: np.ndarray) -> Coupling:
    """The rows ``keep`` of ``coupling`` (slave nodes the master face does not reach dropped)."""
    if not keep.any():
        raise InputError("no slave node faces the master face: check the two contact faces "
                         "(their facets and which body is the slave)")
    dropped = int((~keep).sum())
    if dropped:
        log.info("%d slave nodes beyond the master face have no contact row", dropped)
    return Coupling(kind=coupling.kind, slave=coupling.slave[keep], D=coupling.D[keep],
                    M=coupling.M[keep], slave_rows=coupling.slave_rows[keep],
                    master_rows=coupling.master_rows[keep], gap=coupling.gap[keep],
                    weights=coupling.weights[keep])


def _vector(scalar: sp.csr_matrix, normal: np.ndarray) -> sp.csr_matrix:
    """Rows ``Σₖ Sₛₖ n`` on node-major (x, y) dofs, one normal (2, m) per row."""
    coo = scalar.tocoo()
    data = np.concatenate([coo.data * normal[0, coo.row], coo.data * normal[1, coo.row]])
    return sp.csr_matrix((data, (np.tile(coo.row, 2), np.concatenate([2 * coo.col, 2 * coo.col + 1]))),
                         shape=(scalar.shape[0], 2 * scalar.shape[1]))


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The 2D cross product ``a₀b₁ − a₁b₀`` of vectors along the first axis (broadcast)."""
    return a[0] * b[1] - a[1] * b[0]


def node_to_segment(slave: Face, master: Face, direction: np.ndarray | None = None,
                    radial: bool = False) -> Coupling:
    """One-pass node-to-segment rows: each slave node projected on the master face.

    Slave node s is projected along each master segment's normal n² (or along
    the fixed ``direction``, the slave's outward normal, when given) onto the
    segment's line, ξ in [0, 1]; the nearest such point is its partner ξₛ. Its
    row is ``n`` on u¹ₛ and ``−φⱼ(ξₛ) n`` on the master segment's two nodes,
    with ``n = −n²`` (or ``direction``), and its gap ``gₛ = (x²(ξₛ) − xₛ)·n``.
    Slave nodes that project on no master segment get no row. Weights are the
    slave face's lumped ``∫ φₛ ds`` (``∫ φₛ r ds`` when ``radial``).
    """
    ends = master.points[:, master.segments]  # (2, 2, e)
    tangent = ends[:, 1] - ends[:, 0]
    along = -master.normals if direction is None else np.asarray(direction, float)[:, None]
    with np.errstate(divide="ignore", invalid="ignore"):  # a segment along the direction: no ξ
        xi = _cross(slave.points[:, :, None] - ends[:, 0][:, None, :], along[:, None, :])
        xi /= _cross(tangent, along)[None, :]
    on_segment = (xi >= -END_TOLERANCE) & (xi <= 1.0 + END_TOLERANCE)
    xi = np.clip(xi, 0.0, 1.0)
    foot = ends[:, 0][:, None, :] + xi[None] * tangent[:, None, :]  # (2, k, e)
    distance = np.where(on_segment, np.linalg.norm(slave.points[:, :, None] - foot, axis=0), np.inf)
    nearest = np.argmin(distance, axis=1)
    keep = np.isfinite(distance[np.arange(slave.nodes.size), nearest])
    k = np.arange(slave.nodes.size)
    xi_s = xi[k, nearest]
    normal = along[:, nearest] if direction is None else along[:, [0] * k.size]  # towards the master
    gap = np.einsum("ik,ik->k", foot[:, k, nearest] - slave.points, normal)
    M = _summed(k[:, None], master.segments[:, nearest].T, np.stack([1.0 - xi_s, xi_s], axis=1),
                (slave.nodes.size, master.nodes.size))
    D = sp.identity(slave.nodes.size, format="csr")
    coupling = Coupling(kind="nts", slave=k, D=D, M=M, slave_rows=_vector(D, normal),
                        master_rows=-_vector(M, normal), gap=gap, weights=slave.weights(radial))
    return _kept(coupling, keep)


def _dual(r0, r1, radial: bool) -> np.ndarray:
    """The coefficients A (..., 2, 2) of the dual basis ``ψ = A φ`` on slave segments whose ends
    have radii ``r0, r1`` (broadcast): ``A = D Mₑ⁻¹``, Mₑ the segment's mass matrix ∫ φ φᵀ
    (weight r when ``radial``) and D its row sums, so that ``∫ ψᵢ φⱼ = δᵢⱼ ∫ φᵢ``;
    ``[[2, −1], [−1, 2]]`` when the weight is 1."""
    r0, r1 = np.broadcast_arrays(np.asarray(r0, dtype=float), np.asarray(r1, dtype=float))
    phi = np.stack([1.0 - GAUSS_POINTS, GAUSS_POINTS])
    weight = GAUSS_WEIGHTS * ((1.0 - GAUSS_POINTS) * r0[..., None] + GAUSS_POINTS * r1[..., None]
                              if radial else np.ones(r0.shape + (1,)))
    mass = np.einsum("iq,jq,...q->...ij", phi, phi, weight)
    return mass.sum(axis=-1)[..., None] * np.linalg.inv(mass)


def _covered_dual(slave: Face, s: np.ndarray, lo: np.ndarray, hi: np.ndarray, phi_s: np.ndarray,
                  dw: np.ndarray, radial: bool) -> np.ndarray:
    """The dual coefficients A (e¹, 2, 2) of each slave segment, biorthogonal on the part of it
    the master covers: :func:`_dual` on a segment the pieces ``s`` (slave coordinates lo to hi)
    cover whole; on one they cover in part, ``A = D M꜀⁻¹`` with M꜀ the mass matrix of the
    covered part (of the pieces' points ``phi_s`` and weights ``dw``), so that D stays diagonal
    and positive, ``∫ φₛ`` over the cover. The whole segment's basis there has ``∫ ψₛ φₛ`` of
    either sign (zero when half covered): the row, divided by it, would turn or blow up."""
    ends_r = slave.points[0, slave.segments]  # (2, e¹)
    A = _dual(ends_r[0], ends_r[1], radial)
    partial = np.bincount(s, hi - lo, minlength=A.shape[0]) < 1.0 - END_TOLERANCE
    partial &= np.bincount(s, minlength=A.shape[0]) > 0
    if partial.any():
        mass = np.zeros_like(A)
        np.add.at(mass, s, np.einsum("ipq,jpq,pq->pij", phi_s, phi_s, dw))
        A[partial] = mass[partial].sum(axis=-1)[..., None] * np.linalg.inv(mass[partial])
    return A


#: at most this many (slave, master) segment pairs are projected at once
PAIRS_AT_ONCE = 1 << 20


def _overlaps(slave: Face, master: Face, direction: np.ndarray | None) -> tuple[np.ndarray, ...]:
    """The (slave, master) segment pairs that overlap, slave-major: each master segment facing
    a slave segment (opposite normals) projected onto it along the slave normal (or
    ``direction``). Returns the pairs' slave and master segments and the slave coordinates η
    of the master segment's two ends (2, p) and of the overlap (lo, hi)."""
    x0 = slave.points[:, slave.segments[0]]  # (2, e¹)
    t = slave.points[:, slave.segments[1]] - x0
    along = slave.normals if direction is None else np.asarray(direction, dtype=float)[:, None]
    along = np.broadcast_to(along, x0.shape)
    master_ends = master.points[:, master.segments][:, :, None, :]  # (2, 2, 1, e²)
    block = max(1, PAIRS_AT_ONCE // max(1, master.segments.shape[1]))
    found = []
    for first in range(0, x0.shape[1], block):
        part = slice(first, first + block)
        with np.errstate(divide="ignore", invalid="ignore"):  # along the direction: no piece
            ends = (_cross(master_ends - x0[:, None, part, None], along[:, None, part, None])
                    / _cross(t[:, part], along[:, part])[None, :, None])  # (2, b, e²)
        lo = np.clip(ends.min(axis=0), 0.0, 1.0)
        hi = np.clip(ends.max(axis=0), 0.0, 1.0)
        facing = slave.normals[:, part].T @ master.normals < 0.0  # (b, e²)
        s, m = np.nonzero((hi - lo > END_TOLERANCE) & facing)
        found.append((s + first, m, ends[:, s, m], lo[s, m], hi[s, m]))
    return tuple(np.concatenate(column, axis=-1) for column in zip(*found))


def mortar(slave: Face, master: Face, basis: str = "dual",
           direction: np.ndarray | None = None, radial: bool = False) -> Coupling:
    """Mortar rows: ``D n`` on the slave nodes, ``−M n`` on the master nodes, gap ``g̃``.

    Segment to segment on the slave face: each master segment that faces a
    slave segment (opposite normals) is projected onto it along the slave
    normal (:func:`_overlaps`), each overlap is integrated by two Gauss points
    with n the master segment's normal reversed, and ``Dₛₖ``,
    ``Mₛⱼ``, ``g̃ₛ`` and ``wₛ = ∫ φₛ ds`` accumulate over the overlaps with
    ψₛ the ``basis`` ("dual": biorthogonal, "standard": ψₛ = φₛ with D lumped).
    Slave nodes the master face does not reach get no row. ``radial``: every
    integral carries the weight r = x (an axisymmetric face), the dual basis is
    biorthogonal in that weight (:func:`_dual`) and D stays diagonal.
    """
    if basis not in ("dual", "standard"):
        raise InputError(f"mortar basis={basis!r} must be 'dual' or 'standard'")
    ks, km = slave.nodes.size, master.nodes.size
    s, m, eta_ends, lo, hi = _overlaps(slave, master, direction)
    x0 = slave.points[:, slave.segments[0, s]][..., None]  # (2, p, 1)
    t = slave.points[:, slave.segments[1, s]][..., None] - x0
    eta = lo[:, None] + (hi - lo)[:, None] * GAUSS_POINTS  # (p, q)
    dw = (hi - lo)[:, None] * GAUSS_WEIGHTS * np.sqrt(t[0] ** 2 + t[1] ** 2)  # ds of each point
    if radial:  # r ds: the integrands stay cubic in eta, the two points exact
        dw = dw * (x0[0] + eta * t[0])
    xi = (eta - eta_ends[0, :, None]) / (eta_ends[1, :, None] - eta_ends[0, :, None])
    phi_s = np.stack([1.0 - eta, eta])  # (2, p, q)
    phi_m = np.stack([1.0 - xi, xi])
    if basis == "standard":
        psi = phi_s
    else:
        psi = np.einsum("pik,kpq->ipq", _covered_dual(slave, s, lo, hi, phi_s, dw, radial)[s], phi_s)
    y0, y1 = master.points[:, master.segments[0, m]], master.points[:, master.segments[1, m]]
    across = y0[..., None] + xi * (y1 - y0)[..., None] - (x0 + eta * t)  # (2, p, q)
    normal = (-master.normals[:, m] if direction is None  # (2, p): as node-to-segment
              else np.repeat(np.asarray(direction, dtype=float)[:, None], s.size, axis=1))
    g = np.einsum("ip,ipq->pq", normal, across)  # normal distance from slave to master
    slave_pair, master_pair = slave.segments[:, s], master.segments[:, m]  # (2, p)
    mm = np.einsum("ipq,jpq,pq->ijp", psi, phi_m, dw)  # ∫ψᵢ φ²ⱼ on each piece
    if basis == "standard":  # lumped: ∫ φᵢ on the diagonal
        dd = np.einsum("ik,ipq,pq->ikp", np.eye(2), phi_s, dw)
    else:
        dd = np.einsum("ipq,kpq,pq->ikp", psi, phi_s, dw)
    row, xy = slave_pair[:, None], np.arange(2)  # rows (2, 1, p); the (x, y) dofs of a node
    slave_rows = _summed(row[..., None], 2 * slave_pair[None, ..., None] + xy,
                         dd[..., None] * normal.T, (ks, 2 * ks))
    master_rows = _summed(row[..., None], 2 * master_pair[None, ..., None] + xy,
                          -mm[..., None] * normal.T, (ks, 2 * km))
    gap = np.bincount(slave_pair.ravel(), np.einsum("ipq,pq,pq->ip", psi, g, dw).ravel(),
                      minlength=ks)
    weights = np.bincount(slave_pair.ravel(), np.einsum("ipq,pq->ip", phi_s, dw).ravel(),
                          minlength=ks)
    coupling = Coupling(kind="mortar" if basis == "dual" else "mortar-standard",
                        slave=np.arange(ks), D=_summed(row, slave_pair[None], dd, (ks, ks)),
                        M=_summed(row, master_pair[None], mm, (ks, km)),
                        slave_rows=slave_rows, master_rows=master_rows, gap=gap,
                        weights=weights)
    return _kept(coupling, weights > 0)


def couple(slave: Face, master: Face, discretisation: str = "mortar",
           direction: np.ndarray | None = None, radial: bool = False) -> Coupling:
    """The rows of ``discretisation`` (one of :data:`DISCRETISATIONS`), unscaled; with a fixed
    ``direction`` (the slave's outward unit normal) every row and projection takes it;
    ``radial``: axisymmetric faces in (r, z), every integral weighted by r."""
    if discretisation == "nts":
        return node_to_segment(slave, master, direction, radial)
    if discretisation in ("mortar", "mortar-standard"):
        return mortar(slave, master, "dual" if discretisation == "mortar" else "standard",
                      direction, radial)
    raise InputError(f"discretisation={discretisation!r} must be one of {', '.join(DISCRETISATIONS)}")
