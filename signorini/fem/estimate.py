"""A posteriori estimate of the discretisation error in the energy norm (recovery, ZZ).

The P1 strain ``ε_h = ε(u_h)`` is discontinuous from element to element; the
exact strain is continuous. Zienkiewicz & Zhu's estimator (O. C. Zienkiewicz,
J. Z. Zhu, "A simple error estimator and adaptive procedure for practical
engineering analysis", IJNME 24 (1987) 337–357) measures the error by the
distance between ``ε_h`` and a continuous strain ``ε*`` recovered from it:

    η_K² = ∫_K (ε* − ε_h) : C : (ε* − ε_h) dx        (× r in axisymmetric models)

with C the elasticity tensor, so ``η = (Σ η_K²)^½`` estimates ``‖u − u_h‖_E``,
``‖v‖_E² = a(v, v)`` the elastic energy. Recovering the strain or the stress
is the same thing here (C is constant, the averaging linear). ``ε*`` is the
lumped L² projection of ``ε_h`` onto continuous P1, component by component —
ZZ's nodal averaging, each element weighted by ``∫_K φᵢ dx`` (``∫_K φᵢ r dx``
axisymmetric): at node i, ``ε*ᵢ = Σ_K ∫_K ε_h φᵢ / Σ_K ∫_K φᵢ``. In the
axisymmetric model (see :func:`signorini.fem.assembly.axisymmetric_elasticity`)
the strain has the hoop part ``ε_θθ = u_r / r``, which varies inside an element
and is recovered like the others; integrals are by quadrature
(:data:`QUADRATURE_ORDER`, :data:`AXISYMMETRIC_ORDER`). 3D tetrahedra work the same way (six components).

The contact's parts — the complementarity term at the edge of the contact zone and the
contact pressure's estimate — are in :mod:`signorini.fem.contact_estimate`.

Everything here is in the problem's (dimensionless) units: energies in
``force · displacement`` of :class:`signorini.problem.contact.Scales`, per unit
thickness in plane strain and per radian in axisymmetric models.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from skfem.models.elasticity import lame_parameters as lame  # Lamé's λ and μ of E and ν
from skfem.quadrature import get_quadrature

from signorini.fem.contact_estimate import PressureEstimate, candidate_nodes, contact_term, pressure_estimate
from signorini.fem.stiffness import barycentric_gradients
from signorini.fem.volumetric import nodal_volumetric_strain, simplex_gradients
from signorini.problem.contact import ContactProblem, ContactSolution

#: quadrature order of the element integrals: 2 integrates the plane-strain and 3D ones
#: exactly (a linear field squared); the axisymmetric ones are rational (the hoop strain
#: u_r / r, times r), integrated to order 4
#: the strain components (i, j) of :func:`strains`, in their order, by dimension
STRAIN_PAIRS = {2: [(0, 0), (1, 1), (0, 1)], 3: [(0, 0), (1, 1), (2, 2), (1, 2), (0, 2), (0, 1)]}
QUADRATURE_ORDER = 2
AXISYMMETRIC_ORDER = 4


@dataclass(frozen=True)
class ErrorEstimate:
    """The estimated energy-norm error of one solution, per element and in total.

    ``elements`` are the per-element indicators ``η_K`` (recovery part, and the
    contact term of the element's contact edges), ``recovery`` and ``contact``
    the two parts of ``total = (Σ η_K²)^½``, ``energy_norm`` is ``‖u_h‖_E``;
    ``scale`` turns them into physical units (√(force · length)). ``bodies``: each estimated
    with its own material; for two, no contact term and no pressure estimate.
    """

    elements: np.ndarray
    recovery: float
    contact: float
    energy_norm: float
    scale: float = 1.0
    pressure: PressureEstimate | None = None
    bodies: int = 1

    @property
    def total(self) -> float:
        """η in physical units: ``(Σ η_K²)^½``."""
        return float(np.sqrt(np.sum(self.elements ** 2))) * self.scale

    @property
    def relative(self) -> float:
        """η / ‖u_h‖_E (the same in every unit system)."""
        return float(np.sqrt(np.sum(self.elements ** 2)) / self.energy_norm) \
            if self.energy_norm > 0 else float("nan")

    def as_dict(self) -> dict[str, float | int]:
        """Scalars only (the JSON of a result): total, relative, elements and the largest one."""
        return {"total": self.total, "relative": self.relative,
                "elements": int(self.elements.size),
                "max_element": float(np.max(self.elements)) * self.scale,
                "recovery": self.recovery * self.scale, "contact": self.contact * self.scale,
                "energy_norm": self.energy_norm * self.scale,
                "pressure": None if self.pressure is None else self.pressure.relative,
                "bodies": self.bodies}


@dataclass(frozen=True)
class Quadrature:
    """Points and weights of a rule on every simplex of a mesh.

    ``bary`` (d + 1, q) are the barycentric coordinates of the q points,
    ``points`` (dim, elements, q) their positions, ``dx`` (elements, q) the
    weights times the element's measure (times r when axisymmetric) and
    ``gradients`` (elements, d + 1, dim) those of the barycentric coordinates.
    """

    bary: np.ndarray
    points: np.ndarray
    dx: np.ndarray
    gradients: np.ndarray


def quadrature(mesh: Any, axisymmetric: bool = False, order: int | None = None) -> Quadrature:
    """The quadrature of order ``order`` on every simplex of ``mesh`` (triangles or tetrahedra);
    by default :data:`QUADRATURE_ORDER`, or :data:`AXISYMMETRIC_ORDER` when axisymmetric."""
    if order is None:
        order = AXISYMMETRIC_ORDER if axisymmetric else QUADRATURE_ORDER
    X, W = get_quadrature(mesh.refdom, order)
    bary = np.vstack([1.0 - X.sum(axis=0), X])
    gradients, jacobian = simplex_gradients(mesh)
    points = np.einsum("dke,kq->deq", np.take(mesh.p, mesh.t, axis=1), bary)
    dx = jacobian[:, None] * W[None, :]
    if axisymmetric:
        dx = dx * points[0]
    return Quadrature(bary=bary, points=points, dx=dx, gradients=gradients)


def strains(mesh: Any, u: np.ndarray, rule: Quadrature, axisymmetric: bool = False) -> np.ndarray:
    """The strain of the P1 field ``u`` (nodes, dim) at the quadrature points.

    Returns (components, elements, q): ``xx, yy, xy`` in 2D (``zz, yz, xz``
    added in 3D), then the hoop strain ``u_r / r`` when axisymmetric; tensor
    (not engineering) shears.
    """
    values = np.take(u, mesh.t, axis=0)  # (d + 1, elements, dim)
    grad = np.einsum("kei,ekj->eij", values, rule.gradients)  # ∂u_i/∂x_j per element
    q = rule.bary.shape[1]
    parts = [np.repeat((0.5 * (grad[:, i, j] + grad[:, j, i]))[:, None], q, axis=1)
             for i, j in STRAIN_PAIRS[grad.shape[1]]]
    if axisymmetric:
        u_r = np.einsum("ke,kq->eq", values[:, :, 0], rule.bary)
        parts.append(u_r / rule.points[0])
    return np.array(parts)


def energy_density(eps: np.ndarray, Lambda: float, Mu: float, dim: int,
                   trace: np.ndarray | None = None) -> np.ndarray:
    """``ε : C : ε = 2μ ε : ε + λ (tr ε)²`` of strains laid out as :func:`strains` gives them.

    The first ``dim`` components are the diagonal, the next ``dim (dim − 1) / 2``
    the shears (counted twice in ``ε : ε``) and one more, if any, the hoop strain.
    ``trace`` replaces ``tr ε`` in the λ term: the volumetric strain averaged at
    the nodes when K was assembled so (:mod:`signorini.fem.volumetric`). λ and μ are numbers
    or one per element (bodies of several materials).
    """
    Lambda, Mu = (np.reshape(x, np.shape(x) + (1,) * (eps.ndim - 1 - np.ndim(x)))
                  for x in (Lambda, Mu))
    shears = dim * (dim - 1) // 2
    diagonal = np.concatenate([eps[:dim], eps[dim + shears:]])
    if trace is None:
        trace = diagonal.sum(axis=0)
    squares = np.sum(diagonal ** 2, axis=0) + 2.0 * np.sum(eps[dim:dim + shears] ** 2, axis=0)
    return 2.0 * Mu * squares + Lambda * trace ** 2


def nodal_recovery(mesh: Any, eps: np.ndarray, rule: Quadrature) -> np.ndarray:
    """ZZ's recovered strain at the nodes (components, nodes): the lumped L² projection onto P1."""
    n = mesh.p.shape[1]
    mass = np.zeros(n)
    moments = np.zeros((len(eps), n))
    for k, nodes in enumerate(mesh.t):
        weight = rule.dx * rule.bary[k]  # φ_k times the weights, per element and point
        mass += np.bincount(nodes, weight.sum(axis=1), minlength=n)
        for c, component in enumerate(np.einsum("ceq,eq->ce", eps, weight)):
            moments[c] += np.bincount(nodes, component, minlength=n)
    return moments / mass


def constant_recovery(mesh: Any, eps: np.ndarray, volume: np.ndarray) -> np.ndarray:
    """:func:`nodal_recovery` of a strain constant on each simplex (components, elements) whose
    measures are ``volume``: every corner gets ``volume / (d + 1)`` of the element's weight (one
    sum over all corners at once per component, no quadrature points)."""
    corners, n = mesh.t.shape[0], mesh.p.shape[1]
    corner_of = mesh.t.ravel()  # corner k of every element, then corner k + 1, ...
    share = np.tile(volume / corners, corners)
    mass = np.bincount(corner_of, share, minlength=n)
    return np.array([np.bincount(corner_of, np.tile(component, corners) * share, minlength=n)
                     for component in eps]) / mass


def recover(mesh: Any, eps: np.ndarray, rule: Quadrature) -> np.ndarray:
    """ZZ's recovered strain at the quadrature points (:func:`nodal_recovery` interpolated)."""
    return np.einsum("cke,kq->ceq", np.take(nodal_recovery(mesh, eps, rule), mesh.t, axis=1),
                     rule.bary)


def element_energies(mesh: Any, u: np.ndarray, E: float, nu: float,
                     axisymmetric: bool = False) -> np.ndarray:
    """``a_K(u, u)`` on every element of ``mesh`` for the nodal field ``u`` (nodes, dim)."""
    rule = quadrature(mesh, axisymmetric)
    density = energy_density(strains(mesh, u, rule, axisymmetric), *lame(E, nu), mesh.p.shape[0])
    return np.sum(density * rule.dx, axis=1)


def material_units(problem: ContactProblem) -> tuple[Any, Any] | None:
    """Young's modulus in the problem's units and Poisson's ratio (None without a material):
    two numbers, or one of each per element for a mesh of several bodies.

    Assembly divides E by a stress scale ``force / (displacement · length^k)``
    (k = 1 in axisymmetric and 3D models), which is E itself for a scene made
    dimensionless and 1 otherwise.
    """
    model = problem.model
    if getattr(model.mesh, "p", None) is None:  # no finite-element mesh
        return None
    s = problem.scales
    k = 1 if (model.axisymmetric or model.mesh.p.shape[0] == 3) else 0
    stress = s.force / (s.displacement * s.length ** k)
    E, nu = model.element_materials()
    return E / stress, nu


def _by_quadrature(problem: ContactProblem, mesh: Any, u: np.ndarray, Lambda: float,
                   Mu: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray | None]:
    """Per element ``a(u_h, u_h)`` and ``a(e*, e*)``, the recovered nodal strain and volumetric
    strain (or None), by quadrature: axisymmetric models and the nodal volumetric average."""
    axisymmetric, dim = bool(problem.model.axisymmetric), mesh.p.shape[0]
    rule = quadrature(mesh, axisymmetric)
    eps = strains(mesh, u, rule, axisymmetric)
    theta = theta_points = jump = None
    if problem.model.volumetric == "nodal":
        # K's λ-part sees the volumetric strain averaged at the nodes, θ̄: a continuous P1 field
        # that is already ZZ's recovery of tr ε_h. Recovered once more (θ*), it smooths the
        # one-sided averages of the boundary nodes, which overstate the error (docs/estimate.md)
        theta_bar = nodal_volumetric_strain(mesh, u, axisymmetric)
        theta_points = np.einsum("ke,kq->eq", theta_bar[mesh.t], rule.bary)
        theta = nodal_recovery(mesh, theta_points[None], rule)[0]
        jump = np.einsum("ke,kq->eq", theta[mesh.t], rule.bary) - theta_points
    energy = np.sum(energy_density(eps, Lambda, Mu, dim, theta_points) * rule.dx, axis=1)
    nodal = nodal_recovery(mesh, eps, rule)
    recovered = np.einsum("cke,kq->ceq", np.take(nodal, mesh.t, axis=1), rule.bary)
    squares = np.sum(energy_density(recovered - eps, Lambda, Mu, dim, jump) * rule.dx, axis=1)
    return energy, squares, nodal, theta


def _constant_strains(mesh: Any, u: np.ndarray, Lambda: float,
                      Mu: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`_by_quadrature` in closed form where ε_h is constant per simplex (plane strain, 3D).

    The recovery error ``e* − ε_h = Σₖ δₖ φₖ`` (``δₖ``: the recovered strain at corner k
    minus ε_h) is linear, and ``∫ φₖ φₗ = V (1 + [k = l]) / ((d + 1)(d + 2))``, so that
    ``a(e* − ε_h, e* − ε_h) = V (a(Σδ, Σδ) + Σₖ a(δₖ, δₖ)) / ((d + 1)(d + 2))``: what the
    quadrature of order 2 gives (it is exact here), without its points.
    """
    dim = mesh.p.shape[0]
    gradients, volume = barycentric_gradients(mesh.p, mesh.t)  # (dim, d + 1, elements)
    values = np.take(u.T, mesh.t, axis=1)  # (dim, d + 1, elements)
    grad = np.einsum("ike,jke->ije", values, gradients)  # ∂u_i/∂x_j per element
    eps = np.array([0.5 * (grad[i, j] + grad[j, i]) for i, j in STRAIN_PAIRS[dim]])  # (c, e)
    energy = energy_density(eps, Lambda, Mu, dim) * volume
    corners = mesh.t.shape[0]
    nodal = constant_recovery(mesh, eps, volume)
    total = np.zeros_like(eps)
    own = np.zeros_like(volume)
    for nodes in mesh.t:
        delta = np.take(nodal, nodes, axis=1) - eps
        total += delta
        own += energy_density(delta, Lambda, Mu, dim)
    squares = volume * (energy_density(total, Lambda, Mu, dim) + own) / (corners * (corners + 1))
    return energy, squares, nodal


def estimate(problem: ContactProblem, solution: ContactSolution,
             contact: bool = True) -> ErrorEstimate | None:
    """The ZZ estimate of ``solution``'s energy-norm error (None without a mesh or a material).

    ``contact`` adds the complementarity term at the edge of the contact zone
    (2D models with pressures; see the module's docstring).
    """
    material = material_units(problem)
    if material is None or not np.all(np.isfinite(solution.u)):
        return None
    mesh, axisymmetric = problem.model.mesh, bool(problem.model.axisymmetric)
    Lambda, Mu = lame(*material)
    bodies = max(1, len(problem.model.materials))
    contact = contact and bodies == 1
    u = problem.model.expand(solution.u).reshape(-1, mesh.p.shape[0])
    if axisymmetric or problem.model.volumetric == "nodal":
        energy, squares, nodal, theta = _by_quadrature(problem, mesh, u, Lambda, Mu)
    else:
        energy, squares, nodal = _constant_strains(mesh, u, Lambda, Mu)
        theta = None
    recovery = float(np.sqrt(squares.sum()))
    contact_squares = np.zeros_like(squares)
    if contact and problem.weights is not None and np.all(np.isfinite(solution.lam)):
        try:
            nodes = candidate_nodes(mesh, problem.contact_points)
        except ValueError:
            nodes = None
        if nodes is not None:
            elements, values = contact_term(mesh, nodes, solution.lam / problem.weights,
                                            problem.gap(solution.u), axisymmetric)
            contact_squares += np.bincount(elements, values, minlength=len(squares))
    s = problem.scales
    return ErrorEstimate(elements=np.sqrt(squares + contact_squares), recovery=recovery,
                         contact=float(np.sqrt(contact_squares.sum())),
                         energy_norm=float(np.sqrt(energy.sum())),
                         scale=float(np.sqrt(s.force * s.displacement)),
                         pressure=pressure_estimate(problem, solution, nodal, Lambda, Mu, theta)
                         if contact else None, bodies=bodies)


__all__ = ["ErrorEstimate", "Quadrature", "quadrature", "strains", "energy_density",
           "nodal_recovery", "constant_recovery", "recover", "element_energies", "material_units",
           "estimate"]
