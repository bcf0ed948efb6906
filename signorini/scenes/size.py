"""A scene's size before it is meshed: estimated dofs and memory, refused above what the machine holds.

Each family's ``size_model`` (:data:`SIZE_MODELS` by name) estimates its dofs from its
parameters, bounding the mesh it builds from above (tests/test_size_guard.py holds each estimate
between 1 and 1.3 times the dofs built over grading 0.05..2, n_contact and refine;
tests/test_scene_size.py within a factor 1.5 over the parameters' ranges): a 2D graded mesh by
:class:`SizeModel`, the 3D octant from the number of tetrahedra its target element size asks for
(:class:`signorini.scenes.hertz_sphere_3d.GradedOctant`), a structured mesh counted exactly
(:class:`CountedSize`).

Memory is the peak resident size of building the scene and solving it, in
bytes per dof: :data:`BYTES_PER_DOF` with a factorising method;
:data:`BYTES_PER_DOF_3D_PUSHED` in 3D without one (a prescribed push, or a
target load matched by a method that declares it factorises nothing from that many dofs on,
``Method.factor_free_from``: :class:`Solver`); a 3D factorisation's fill grows like n^⅓ per dof
from :data:`FILL_GROWS_FROM` dofs on; :data:`NODAL_MEMORY` scales it all when
the volumetric strain is averaged at the nodes. The constants were chosen
from measurements (docs/calibration.md).

A scene whose estimate exceeds :func:`memory_limit` — by default three
quarters of this machine's physical memory, or ``SIGNORINI_MAX_MEMORY_GB`` —
is refused with one line before any mesh is made.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from typing import Any, Callable, Protocol

import numpy as np

from signorini.errors import InputError
from signorini.fem.model import resolve
from signorini.numerics.factor import gigabytes_from
from signorini.scenes.meshing import MAX_ELEMENTS, MAX_TRIANGLES
from signorini.scenes.registry import SCENES, FamilyField

#: the environment variable that raises (or lowers) the memory a scene may take, in GB
MEMORY_VARIABLE = "SIGNORINI_MAX_MEMORY_GB"
#: bytes per dof of building a scene and solving it with pdas (see the module's docstring)
BYTES_PER_DOF = {2: 4_000, 3: 20_000}
#: bytes per dof of a 3D scene given a push (no load targeting): pdas-amg, no factorisation
BYTES_PER_DOF_3D_PUSHED = 5_000
#: from this many 3D dofs a factorisation's bytes per dof grow like (dofs / this)^⅓
FILL_GROWS_FROM = 350_000
#: tetrahedra per dof of the 3D octant's meshes (chosen from measurements, docs/calibration.md)
TETRAHEDRA_PER_DOF = 1.9
#: elements per dof of the graded meshes: a triangle mesh has about twice as many triangles as
#: nodes, one per dof
ELEMENTS_PER_DOF = {2: 1.0, 3: TETRAHEDRA_PER_DOF}
#: the estimate a graded mesh may reach: the 3D mesher's limit; twice the 2D mesher's (the
#: estimate is within a factor 1.5, and the last refinement pass may overshoot the limit)
GRADED_LIMIT = {2: 2 * MAX_TRIANGLES, 3: MAX_ELEMENTS}
ELEMENT_NAMES = {2: "triangles", 3: "tetrahedra"}
#: peak memory with the volumetric strain averaged at the nodes over plain P1, same scene and
#: default method (chosen from measurements at ν = 0.45, docs/calibration.md)
NODAL_MEMORY = {2: 2.2, 3: 2.6}


class Solver(Protocol):
    """What the size guard asks of the method that will solve a scene (a
    :class:`signorini.solvers.base.Method` declares it): from how many dofs it solves a 3D model
    with a target load without any factorisation (None: it factorises at every size)."""

    factor_free_from: float | None


def bytes_per_dof(dim: int, dofs: float, params: dict[str, Any],
                  solved_by: Solver | None = None) -> float:
    """Memory per dof of building and solving a scene (see the module's docstring) with the
    method ``solved_by`` (None: load targeting factorises)."""
    return _plain_bytes_per_dof(dim, dofs, params, solved_by) * (
        NODAL_MEMORY[dim] if resolve(params.get("volumetric", "auto"), params.get("nu", 0.0), dim)
        == "nodal" else 1.0)


def _plain_bytes_per_dof(dim: int, dofs: float, params: dict[str, Any],
                         solved_by: Solver | None = None) -> float:
    if dim == 2:
        return BYTES_PER_DOF[2]
    if params.get("delta") is not None and params.get("P") is None:
        return BYTES_PER_DOF_3D_PUSHED
    free_from = None if solved_by is None else solved_by.factor_free_from
    if free_from is not None and dofs >= free_from:
        return BYTES_PER_DOF_3D_PUSHED  # the method matches the load: no factorisation
    return BYTES_PER_DOF[3] * max(1.0, dofs / FILL_GROWS_FROM) ** (1 / 3)


#: the estimate's factor for the Hertz discs meshed by Triangle (``mesher=triangle``): over
#: grading 0.05..2 its meshes had up to 1.18 times the nodes of the relaxed mesh of the same
#: parameters (more where the grading is fine or coarse, fewer between; docs/calibration.md)
TRIANGLE_DOFS = 1.2
#: a half-block's far field per unit of ln(size / 20) (docs/calibration.md)
BLOCK_FAR_GROWTH = 1.4


@dataclass(frozen=True)
class SizeModel:
    """A 2D family's default mesh (``dofs`` at ``n_contact``, ``grading`` and ``a_over_R``) and how
    its dofs grow, calibrated per family (docs/calibration.md)::

        dofs ≈ m · [b + (dofs₀ − b) · (n_contact / n₀)^α · (grading₀ / grading)^β
                · (1 + ¼ ln(a₀ / a))] · 4^refine

    with α ``alpha``, β ``beta``, the far field b ``far_field`` that every mesh has and m the
    ``margin`` that lifts the estimate over every mesh measured; a the contact ratio the mesh is
    graded for, from the load. Never more than the uniform mesh at the contact's element size,
    ``uniform · (n_contact / a)^d · 2^(d · refine)``."""

    dofs: float
    n_contact: float
    grading: float
    a_over_R: float | None = None
    uniform: float | None = None
    alpha: float = 0.75
    beta: float = 1.35
    far_field: float = 300.0
    margin: float = 1.0
    #: n_contact is rounded up to a power of two (the half-block meshes), and ``half=0`` mirrors
    block: bool = False
    #: the a/R the mesh is graded for, from the parameters (None: ``a_over_R``)
    ratio: Callable[[dict[str, Any]], float] | None = None
    dim: int = 2

    def estimate(self, p: dict[str, Any]) -> float:
        """The dofs of a mesh with checked parameters ``p``: inf where they overflow a float
        (the size check then refuses them, naming the mesh parameters)."""
        return self.graded(p) * 2.0 ** (self.dim * p.get("refine", 0))

    def graded(self, p: dict[str, Any]) -> float:
        """The dofs of the graded mesh, before any uniform refinement."""
        n = np.float64(p["n_contact"])
        if self.block:  # the bottom's edges are 1/n_contact rounded down to a power of two
            n = 2.0 ** np.ceil(np.log2(n))
        a = self.ratio(p) if self.ratio is not None else p.get("a_over_R")
        with np.errstate(over="ignore", divide="ignore"):  # an overflow is an infinite estimate
            dofs = (self.dofs - self.far_field) * (n / self.n_contact) ** self.alpha
            dofs *= (self.grading / np.float64(p["grading"])) ** self.beta
            if self.a_over_R is not None and a is not None and a < self.a_over_R:
                dofs *= 1.0 + 0.25 * math.log(self.a_over_R / a)
            far = self.far_field
            if self.block:  # the far field grows with the log of the block's size (20 a: 1)
                far *= 1.0 + BLOCK_FAR_GROWTH * math.log(max(p.get("size", 20.0) / 20.0, 1.0))
                far *= min(1.0, n / self.n_contact) ** 0.25  # and shrinks with a coarser contact
            dofs = self.margin * (dofs + far)
            if self.uniform is not None:  # no finer than uniform at the contact's element size
                dofs = min(dofs, self.uniform * (n / (a or 1.0)) ** self.dim)
            if p.get("mesher") == "triangle":
                dofs *= TRIANGLE_DOFS
            return float(dofs * (2.0 if self.block and p.get("half", 1) == 0 else 1.0))


@dataclass(frozen=True)
class CountedSize:
    """A mesh whose dofs are counted from its parameters, ``dofs(p)`` (e.g. a structured
    block's ``2 (nx + 1)(ny + 1)``): the estimate is exact, and nothing is graded."""

    dofs: Callable[[dict[str, Any]], float]
    dim: int = 2

    def estimate(self, p: dict[str, Any]) -> float:
        return float(self.dofs(p))

    def graded(self, p: dict[str, Any]) -> float:
        return self.estimate(p)


#: each family's size model by name (a live view of :attr:`SceneFamily.size_model`)
SIZE_MODELS = FamilyField("size_model")


def estimate_dofs(family: str, params: dict[str, Any]) -> tuple[float, int] | None:
    """``(dofs, dimension)`` of scene ``family`` with checked ``params``; None when unknown."""
    model = SCENES[family].size_model if family in SCENES else None
    return None if model is None else (model.estimate(params), model.dim)
def physical_memory() -> float:
    """This machine's physical memory in bytes (NaN when the system does not say)."""
    try:
        return float(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))
    except (ValueError, OSError, AttributeError):
        return float("nan")


def memory_limit() -> float:
    """Bytes a scene may take: ``SIGNORINI_MAX_MEMORY_GB``, else ¾ of the physical memory."""
    limit = gigabytes_from(MEMORY_VARIABLE)
    if limit is not None:
        return limit
    total = physical_memory()
    return 0.75 * total if math.isfinite(total) else math.inf


def check_size(family: str, params: dict[str, Any], solved_by: Solver | None = None) -> None:
    """InputError, with the estimate, the limit and how to raise it, when the scene is too big
    to solve with the method ``solved_by`` (see :func:`bytes_per_dof`)."""
    found = estimate_dofs(family, params)
    if found is None:
        return
    dofs, dim = found
    if dim == 3:  # the mesher's limit first (as the tetrahedra reach it long before memory)
        _check_graded(family, params, dim)
    _check_memory(family, params, dofs, dim, solved_by)
    _check_graded(family, params, dim)


def _check_graded(family: str, params: dict[str, Any], dim: int) -> None:
    """InputError when the graded mesh, before uniform refinement, exceeds the mesher's limit."""
    if "grading" not in params:
        return
    graded = SCENES[family].size_model.graded(params) * ELEMENTS_PER_DOF[dim]
    if graded > GRADED_LIMIT[dim]:
        raise InputError(
            f"scene {family!r} with grading={params['grading']:g}, n_contact={params['n_contact']:g} "
            f"would be graded to about {graded:,.0f} {ELEMENT_NAMES[dim]} "
            f"({graded / ELEMENTS_PER_DOF[dim]:,.0f} dofs) before any uniform refinement, over "
            f"the mesher's {GRADED_LIMIT[dim]:,}: make the grading larger or n_contact smaller, "
            "and refine (refine=1, 2...) to go finer")


def over_limit(dofs: float, dim: int, params: dict[str, Any],
               solved_by: Solver | None = None) -> tuple[float, float] | None:
    """``(bytes needed, limit)`` when building and solving a model of ``dofs`` dofs with the
    method ``solved_by`` would exceed :func:`memory_limit`; None when it fits. ``params`` needs
    only ``nu`` and ``volumetric`` (and for 3D ``P`` and ``delta``), as :func:`bytes_per_dof`."""
    need, limit = dofs * bytes_per_dof(dim, dofs, params, solved_by), memory_limit()
    return None if need <= limit else (need, limit)


def _check_memory(family: str, params: dict[str, Any], dofs: float, dim: int,
                  solved_by: Solver | None) -> None:
    """InputError when building and solving the scene would exceed :func:`memory_limit`."""
    over = over_limit(dofs, dim, params, solved_by)
    if over is None:
        return
    need, limit = over
    names = [k for k in ("n_contact", "grading", "refine", "nx", "ny") if k in params]
    mesh = ", ".join(f"{k}={params[k]:g}" for k in names)
    raise InputError(
        f"scene {family!r} with {mesh} would have about {dofs:,.0f} dofs and take about "
        f"{need / 1e9:,.1f} GB to build and solve, over the limit of {limit / 1e9:,.1f} GB "
        f"(¾ of this machine's memory unless {MEMORY_VARIABLE} says otherwise): make the mesh "
        f"coarser ({', '.join(names)})" + (f", or raise the limit, e.g. {MEMORY_VARIABLE}="
                                          f"{math.ceil(need / 1e9) + 1}" if math.isfinite(need) else "")
        + _push_hint(dim, dofs, params, limit))


def _push_hint(dim: int, dofs: float, params: dict[str, Any], limit: float) -> str:
    """For a 3D scene with a target load that a push would fit: say so."""
    pushed = dofs * BYTES_PER_DOF_3D_PUSHED
    if dim != 3 or _plain_bytes_per_dof(dim, dofs, params) == BYTES_PER_DOF_3D_PUSHED or pushed > limit:
        return ""
    return (f"; or solve it with --method auto (the default) or pdas-amg, which match the load "
            f"without a factorisation: about {pushed / 1e9:,.1f} GB")


__all__ = ["Solver", "bytes_per_dof", "SizeModel", "CountedSize", "estimate_dofs",
           "physical_memory", "memory_limit", "check_size", "over_limit", "MEMORY_VARIABLE",
           "SIZE_MODELS"]
