"""The peer benchmark's cases: each scene's GetFEM script, shared parameters, Hertz reference and ladders.

One body (``hertz-cylinder``, ``hertz-sphere``: ``getfem_hertz.py``, a body on a
rigid flat) and two bodies (``hertz-two-cylinders``: ``getfem_two_cylinders.py``,
GetFEM's nodal contact between non-matching meshes). The ladders differ by code:
GetFEM refines its gmsh size field at the contact (``h_contact``, a fraction of
a), this package its scene parameters (``n_contact``, ``refine``; the grading
the scene's default); each spans a few thousand to some tens of thousands of dofs.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable

import signorini
from signorini.references.analytic import (contact_modulus, hertz_cylinder_load, hertz_cylinder_peak,
                                hertz_sphere_load, hertz_sphere_peak)
from signorini.errors import InputError
from signorini.fem.two_bodies import series_modulus
from signorini.scenes.hertz_two_cylinders import pair_radius
from signorini.scenes.meshing import MESHERS

__all__ = ["CASES", "ONE_BODY", "SCENES", "SCRIPTS", "Case", "hertz_reference", "ladder_of"]

#: the standalone GetFEM scripts, run by the system Python: in the repository's checkout,
#: beside the package's source tree (an installed package has none)
SCRIPTS = Path(signorini.__file__).parents[1] / "benchmarks" / "peers"
#: parameters only the package takes, added to each of its rungs (e.g. --set mesher=triangle)
OURS_ONLY = ("mesher",)


@dataclass(frozen=True)
class Case:
    """One scene side by side: GetFEM's script and the package's scene on the same problem."""

    script: str                                  # the script's file name in :data:`SCRIPTS`
    defaults: dict[str, float]                   # parameters both codes take, with their defaults
    getfem: tuple[dict[str, float], ...]         # GetFEM's ladder
    ours: tuple[dict[str, Any], ...]             # this package's ladder, rung for rung
    reference: Callable[..., tuple[float, float, float]]   # (load P, p0, a) of Hertz
    name: str | None = None                      # the script's scene key (None: one scene)

    @property
    def path(self) -> Path:
        return SCRIPTS / self.script


def _one_body(load: Callable, peak: Callable) -> Callable[..., tuple[float, float, float]]:
    """Hertz's (load P, p0, a) of one body on a rigid flat, by its ``load`` and ``peak`` formulas."""
    def reference(*, R: float, E: float, nu: float, a_over_R: float) -> tuple[float, float, float]:
        a = a_over_R * R
        P = load(a, R, contact_modulus(E, nu))
        return P, peak(P, a), a
    return reference


def _two_cylinders(*, R1: float, R2: float, E1: float, nu1: float, E2: float, nu2: float,
                   a_over_R: float) -> tuple[float, float, float]:
    """Two-body Hertz: E* and R* from both cylinders (P per unit thickness of the full cylinders)."""
    R = pair_radius({"R1": R1, "R2": R2})
    a = a_over_R * R
    P = hertz_cylinder_load(a, R, series_modulus(E1, nu1, E2, nu2))
    return P, hertz_cylinder_peak(P, a), a


#: GetFEM's ladder on one body: the element size at the contact, a fraction of a
ONE_BODY_LADDER = tuple({"h_contact": 1 / n} for n in (16, 24, 40, 64, 112))
ONE_BODY_DEFAULTS = {"R": 1.0, "E": 1.0, "nu": 0.3, "a_over_R": 0.05}

CASES = {
    "hertz-cylinder": Case(
        "getfem_hertz.py", ONE_BODY_DEFAULTS, ONE_BODY_LADDER,
        # the scene's default mesh (n_contact 24) is the middle rung
        ({"n_contact": 8}, {"n_contact": 14}, {"n_contact": 24}, {"n_contact": 48},
         {"n_contact": 48, "refine": 1}), _one_body(hertz_cylinder_load, hertz_cylinder_peak), "cylinder"),
    "hertz-sphere": Case(
        "getfem_hertz.py", ONE_BODY_DEFAULTS, ONE_BODY_LADDER,
        # the scene's default mesh (n_contact 48) is the middle rung
        ({"n_contact": 12}, {"n_contact": 24}, {"n_contact": 48}, {"n_contact": 96},
         {"n_contact": 96, "refine": 1}), _one_body(hertz_sphere_load, hertz_sphere_peak), "sphere"),
    # the scene's defaults (its mesh: n_contact 48); the slave's size at the contact, the
    # master's 1.25 times coarser on GetFEM's side (the script's master_ratio)
    "hertz-two-cylinders": Case(
        "getfem_two_cylinders.py",
        {"R1": 1.0, "R2": 1.0, "E1": 1.0, "nu1": 0.3, "E2": 1.0, "nu2": 0.3, "a_over_R": 0.05},
        tuple({"h_contact": 1 / n} for n in (16, 24, 40, 64)),
        tuple({"n_contact": n} for n in (8, 16, 32, 64)), _two_cylinders),
}
SCENES = tuple(CASES)
#: the scenes ``signorini bench --peer getfem`` runs without ``--scene``
ONE_BODY = ("hertz-cylinder", "hertz-sphere")


def hertz_reference(scene: str, **params: float) -> tuple[float, float, float]:
    """(load P, p0, a) of Hertz's solution for the scene's shared parameters (P per unit
    thickness for the cylinders)."""
    return CASES[scene].reference(**params)


def ladder_of(scenes: list[str], sizes: list[int] | None,
              params: dict[str, Any]) -> list[tuple[str, int, dict, dict, dict]]:
    """Per scene and chosen rung (default: every rung): (scene, rung, GetFEM's mesh, the package's
    mesh, the shared parameters). ``params`` are ``--set`` values: parameters every chosen scene
    shares with GetFEM, or ``mesher`` for the package alone."""
    unknown = [s for s in scenes if s not in CASES]
    if unknown:
        raise InputError(f"--scene {unknown[0]!r} has no peer model: choose from {', '.join(CASES)}")
    for scene in scenes:
        extra = sorted(set(params) - set(CASES[scene].defaults) - set(OURS_ONLY))
        if extra:
            raise InputError(f"--set {extra[0]} is not shared by both codes on {scene}: the peer "
                             f"benchmark takes {', '.join(CASES[scene].defaults)}, and mesher for "
                             "the package alone")
    ours = {k: v for k, v in params.items() if k in OURS_ONLY}
    if "mesher" in ours and ours["mesher"] not in MESHERS:
        raise InputError(f"--set mesher={ours['mesher']} is not a mesher of the Hertz discs: "
                         f"choose one of {', '.join(MESHERS)}")
    shared = {k: float(v) for k, v in params.items() if k not in OURS_ONLY}
    rungs = min(len(CASES[scene].getfem) for scene in scenes)
    chosen = range(rungs) if sizes is None else sizes
    bad = [i for i in chosen if not 0 <= i < rungs]
    if bad:
        raise InputError(f"--sizes {bad[0]} is not a rung of the peer ladder: give numbers in "
                         f"0..{rungs - 1}")
    return [(scene, i, dict(CASES[scene].getfem[i]), {**CASES[scene].ours[i], **ours},
             {**CASES[scene].defaults, **shared}) for scene in scenes for i in chosen]
