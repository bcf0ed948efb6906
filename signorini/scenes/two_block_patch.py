"""The contact patch test: an elastic block on an elastic block, faces meshed differently.

Plane strain (Taylor & Papadopoulos 1991). The lower block ``[0, W] × [−H1, 0]``
(E1, ν1) stands on its base (``u_y = 0``); the upper block ``[0, W] × [0, H2]``
(E2, ν2) is pushed down by δ on its top (``u_y = −δ``, u_x free). The side
x = 0 of each is a roller (``u_x = 0``): a symmetry plane of a pair 2W wide,
and what holds each body's last rigid motion, so that neither floats and K is
non-singular without relying on the contact. Every other boundary is free.

The exact answer is uniform in each body: ``σ_yy = −p``, ``σ_xx = 0``, with the
two blocks shortening like springs in series,

    p = δ / (H1/E1* + H2/E2*),   E* = E / (1 − ν²),

a linear displacement that P1 elements reproduce exactly. The parameter ``p``
sets δ by this formula (the push is prescribed either way: no load control).
The contact faces have ``nx`` and ``round(mesh_ratio · nx)`` elements (lower,
upper); the upper block is the slave, so ``mesh_ratio > 1`` makes the slave
finer and ``mesh_ratio < 1`` the master. A contact discretisation passes the
patch test when every slave node's pressure ``λ / w`` equals p: mortar does to
round-off, node-to-segment does not (docs/two-bodies.md).

The analytic reference is the block's (``uniform``, ``E*_pair δ / H``) with
``H = H1 + H2`` and the pair's modulus ``E*_pair = H / (H1/E1* + H2/E2*)``.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from skfem import MeshTri

from signorini.references.analytic import contact_modulus
from signorini.problem.model import ReferenceData
from signorini.errors import InputError
from signorini.fem.mortar import DISCRETISATIONS
from signorini.fem.topology import facets_on
from signorini.fem.two_bodies import Body, TwoBodyModel
from signorini.scenes.base import (VOLUMETRIC, Case, Param, SceneFamily, at_least, length, one_of,
                                   poisson_ratio, positive)
from signorini.scenes.size import CountedSize

__all__ = ["DISCRETISATION", "FAMILY", "compliance", "materials", "patch_pressure", "slave_elements"]

#: the analytic reference (signorini.references.catalogue) this family's problems compare with
REFERENCE = "uniform"

#: how the two contact faces are coupled (signorini.fem.mortar)
DISCRETISATION = Param("discretisation", "mortar", "mortar: dual (biorthogonal) mortar; "
                       "mortar-standard: standard mortar, D lumped; nts: node-to-segment, one pass",
                       kind=str, check=one_of(*DISCRETISATIONS))


def materials(first: str, second: str) -> tuple[Param, ...]:
    """The parameters E1, nu1 of the body named ``first`` and E2, nu2 of ``second``."""
    return tuple(Param(f"{name}{k}", default, f"{what} of the {body}", check=check)
                 for k, body in ((1, first), (2, second))
                 for name, default, what, check in (("E", 1.0, "Young's modulus", positive),
                                                    ("nu", 0.3, "Poisson's ratio", poisson_ratio)))


PARAMS = (
    Param("W", 1.0, "width of both blocks (x = 0 is a symmetry plane of a pair 2W wide)",
          check=length),
    Param("H1", 1.0, "height of the lower block", check=length),
    Param("H2", 1.0, "height of the upper block", check=length),
    *materials("lower block", "upper block"),
    VOLUMETRIC,
    Param("delta", None, "prescribed downward displacement of the upper block's top (default "
          "0.01 · (H1 + H2); exclusive with p)", check=positive),
    Param("p", None, "uniform contact pressure: sets delta = p (H1/E1* + H2/E2*) (exclusive with "
          "delta)", check=positive),
    Param("nx", 10, "elements along the lower block's contact face", kind=int, check=at_least(1)),
    Param("ny", 4, "elements along each block's height", kind=int, check=at_least(1)),
    Param("mesh_ratio", 1.7, "elements along the upper (slave) face over the lower (master) "
          "face's: non-matching unless an integer ratio", check=lambda r: None if 1e-3 <= r <= 1e3
          else "in [0.001, 1000]"),
    DISCRETISATION,
)


def compliance(p: dict[str, Any]) -> float:
    """``H1/E1* + H2/E2*``: the two blocks' compliances in series (push per unit pressure)."""
    return (p["H1"] / contact_modulus(p["E1"], p["nu1"])
            + p["H2"] / contact_modulus(p["E2"], p["nu2"]))


def _load_choice(p: dict[str, Any], given: set[str]) -> tuple[None, float]:
    """No target load (the push is prescribed) and the push δ: given, set by p, or the default."""
    if p["delta"] is not None and p["p"] is not None:
        raise InputError("scene parameters delta and p both set the load: give only one of them")
    if p["p"] is not None:
        return None, p["p"] * compliance(p)
    return None, p["delta"] if p["delta"] is not None else 0.01 * (p["H1"] + p["H2"])


def patch_pressure(p: dict[str, Any]) -> float:
    """The uniform contact pressure of the patch test, ``δ / (H1/E1* + H2/E2*)``."""
    return _load_choice(p, set())[1] / compliance(p)


def slave_elements(p: dict[str, Any]) -> int:
    """The upper (slave) face's elements, ``round(mesh_ratio · nx)``; refused below one."""
    count = round(p["mesh_ratio"] * p["nx"])
    if count < 1:
        raise InputError(f"scene parameter mesh_ratio={p['mesh_ratio']:g} gives the upper face "
                         f"round(mesh_ratio · nx) = 0 elements with nx={p['nx']}: raise "
                         f"mesh_ratio above {0.5 / p['nx']:g} or raise nx")
    return count


def _block(width: float, bottom: float, top: float, nx: int, ny: int) -> MeshTri:
    return MeshTri.init_tensor(np.linspace(0.0, width, nx + 1), np.linspace(bottom, top, ny + 1))


def _on(mesh: MeshTri, component: int, value: float, scale: float) -> np.ndarray:
    """The nodes of ``mesh`` whose coordinate ``component`` is ``value``."""
    return np.flatnonzero(np.abs(mesh.p[component] - value) < 1e-12 * scale)


def build(p: dict[str, Any], given: set[str] | None = None) -> TwoBodyModel:
    """The two blocks in physical units: upper (slave) on lower (master)."""
    _, delta = _load_choice(p, set() if given is None else given)
    W, H1, H2 = p["W"], p["H1"], p["H2"]
    scale = max(W, H1, H2)
    upper_nx = slave_elements(p)
    lower, upper = _block(W, -H1, 0.0, p["nx"], p["ny"]), _block(W, 0.0, H2, upper_nx, p["ny"])
    lower_face, upper_face = _on(lower, 1, 0.0, scale), _on(upper, 1, 0.0, scale)
    top = _on(upper, 1, H2, scale)
    slave = Body(mesh=upper, E=p["E2"], nu=p["nu2"],
                 dirichlet=[(0, _on(upper, 0, 0.0, scale), 0.0), (1, top, -delta)],
                 contact_facets=facets_on(upper, upper_face), load_nodes=top,
                 volumetric=p["volumetric"])
    master = Body(mesh=lower, E=p["E1"], nu=p["nu1"],
                  dirichlet=[(0, _on(lower, 0, 0.0, scale), 0.0), (1, _on(lower, 1, -H1, scale), 0.0)],
                  contact_facets=facets_on(lower, lower_face), volumetric=p["volumetric"])
    H = H1 + H2
    return TwoBodyModel(
        slave=slave, master=master, discretisation=p["discretisation"], length_scale=scale,
        force_multiplicity=2.0, reference=ReferenceData(REFERENCE, E_star=H / compliance(p), H=H),
        params=dict(p, delta=delta))


def mesh_dofs(p: dict[str, Any]) -> float:
    """The dofs of the two structured meshes: two per node of each grid."""
    return 2.0 * (p["nx"] + 1 + slave_elements(p) + 1) * (p["ny"] + 1)


FAMILY = SceneFamily(
    name="two-block-patch",
    summary="contact patch test: an elastic block on an elastic block, non-matching faces",
    params=PARAMS, build=build, loads=_load_choice, reference=REFERENCE,
    size_model=CountedSize(mesh_dofs),
    validation=(Case("two-block-patch", "two-block-patch",
                     {"E1": 1.0, "nu1": 0.3, "E2": 3.0, "nu2": 0.2, "H2": 0.7}),))
