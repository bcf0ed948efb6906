"""An elastic block pressed onto a rigid flat: uniform pressure, checkable by hand.

The right half ``[0, W] × [0, H]`` of a ``2W``-wide block, plane strain: the
cut x = 0 is a symmetry plane, the top is pushed down by δ (u_x free), the
bottom rests on the flat ``y = 0`` without friction. Every bottom node is in
contact with the pressure ``p = E* δ / H`` (uniaxial plane strain), so the
full block carries ``P = 2 W p`` per unit thickness.

Two variants serve the stability atlas (:mod:`signorini.studies.atlas`):

- ``touching > 0`` (a scene parameter): only the bottom nodes with
  ``x < (1 − touching) W`` rest on the flat; under the outer part the
  obstacle is shaped exactly to where the unsupported bottom goes. Those
  nodes end up touching with zero force: weakly active, gap 0 and λ 0.
- :func:`force_controlled_problem`: the top carries a uniform pressure q
  instead of a prescribed push, so nothing but the contact holds the block
  in y and K is singular (force control).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from skfem import MeshTri

from signorini.references.analytic import contact_modulus
from signorini.problem.model import ReferenceData
from signorini.errors import InputError
from signorini.fem.assembly import assemble, contact_weights
from signorini.fem.model import FlatObstacle, SceneModel
from signorini.fem.obstacles import ScaledQuery
from signorini.fem.topology import facets_on
from signorini.numerics.factor import factorize
from signorini.numerics.lcp import delassus, solve_lcp
from signorini.problem.contact import ContactProblem, ContactSolution, Scales
from signorini.scenes.base import (VOLUMETRIC, Case, Param, SceneFamily, at_least, length, poisson_ratio,
                                   positive, scene_params)
from signorini.scenes.size import CountedSize

#: the analytic reference (signorini.references.catalogue) this family's problems compare with
REFERENCE = "uniform"

PARAMS = (
    Param("W", 1.0, "half-width of the block", check=length),
    Param("H", 1.0, "height of the block", check=length),
    Param("E", 1.0, "Young's modulus", check=positive),
    Param("nu", 0.3, "Poisson's ratio", check=poisson_ratio),
    VOLUMETRIC,
    Param("delta", 0.01, "prescribed downward displacement of the top", check=positive),
    Param("nx", 16, "elements along the width", kind=int, check=at_least(1)),
    Param("ny", 16, "elements along the height", kind=int, check=at_least(1)),
    Param("touching", 0.0, "outer fraction of the bottom that touches an obstacle shaped to the "
          "unsupported bottom with zero force (weakly active nodes); 0 = the plain block",
          check=lambda t: None if 0.0 <= t < 1.0 else "in [0, 1)"),
)


@dataclass(frozen=True)
class HeightProfile:
    """A rigid obstacle ``y = h(x)`` under the body, h piecewise linear through ``(x_k, h_k)``.

    The normal is taken as (0, −1) everywhere and the gap is the vertical
    distance ``y − h(x)`` (small slopes, small displacements).
    """

    x: tuple[float, ...]
    height: tuple[float, ...]

    def normals_and_gaps(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Normal (0, −1) and gap ``y − h(x)`` at each point."""
        points = np.atleast_2d(np.asarray(points, dtype=float))
        normals = np.tile([0.0, -1.0], (len(points), 1))
        return normals, points[:, 1] - np.interp(points[:, 0], self.x, self.height)


def _mesh_parts(p: dict[str, Any]) -> tuple[MeshTri, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The mesh, its bottom nodes sorted by x, the bottom facets, the top and the symmetry nodes."""
    mesh = MeshTri.init_tensor(np.linspace(0.0, p["W"], p["nx"] + 1),
                               np.linspace(0.0, p["H"], p["ny"] + 1))
    x, y = mesh.p
    tol = 1e-12 * max(p["W"], p["H"])
    bottom = np.nonzero(np.abs(y) < tol)[0]
    bottom = bottom[np.argsort(x[bottom])]
    bottom_facets = facets_on(mesh, bottom)
    top = np.nonzero(np.abs(y - p["H"]) < tol)[0]
    symmetry = np.nonzero(np.abs(x) < tol)[0]
    return mesh, bottom, bottom_facets, top, symmetry


def _plain_model(p: dict[str, Any], contact_nodes: np.ndarray | None = None,
                 obstacle: Any = None) -> SceneModel:
    mesh, bottom, bottom_facets, top, symmetry = _mesh_parts(p)
    nodes = bottom if contact_nodes is None else contact_nodes
    facets = bottom_facets[np.all(np.isin(mesh.facets[:, bottom_facets], nodes), axis=0)]
    return SceneModel(
        mesh=mesh, E=p["E"], nu=p["nu"],
        dirichlet=[(0, symmetry, 0.0), (1, top, -p["delta"])],
        contact_nodes=nodes, contact_facets=facets,
        obstacle=FlatObstacle(0.0) if obstacle is None else obstacle, load_dofs=(1, top),
        length_scale=p["H"], force_multiplicity=2.0, params=dict(p),
        volumetric_choice=p["volumetric"], delta=p["delta"],
        reference=ReferenceData(REFERENCE, E_star=contact_modulus(p["E"], p["nu"]), H=p["H"]))


def build(p: dict[str, Any], given: set[str] | None = None) -> SceneModel:
    """The half block in physical units (with a touching outer part when ``touching > 0``)."""
    return _touching_model(p) if p.get("touching") else _plain_model(p)


def _touching_model(p: dict[str, Any]) -> SceneModel:
    """Bottom supported on ``x < (1 − touching) W``; the rest meets an obstacle at its own deflection.

    The problem with only the supported nodes as candidates is solved first
    (exactly, on its condensed LCP); under each outer bottom node the obstacle is then placed at
    that node's deflected height. The solution of the full problem is the same
    one, and at the outer nodes both the gap and the force are zero.
    """
    mesh, bottom, _, _, _ = _mesh_parts(p)
    x = mesh.p[0]
    # the outer corner x = W always touches
    supported = bottom[x[bottom] < (1.0 - p["touching"]) * p["W"] * (1 - 1e-12)]
    problem = assemble(_plain_model(p, contact_nodes=supported))
    factor = factorize(problem.K)
    try:
        lam, _ = solve_lcp(delassus(problem.N, factor), problem.N @ factor.solve(problem.f) - problem.d)
    except ArithmeticError as exc:  # pragma: no cover - the LCP of an SPD W is solvable
        raise InputError(f"scene parameter touching={p['touching']!r}: the supported block did not "
                         f"solve ({exc})") from None
    u = factor.solve(problem.f - problem.N.T @ lam)
    full = problem.model.expand(u) * problem.scales.displacement
    deflection = full[problem.model.basis.nodal_dofs[1, bottom]]
    height = np.where(np.isin(bottom, supported), 0.0, deflection)
    profile = HeightProfile(tuple(x[bottom]), tuple(height))
    obstacle = ScaledQuery(profile, mesh.p[:, bottom].T, p["H"])
    return _plain_model(p, obstacle=obstacle)


def mesh_dofs(p: dict[str, Any]) -> float:
    """The dofs of the block's structured mesh: two per node of its (nx + 1) × (ny + 1) grid."""
    return 2.0 * (p["nx"] + 1) * (p["ny"] + 1)


FAMILY = SceneFamily(name="block", summary="elastic block pressed onto a rigid flat (uniform pressure)",
                     params=PARAMS, build=build, reference=REFERENCE, size_model=CountedSize(mesh_dofs),
                     validation=(Case("block", "block"),))


# --- force control: a body held only by contact --------------------------------------------------


def force_controlled_problem(pressure: float = 0.01, params: dict[str, Any] | None = None, *,
                             nondimensionalise: bool = True) -> ContactProblem:
    """The half block under a uniform pressure q on its top: held in y by the contact alone.

    Only the symmetry plane is prescribed (``u_x = 0`` at x = 0), so K is
    singular: the rigid translation ``t`` (``u_y = 1`` at every node) has
    ``K t = 0``. The QP ``min ½uᵀKu − fᵀu, Nu ≤ d`` still has one solution
    because every candidate blocks ``−t`` (``N(−t) = 1 > 0 = d``) and the load
    pushes along it (``fᵀt = −2Wq·½ < 0``): the patch solution

        p = q at every bottom node,  u_y = −q(1 − ν²) y / E,  u_x = q ν(1 + ν) x / E

    (exact for P1, see :func:`force_controlled_exact`). Methods that need
    ``K⁻¹`` cannot solve it as it stands; :func:`signorini.certification.diagnosis.regularise`
    adds a documented small stiffness.

    Parameters
    ----------
    pressure : the uniform pressure q on the top (physical units, > 0).
    params : the block's scene parameters (``W``, ``H``, ``E``, ``nu``, ``nx``, ``ny``) by name;
        ``delta`` and ``touching`` do not apply.
    nondimensionalise : scale as :func:`signorini.fem.assembly.assemble` does, with the
        displacement unit ``q H / E*`` (the size of the answer).

    Returns
    -------
    ContactProblem
        with ``params["pressure"] = q``; its ``load_offset`` is the applied load 2Wq.
    """
    values = scene_params(params)
    for name in ("delta", "touching"):
        if name in values:
            raise InputError(f"scene parameter {name} does not apply to the force-controlled "
                             "block: it is loaded by pressure=<q> alone")
    p = FAMILY.parse(values)
    if isinstance(pressure, bool) or not isinstance(pressure, (int, float)) \
            or not (math.isfinite(pressure) and pressure > 0):
        raise InputError(f"pressure={pressure!r} must be a finite number > 0 (the load on the top)")
    p["pressure"] = float(pressure)
    mesh, bottom, bottom_facets, top, symmetry = _mesh_parts(p)
    model = SceneModel(mesh=mesh, E=p["E"], nu=p["nu"], dirichlet=[(0, symmetry, 0.0)],
                       contact_nodes=bottom, contact_facets=bottom_facets,
                       obstacle=FlatObstacle(0.0), load_dofs=(1, top), length_scale=p["H"],
                       force_multiplicity=2.0, params=dict(p), volumetric_choice=p["volumetric"])
    problem = assemble(model, nondimensionalise=nondimensionalise)
    basis = problem.model.basis
    L, E = problem.scales.length, (p["E"] if nondimensionalise else 1.0)
    U = p["pressure"] * p["H"] * (1.0 - p["nu"] ** 2) / p["E"] if nondimensionalise else 1.0
    force = E * U  # plane strain: forces per unit thickness in units of E·U
    facets = problem.model.mesh.boundary_facets()
    on_top = np.all(np.isin(problem.model.mesh.facets[:, facets], top), axis=0)
    weights = contact_weights(problem.model.mesh, facets[on_top], top) * L  # physical lengths
    load = np.zeros(basis.N)
    load[basis.nodal_dofs[1, top]] = -p["pressure"] * weights / force
    problem = problem.with_data(
        f=load[problem.model.free_dofs], load_row=np.zeros(problem.n),
        load_offset=2.0 * p["W"] * p["pressure"] / force, push=None,
        scales=Scales(length=L, displacement=U, force=force, weight=L), params=dict(p),
        name="block (force control)")
    problem.model.basis = basis
    return problem


def force_controlled_exact(problem: ContactProblem) -> ContactSolution:
    """The exact (patch) solution of :func:`force_controlled_problem`, in the problem's units.

    ``u_x = q ν(1 + ν) x / E``, ``u_y = −q (1 − ν²) y / E`` and ``λᵢ = q wᵢ``:
    a homogeneous stress ``σ_yy = −q``, reproduced exactly by P1 elements.
    """
    p, s = problem.model.params, problem.scales
    q, E, nu = p["pressure"], p["E"], p["nu"]
    x, y = problem.model.mesh.p * s.length
    full = np.zeros(problem.model.basis.N)
    full[problem.model.basis.nodal_dofs[0]] = q * nu * (1.0 + nu) * x / E
    full[problem.model.basis.nodal_dofs[1]] = -q * (1.0 - nu ** 2) * y / E
    u = full[problem.model.free_dofs] / s.displacement
    lam = q * problem.weights * s.weight / s.force
    return ContactSolution(method="exact", u=u, lam=lam, status="converged",
                           message="patch solution of the force-controlled block")


__all__ = ["HeightProfile", "build", "mesh_dofs", "force_controlled_problem",
           "force_controlled_exact", "FAMILY"]
