"""A rigid flat punch pressed into an elastic block, plane strain (frictionless).

The block ``[−W, W] × [0, H]`` rests on a rigid flat-ended punch of
half-width a whose face is the line y = 0 under ``|x| ≤ a`` (the obstacle is
the punch; the block's bottom face is the contact candidate). The block's top
is pushed down by a uniform δ (u_y = −δ, u_x free) adjusted until the contact
force equals the target load P. By default the right half ``x ≥ 0`` is
modelled with the symmetry plane x = 0 (u_x = 0); ``half=0`` models the
whole width (then u_x = 0 at the top's centre removes the rigid sliding).

Sharp corners (``corner_radius = 0``): the contact zone is the face itself,
every node under it touches, and for a block much larger than the punch the
pressure approaches the half-plane solution (Johnson 1985, ch. 2)
``p(x) = P / (π √(a² − x²))``, singular at the edges. Only the nodes under
the face are candidates: the surface beside a sharp punch moves away from
its vertical sides. Rounded corners (``corner_radius = r > 0``): the face
falls away along quarter circles of radius r beyond ``|x| = a``, the contact
spreads onto them with the load and the pressure stays bounded; the
candidates then extend to ``|x| ≤ a + r``.

The mesh is graded towards the contact zone with ``n_contact`` elements
across a and ``refine`` further uniform refinements.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from skfem import MeshTri

from signorini.references.analytic import contact_modulus
from signorini.problem.model import ReferenceData
from signorini.errors import InputError
from signorini.fem.model import SceneModel
from signorini.fem.obstacles import FlatPunch, Obstacle, ScaledQuery
from signorini.fem.topology import facets_on
from signorini.scenes.base import (
    HALF,
    VOLUMETRIC,
    Case,
    Param,
    SceneFamily,
    at_least,
    between,
    block_size,
    chosen_load,
    grading,
    length,
    poisson_ratio,
    positive,
    refinements,
    two_refinements_coarser,
)
from signorini.scenes.meshing import distance_to_segment, refine_to_size
from signorini.scenes.size import SizeModel

__all__ = ["FAMILY", "block_on_obstacle", "graded_half_block", "load_choice", "mirrored_about_x0"]

PARAMS = (
    Param("a", 1.0, "half-width of the punch's flat face", check=length),
    Param("corner_radius", 0.0, "radius of the punch's rounded corners (0: sharp)",
          check=at_least(0.0)),
    Param("size", 20.0, "block half-width and height in units of a", check=block_size(2.0)),
    Param("E", 1.0, "Young's modulus of the block", check=positive),
    Param("nu", 0.3, "Poisson's ratio of the block", check=poisson_ratio),
    VOLUMETRIC,
    Param("P", None, "load per unit thickness of the whole block (exclusive with load_ratio, delta)",
          check=positive),
    Param("load_ratio", 0.005, "P / (E* a): sets the load when neither P nor delta is given",
          check=between(0.0, 1.0)),
    Param("delta", None, "prescribed downward displacement of the top (no load targeting)",
          check=positive),
    Param("n_contact", 128, "elements across the punch half-width a (rounded up to a power of two)",
          kind=int, check=at_least(2)),
    grading(0.2),
    refinements(),
    HALF,
)


def load_choice(p: dict[str, Any], given: set[str]) -> tuple[float | None, float | None]:
    """The target load (None when δ is prescribed) and the prescribed δ (None when targeted).

    One of ``P``, ``load_ratio`` (the default, ``P = load_ratio · E* · a``)
    or ``delta`` sets the load, once the corners fit in the block.
    """
    if p["corner_radius"] > 0.5 * p["size"] * p["a"]:
        raise InputError(f"scene parameter corner_radius={p['corner_radius']:g} must be less than "
                         f"half the block (size · a / 2 = {0.5 * p['size'] * p['a']:g})")
    chosen = chosen_load(p, given, ("P", "load_ratio", "delta"))
    if "delta" in chosen:
        return None, p["delta"]
    if "P" in chosen:
        return p["P"], None
    return p["load_ratio"] * contact_modulus(p["E"], p["nu"]) * p["a"], None


def _coarse_coordinates(zone: float, extent: float) -> np.ndarray:
    """0, zone/2, zone, then doubling steps up to ``extent`` (a coarse grid line)."""
    points = [0.0, 0.5 * zone, zone]
    step = zone
    while points[-1] + 1.5 * step < extent:
        points.append(points[-1] + step)
        step *= 2.0
    points.append(extent)
    return np.array(points)


def graded_half_block(width: float, height: float, fine_end: float, n_contact: int,
                      grading: float, refine: int = 0, kinks: tuple[float, ...] = ()) -> MeshTri:
    """Triangles of ``[0, width] × [0, height]`` graded towards ``[0, fine_end]`` on y = 0.

    Lengths are in units of the contact half-width. The coarse grid has
    nodes at 0, ½, 1, then doubling steps, plus ``fine_end`` and ``kinks`` on
    the bottom line; elements are split (conforming local refinement) until
    their longest edge is at most ``√2 / n_contact + grading · dist(x, [0, fine_end] × {0})``
    (and a quarter of the smaller side), so the bottom edges next to the
    contact have length ``1 / n_contact`` rounded down to a power of two
    (``n_contact`` elements across the half-width when it is a power of two);
    ``refine`` uniform refinements follow.
    """
    xs = np.union1d(_coarse_coordinates(1.0, width),
                    [k for k in (fine_end,) + tuple(kinks) if 0 < k < width])
    mesh = MeshTri.init_tensor(xs, _coarse_coordinates(1.0, height))
    h_contact = np.sqrt(2.0) / n_contact
    cap = 0.25 * min(width, height)

    def target_size(points: np.ndarray) -> np.ndarray:
        dist = distance_to_segment(points, np.zeros(2), np.array([fine_end, 0.0]))
        return np.minimum(h_contact + grading * dist, cap)

    mesh = refine_to_size(mesh, target_size)
    return mesh.refined(refine) if refine else mesh


def mirrored_about_x0(mesh: MeshTri) -> MeshTri:
    """The mesh and its mirror image in the line x = 0, sharing the nodes on it."""
    p, t = mesh.p, mesh.t
    on_axis = np.abs(p[0]) <= 1e-14 * max(1.0, float(np.max(np.abs(p))))
    image = np.empty(p.shape[1], dtype=np.int64)
    off = np.nonzero(~on_axis)[0]
    image[on_axis] = np.nonzero(on_axis)[0]
    image[off] = p.shape[1] + np.arange(off.size)
    points = np.hstack([p, np.vstack([-p[0, off], p[1, off]])])
    mirror_t = image[t][[0, 2, 1]]  # reflected triangles, orientation restored
    return MeshTri(points, np.hstack([t, mirror_t]))


def block_on_obstacle(p: dict[str, Any], *, scale: float, fine_end: float, candidate_end: float,
                      obstacle: Obstacle, target: float | None, delta: float | None,
                      indentation: float, params: dict[str, Any],
                      reference: ReferenceData) -> SceneModel:
    """A block (half or whole, ``p["half"]``) whose bottom y = 0 is the contact candidate, pushed
    down at the top: :func:`graded_half_block` of the scene's ``size``, ``n_contact``,
    ``grading`` and ``refine``, towards ``[0, fine_end]``.

    ``fine_end`` and ``candidate_end`` are in units of ``scale``; the model (and ``obstacle``)
    are in physical units. The candidates are the bottom nodes with ``|x| ≤ candidate_end``,
    sorted by x. Without a prescribed ``delta``, the first guess of the push is the block's
    compression plus an indentation, ``P/E* · (1/(2 size) + indentation)``. ``params`` are the
    scene's parameters as its problem reports them, ``reference`` what its analytic reference
    reads.
    """
    height = p["size"]
    mesh = graded_half_block(height, height, fine_end, p["n_contact"], p["grading"], p["refine"],
                             kinks=(candidate_end,))
    if not p["half"]:
        mesh = mirrored_about_x0(mesh)
    delta_nominal = delta if delta is not None else \
        (target / contact_modulus(p["E"], p["nu"])) * (1.0 / (2.0 * height) + indentation)
    x, y = mesh.p
    tol = 1e-12 * height
    bottom = np.nonzero(np.abs(y) <= tol)[0]
    top = np.nonzero(np.abs(y - height) <= tol)[0]
    bottom_facets = facets_on(mesh, bottom)
    candidates = bottom[np.abs(x[bottom]) <= candidate_end * (1 + 1e-9)]
    candidates = candidates[np.argsort(x[candidates], kind="stable")]
    if p["half"]:
        dirichlet = [(0, np.nonzero(np.abs(x) <= tol)[0], 0.0), (1, top, -delta_nominal)]
    else:
        centre = top[np.argmin(np.abs(x[top]))]
        dirichlet = [(0, np.array([centre]), 0.0), (1, top, -delta_nominal)]
    mesh = MeshTri(mesh.p * scale, mesh.t)
    return SceneModel(
        mesh=mesh, E=p["E"], nu=p["nu"], dirichlet=dirichlet, contact_nodes=candidates,
        contact_facets=bottom_facets,
        obstacle=ScaledQuery(obstacle, mesh.p[:, candidates].T, scale),
        load_dofs=(1, top), length_scale=scale, force_multiplicity=2.0 if p["half"] else 1.0,
        target_load=target, params=params, volumetric_choice=params["volumetric"],
        delta=delta_nominal, reference=reference)


def build(p: dict[str, Any], given: set[str] | None = None) -> SceneModel:
    """The punch scene in physical units."""
    a, r = p["a"], p["corner_radius"]
    target, delta = load_choice(p, set() if given is None else given)
    E_star = contact_modulus(p["E"], p["nu"])
    zone = 1.0 + r / a
    params = dict(p, P=target, delta=delta, load_ratio=None if target is None else target / (E_star * a))
    return block_on_obstacle(
        p, scale=a, fine_end=zone, candidate_end=zone,
        obstacle=FlatPunch(half_width=a, corner_radius=r), target=target, delta=delta,
        indentation=1.0 / np.pi, params=params,
        reference=ReferenceData(REFERENCE, E_star=E_star, a=a, corner_radius=r))


#: the analytic reference (signorini.references.catalogue) this family's problems compare with
REFERENCE = "punch"


FAMILY = SceneFamily(
    name="punch",
    summary="rigid flat punch (sharp or rounded corners) pressed into an elastic block, plane strain",
    params=PARAMS, build=build, loads=load_choice, reference=REFERENCE,
    # the default mesh's dofs and how they grow, fitted to the meshes built (docs/calibration.md)
    size_model=SizeModel(7948, 128, 0.2, uniform=6082.0, alpha=0.55, beta=1.5, far_field=1200.0,
                         margin=1.13, block=True),
    coarse=two_refinements_coarser, validation=(Case("punch", "punch"),),
    convergence_start={"n_contact": 16, "grading": 0.6})
