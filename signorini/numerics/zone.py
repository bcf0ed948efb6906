"""Exact contact from a predicted contact zone: one factorisation and a small LCP on its edge.

A prediction (from a coarser model of the same scene) splits the candidates into a *core* that
surely touches, a *band* where the edge of the contact zone may lie, and the *rest* that surely
stays apart. Then:

1. K is factorised once with the core's dofs pinned at gap-closing values (a Dirichlet
   condition; this needs every row of N to bound one dof, as for a flat obstacle);
2. the band is condensed onto ``W_B = N_B K̃⁻¹ N_Bᵀ`` (one back-solve per band node) and its
   complementarity problem solved exactly (:func:`signorini.numerics.lcp.solve_lcp`);
3. a core node whose reaction pulls, or a node of the rest that penetrates, joins the band and
   the band problem is solved again (a pulling core node also costs a new numeric
   factorisation with it released).

The loop ends only when every KKT condition holds to round-off, so the answer is exact whatever
the prediction; a good prediction only makes it cheap. With a target load the push ``s``
(:mod:`signorini.numerics.push`) joins the band problem as one more unknown, with the total
contact force (band forces plus core reactions) as one more equation.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from signorini.numerics.active_set import PinnedFactor, Pinning, selection_dofs
from signorini.numerics.factor import resolve_backend
from signorini.numerics.lcp import solve_lcp
from signorini.numerics.push import condensed_pair, push_for_load

log = logging.getLogger(__name__)

#: relative size under which a negative core reaction or a positive violation is round-off
ROUND_OFF = 1e-10
#: back-solves are done on blocks of this many band nodes
BLOCK = 32
#: band columns ``K̃⁻¹N_jᵀ`` are kept whole while they fit in this many bytes; beyond, only what
#: the band's LCP reads of them (``N z_j`` and the core's reactions) is kept, and the displacement
#: costs one back-solve more: kept whole, the columns of a large 3D band do not fit in memory
#: (chosen from measurements, docs/calibration.md)
COLUMN_BYTES = 512 * 2 ** 20
#: a load (and gaps) is taken as a combination of the last ones solved when the combination
#: reproduces it to this, relative to its largest entry: its solution is then that combination
#: of theirs, to round-off, and costs no back-solve
SPAN_RTOL = 1e-13


@dataclass
class Zone:
    """A prediction of the contact zone, as boolean masks over the candidates."""

    core: np.ndarray  # surely touching: pinned
    band: np.ndarray  # unsure: condensed and solved exactly

    @property
    def rest(self) -> np.ndarray:
        return ~(self.core | self.band)

    def copy(self) -> "Zone":
        return Zone(self.core.copy(), self.band.copy())

    def counts(self) -> str:
        return f"core {int(self.core.sum())}, band {int(self.band.sum())}, rest {int(self.rest.sum())}"


def predict_zone(points: np.ndarray, coarse_points: np.ndarray, coarse_active: np.ndarray,
                 neighbours: int | None = None) -> Zone:
    """The zone of candidates at ``points`` from a coarse model's active set.

    A candidate is core when its ``neighbours`` nearest coarse candidates all touch (default: 4
    on a contact curve, 2D and axisymmetric; 10 on a contact surface, 3D), rest when none of
    the nearest half of them does, band otherwise: about two coarse elements inside the coarse
    edge and one outside, leaning on what a wrong guess costs (a core node that should separate
    costs a new factorisation, a rest node that penetrates one back-solve).
    """
    from scipy.spatial import cKDTree  # on use: scipy.spatial is slow to import

    points, coarse_points = np.atleast_2d(points), np.atleast_2d(coarse_points)
    if neighbours is None:
        neighbours = 4 if points.shape[1] == 2 else 10
    k = max(1, min(int(neighbours), len(coarse_points)))
    _, index = cKDTree(coarse_points).query(points, k=k)
    votes = np.asarray(coarse_active, dtype=bool)[index.reshape(len(points), k)]
    core = votes.all(axis=1)
    band = votes[:, :max(1, k // 2)].any(axis=1) & ~core
    return Zone(core=core, band=band)


def zone_around(x: np.ndarray, a: float, margin: float, spacing: float | None = None,
                outside: float = 1.0) -> Zone | None:
    """The zone of candidates at abscissae ``x`` (2D, axisymmetric) for a contact half-width ``a``.

    Core: inside ``a − max(2h, margin·a)``; band: up to ``a + max(outside·h, margin·a)``
    (``h`` the candidates' ``spacing`` at a, by default the gap between the sorted
    abscissae there) — the asymmetry of :func:`predict_zone`.
    None when the candidates do not reach past the band on both sides.
    """
    x = np.asarray(x, dtype=float)
    if not (a > 0) or len(x) < 3 or not np.all(np.isfinite(x)):
        return None
    ordered = np.sort(x)
    at = int(np.clip(np.searchsorted(ordered, a), 1, len(x) - 1))
    h = ordered[at] - ordered[at - 1] if spacing is None else spacing
    inner, outer = a - max(2 * h, margin * a), a + max(outside * h, margin * a)
    if outer >= ordered[-1] or inner <= ordered[0]:
        return None
    return Zone(core=x < inner, band=(x >= inner) & (x <= outer))


def radial_distance(points: np.ndarray) -> np.ndarray:
    """Each candidate's distance from the first point of contact along the flat: ``|x|`` of a 2D
    or axisymmetric point (x, y), ``√(x² + y²)`` of a 3D one (x, y, z) over a flat z = const."""
    points = np.atleast_2d(points)
    return np.abs(points[:, 0]) if points.shape[1] == 2 else np.hypot(points[:, 0], points[:, 1])


def zone_around_points(points: np.ndarray, a: float, margin: float) -> Zone | None:
    """:func:`zone_around` for candidates at ``points`` (m, 2 or 3) around a contact of radius
    ``a`` centred at the origin: by :func:`radial_distance`; in 3D ``h`` is the candidates'
    median distance to their nearest neighbour within a quarter of a from the edge (their
    radial distances crowd together, so the gap between sorted ones says nothing), and the band
    stops at ``a + margin·a``: a ring of candidates costs a back-solve each, and a node beyond it
    that touches joins it for one back-solve more (docs/calibration.md)."""
    points = np.atleast_2d(np.asarray(points, dtype=float))
    rho = radial_distance(points)
    if points.shape[1] == 2:
        return zone_around(rho, a, margin)
    from scipy.spatial import cKDTree  # in 3D only: scipy.spatial is slow to import

    near = points[np.abs(rho - a) < 0.25 * a]
    if len(near) < 3:
        return None
    distance, _ = cKDTree(near).query(near, k=2)
    return zone_around(rho, a, margin, spacing=float(np.median(distance[:, 1])), outside=0.0)


class ZoneSolver:
    """``min ½uᵀKu − fᵀu, Nu ≤ d`` solved exactly around a predicted zone (see module doc).

    Keeps its pinned factorisation (``factor``, which the certificate reuses), its band
    columns ``K̃⁻¹N_jᵀ`` and its last loads' solutions between calls, so the same K solved for
    other loads costs back-solves only while the core stays the same, and none for a load that
    combines the last ones (load control's two, the push's and the fixed load's, then the
    method's at the push found).
    """

    def __init__(self, K: sp.spmatrix, N: sp.spmatrix, backend: str | None = None):
        self.K = K if sp.issparse(K) else sp.csr_matrix(K)
        self.N = sp.csr_matrix(N)
        dofs = selection_dofs(self.N)
        if dofs is None:
            raise ValueError("the zone solver needs every row of N to bound one dof "
                             "(a flat obstacle, or dofs rotated into the obstacle's normal)")
        rows = sp.csr_matrix(self.N, copy=True)
        rows.eliminate_zeros()
        rows.sort_indices()
        self.dofs, self.coef = dofs, rows.data.copy()
        self.n, self.m = self.K.shape[0], self.N.shape[0]
        self.backend = resolve_backend(backend, self.n, self.K.nnz)
        self._pinning = Pinning(self.K, self.backend)
        self._core: np.ndarray | None = None
        self.factor: PinnedFactor | None = None
        #: per band node: ``N z_j`` and the core's reactions to ``z_j``, and ``z_j`` while it fits
        self._columns: dict[int, tuple[np.ndarray, np.ndarray, np.ndarray | None]] = {}
        self._whole = 0
        #: the last loads and gaps solved on this core: (F, D, U0, right-hand sides)
        self._loads: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray] | None = None
        self.factorisations = 0  # numeric factorisations made (one per core)

    # --- linear algebra on the pinned factorisation -------------------------------------------

    def _use_core(self, core: np.ndarray) -> None:
        if self._core is not None and np.array_equal(core, self._core):
            return
        self.factor = PinnedFactor(self.K, self.dofs[core], self.backend, self._pinning)
        self._core = core.copy()
        self._columns.clear()
        self._whole = 0
        self._loads = None
        self.factorisations += 1

    def _combination(self, F: np.ndarray, D: np.ndarray) -> np.ndarray | None:
        """Weights w with ``F = F₀ w`` and ``D = D₀ w`` (F₀, D₀ the last loads and gaps solved on
        this core, see :data:`SPAN_RTOL`), or None."""
        if self._loads is None:
            return None
        pairs = list(zip(self._loads[:2], (F, D)))
        gram = sum(old.T @ old for old, _ in pairs)  # the normal equations: k × k, k ≤ 2 here
        weights = np.zeros((gram.shape[0], F.shape[1]))
        for _ in range(2):  # solved, then refined once on its residual
            weights += np.linalg.lstsq(gram, sum(old.T @ (new - old @ weights)
                                                 for old, new in pairs), rcond=None)[0]
        for old, new in pairs:  # loads and gaps each to their own scale
            miss = np.max(np.abs(old @ weights - new), axis=0, initial=0.0)
            if np.any(miss > SPAN_RTOL * np.max(np.abs(new), axis=0, initial=0.0)):
                return None
        return weights

    def _units(self, band) -> np.ndarray:
        """``N_Bᵀ`` as dense columns (n × |B|): a unit force along each band node's normal."""
        units = np.zeros((self.n, len(band)))
        units[self.dofs[band], np.arange(len(band))] = self.coef[band]
        return units

    def _solutions(self, F: np.ndarray, D: np.ndarray, zone: Zone,
                   band: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``U0``: u (n × k) with the core's gaps closed, loads F and no band forces, and the
        right-hand sides it solves; the band columns ``z_j = K̃⁻¹ N_jᵀ`` not kept from an earlier
        call are solved with U0 (one pass over the factor for both) and kept (:data:`COLUMN_BYTES`).
        Loads that combine the last ones solved take U0 from theirs (:meth:`_combination`).
        """
        core = zone.core
        F = np.array(F, dtype=float).reshape(self.n, -1)
        D = np.array(D, dtype=float).reshape(self.m, -1)
        weights = self._combination(F, D)
        U0 = None
        if weights is not None:
            U0, rhs = self._loads[2] @ weights, self._loads[3] @ weights
        else:
            rhs = F.copy()
            rhs[self.dofs[core]] = D[core] / self.coef[core][:, None]
        missing = [j for j in band if j not in self._columns]
        chunks = [missing[first:first + BLOCK] for first in range(0, len(missing), BLOCK)]
        for chunk in chunks or ([] if U0 is not None else [[]]):
            units = self._units(chunk)
            block = self.factor.solve(units if U0 is not None else np.hstack([rhs, units]))
            if U0 is None:
                U0, block = block[:, :rhs.shape[1]], block[:, rhs.shape[1]:]
            gaps, reactions = self.N @ block, self.factor.fixed_rows(block)
            for k, j in enumerate(chunk):
                whole = (self._whole + 1) * self.n * 8 <= COLUMN_BYTES
                self._whole += whole
                column = block[:, k].copy() if whole else None
                self._columns[j] = (gaps[:, k], reactions[:, k], column)
                if whole:  # the certificate's bordering reads it back (forward_error)
                    self.factor.kept[int(self.dofs[j])] = (column, self.coef[j])
        if weights is None:
            self._loads = (F, D, U0, rhs)
        return U0, rhs

    def _displacement(self, U0: np.ndarray, rhs: np.ndarray, band: np.ndarray,
                      lam_band: np.ndarray) -> np.ndarray:
        """``u = U0 − Σ_B z_j λ_j``: from the kept columns, or one back-solve when some were not."""
        if not len(band):
            return U0
        kept = [self._columns[j][2] for j in band]
        if all(z is not None for z in kept):
            return U0 - np.column_stack(kept) @ lam_band
        return self.factor.solve(rhs - self._units(band) @ lam_band)

    def _pieces(self, F: np.ndarray, D: np.ndarray, zone: Zone):
        """Everything affine in the band forces, for loads F (n × k) and gaps D (m × k):
        ``u = U0 − Zλ_B`` (U0 and its right-hand sides), band gaps ``Wλ_B − b``, core reactions
        ``R + Gλ_B`` (``R``: ``F − K U0`` on the core's dofs)."""
        self._use_core(zone.core)
        band = np.nonzero(zone.band)[0]
        U0, rhs = self._solutions(F, D, zone, band)
        coef = self.coef[zone.core][:, None]
        if len(band):
            W = np.column_stack([self._columns[j][0][band] for j in band])
            W = 0.5 * (W + W.T)
            G = np.column_stack([self._columns[j][1] for j in band]) / coef
        else:
            W, G = np.zeros((0, 0)), np.zeros((0, 0))
        b = self.N[band] @ U0 - np.asarray(D, dtype=float)[band]
        R = (F[self.dofs[zone.core]] - self.factor.fixed_rows(U0)) / coef
        return band, U0, rhs, W, b, R, G

    # --- the check that makes it exact ---------------------------------------------------------

    def _amend(self, zone: Zone, lam: np.ndarray, violation: np.ndarray, d: np.ndarray,
               u: np.ndarray) -> bool:
        """Move wrongly predicted nodes into the band; True when none was wrong."""
        force_tol = ROUND_OFF * max(float(np.max(np.abs(lam), initial=0.0)), 1e-300)
        gap_tol = ROUND_OFF * max(float(np.max(np.abs(d))), float(np.max(np.abs(self.N @ u))),
                                  1e-300)
        pulling = zone.core & (lam < -force_tol)
        penetrating = zone.rest & (violation > gap_tol)
        if not (pulling.any() or penetrating.any()):
            return True
        log.info("zone amended: %d core nodes pull, %d others penetrate",
                 int(pulling.sum()), int(penetrating.sum()))
        zone.core &= ~pulling
        zone.band |= pulling | penetrating
        return False

    # --- the two problems ----------------------------------------------------------------------

    def _rounds(self, F: np.ndarray, D: np.ndarray, zone: Zone, band_solve,
                max_rounds: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, Zone]:
        """The band solved by ``band_solve(W, b, R, G) → (weights, λ_B)`` (the load is
        ``F @ weights``, the gaps ``D @ weights``) and the zone amended until no node was wrong:
        ``(weights, u, λ, final zone)``."""
        zone = zone.copy()
        for _ in range(max_rounds):
            band, U0, rhs, W, b, R, G = self._pieces(F, D, zone)
            weights, lam_band = band_solve(W, b, R, G)
            u = self._displacement(U0 @ weights, rhs @ weights, band, lam_band)
            lam = np.zeros(self.m)
            lam[band] = lam_band
            lam[zone.core] = R @ weights + (G @ lam_band if len(band) else 0.0)
            d = D @ weights
            if self._amend(zone, lam, self.N @ u - d, d, u):
                return weights, u, lam, zone
        raise ArithmeticError(f"the contact zone kept changing for {max_rounds} rounds")

    def solve(self, f: np.ndarray, d: np.ndarray, zone: Zone,
              max_rounds: int = 100) -> tuple[np.ndarray, np.ndarray, Zone]:
        """``(u, λ, final zone)`` for load f and gaps d, starting from ``zone``."""
        def band(W, b, R, G):
            return np.ones(1), solve_lcp(W, b[:, 0])[0] if len(b) else np.zeros(0)

        _, u, lam, zone = self._rounds(np.reshape(f, (-1, 1)), np.reshape(d, (-1, 1)), zone,
                                       band, max_rounds)
        return u, lam, zone

    def push_for_load(self, f1: np.ndarray, d0: np.ndarray, d1: np.ndarray, target: float,
                      multiplicity: float, zone: Zone, max_rounds: int = 100,
                      f0: np.ndarray | None = None) -> tuple[float, np.ndarray, np.ndarray, Zone]:
        """The push s with total contact force ``μ Σλ = target`` for ``f = s f1 + f0, d = d0 + s d1``.

        Returns ``(s, u, λ, final zone)``.
        """
        def band(W, b, R, G):
            s, lam_band = _band_push(W, b, R, G, target, multiplicity)
            return np.array([s, 1.0]), lam_band

        F = np.column_stack([f1, np.zeros_like(f1) if f0 is None else f0])
        weights, u, lam, zone = self._rounds(F, np.column_stack([d1, d0]), zone, band, max_rounds)
        return float(weights[0]), u, lam, zone


def _band_push(W: np.ndarray, b: np.ndarray, R: np.ndarray, G: np.ndarray, target: float,
               multiplicity: float) -> tuple[float, np.ndarray]:
    """The band's share of load targeting: :func:`signorini.numerics.push.push_for_load`.

    Band gaps ``Wλ − (s b₁ + b₀) ≥ 0``, forces ``λ ≥ 0``, complementary; the
    load is ``μ (Σλ + Σ core reactions)`` with core reactions ``s R₁ + R₀ + Gλ``
    (so an empty band still carries a load). Starts from the band closed.
    """
    weight = multiplicity * (1.0 + G.sum(axis=0))
    fixed = multiplicity * R.sum(axis=0)
    s, lam = push_for_load(condensed_pair(W, b), np.ones(W.shape[0], dtype=bool), target,
                           lambda pair: fixed + weight @ pair, max_iter=200, empty_allowed=True)
    return s, np.maximum(lam, 0.0)


__all__ = ["Zone", "predict_zone", "zone_around", "radial_distance", "zone_around_points",
           "ZoneSolver", "COLUMN_BYTES"]
