"""What a scene is: a mesh, a material, boundary conditions and a rigid obstacle.

A scene family declares its parameters (:class:`Param`) and a ``build``
function that turns checked parameter values into a
:class:`~signorini.fem.model.SceneModel` in physical units;
:mod:`signorini.fem.assembly` turns the model into a
:class:`~signorini.problem.ContactProblem`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Callable

from signorini.errors import InputError
from signorini.fem.model import SceneModel
from signorini.fem.volumetric import CHOICES


@dataclass(frozen=True)
class Param:
    """A scene parameter: name, default, type and the check of its range.

    ``check`` returns ``None`` when the value is fine, otherwise the phrase
    that completes "must be ..." (for example ``"in (-1, 0.5)"``).
    """

    name: str
    default: Any
    doc: str
    kind: type = float
    check: Callable[[Any], str | None] | None = None

    def parse(self, value: Any) -> Any:
        """Convert (from a string if need be) and check one value."""
        if value is None:
            if self.default is None:
                return None
            raise InputError(f"scene parameter {self.name} needs a value: "
                             f"pass --set {self.name}=<{self.kind.__name__}> ({self.doc})")
        if isinstance(value, bool):
            raise InputError(f"scene parameter {self.name}={value!r} is not a valid "
                             f"{self.kind.__name__}: pass --set {self.name}=<{self.kind.__name__}>")
        try:
            if self.kind is int:
                converted = int(value)
                if isinstance(value, float) and converted != value:
                    raise ValueError
                if isinstance(value, str) and str(converted) != value.strip():
                    raise ValueError
            else:
                converted = self.kind(value)
        except (TypeError, ValueError, OverflowError):
            raise InputError(
                f"scene parameter {self.name}={value!r} is not a valid {self.kind.__name__}: "
                f"pass --set {self.name}=<{self.kind.__name__}> ({self.doc})") from None
        if isinstance(converted, float) and not math.isfinite(converted):
            raise InputError(f"scene parameter {self.name}={value!r} must be a finite number")
        if self.check is not None:
            problem = self.check(converted)
            if problem:
                raise InputError(f"scene parameter {self.name}={value!r} must be {problem}")
        return converted


def positive(x: float) -> str | None:
    return None if x > 0 else "> 0"


def poisson_ratio(x: float) -> str | None:
    return None if -1.0 < x < 0.5 else "in (-1, 0.5) (0.5 is incompressible, which P1 cannot model)"


def one_of(*choices: str) -> Callable[[str], str | None]:
    return lambda x: None if x in choices else f"one of {', '.join(choices)}"


#: how the Hertz scenes load their body (see :class:`signorini.fem.model.CutLoad`)
LOADING = Param("loading", "traction",
                "traction: a uniform traction on the cut through the centre, as Hertz's theory "
                "loads the body (the centre node's push carries no force); displacement: the cut "
                "pushed flat by a uniform displacement adjusted to the load (always so with delta=)", kind=str,
                check=one_of("traction", "displacement"))


#: how the Hertz scenes mesh their disc (signorini.scenes.meshing.graded_quarter_disc)
MESHER = Param("mesher", "relaxed",
               "relaxed: the graded mesh's nodes moved into near-equilateral triangles (more "
               "accurate per dof: docs/accuracy.md); bisection: the graded mesh as refined",
               kind=str, check=one_of("relaxed", "bisection"))

#: how every scene's K integrates λ (tr ε)² (signorini.fem.volumetric)
VOLUMETRIC = Param("volumetric", "auto",
                   "element: plain P1, the volumetric strain element by element (locks as nu -> "
                   "0.5); nodal: the volumetric strain averaged at the nodes (no locking, K with "
                   "2.7x the nonzeros in 2D, 5.2x in 3D: docs/accuracy.md); auto: nodal from nu = 0.4 "
                   "on in 2D and axisymmetric models, element in 3D",
                   kind=str, check=one_of(*CHOICES))

#: what a scene with a ``candidates`` parameter says when the contact outgrows its candidates
CANDIDATE_REMEDY = ("raise the scene parameter candidates (now {candidates:g}, in contact half-widths) "
                    "or lower the load")


def at_least(bound: float) -> Callable[[float], str | None]:
    return lambda x: None if x >= bound else f">= {bound:g}"


def between(lo: float, hi: float) -> Callable[[float], str | None]:
    return lambda x: None if lo < x <= hi else f"in ({lo:g}, {hi:g}]"


@dataclass(frozen=True)
class SceneFamily:
    """A named family of scenes and how to build one."""

    name: str
    summary: str
    params: tuple[Param, ...]
    build: Callable[[dict[str, Any], set[str]], SceneModel]
    reference: str = ""

    def parse(self, values: dict[str, Any]) -> dict[str, Any]:
        """Defaults overridden by ``values``; unknown names and bad values raise InputError."""
        known = {p.name: p for p in self.params}
        unknown = sorted(set(values) - set(known))
        if unknown:
            raise InputError(
                f"scene {self.name!r} has no parameter {unknown[0]!r}: "
                f"--set takes {', '.join(known)}")
        return {name: p.parse(values.get(name, p.default)) for name, p in known.items()}
