"""What a scene is: a mesh, a material, boundary conditions and a rigid obstacle.

A scene family declares its parameters (:class:`Param`) and a ``build``
function that turns checked parameter values into a
:class:`~signorini.fem.model.SceneModel` in physical units;
:mod:`signorini.fem.assembly` turns the model into a
:class:`~signorini.problem.contact.ContactProblem`. The family also owns what else
is known of it (:class:`SceneFamily`): its size model, its coarse rule, how
refined nodes go back onto a curved boundary, its analytic reference (by
name, :mod:`signorini.references.catalogue`) and its validation cases (:class:`Case`).
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass, field
from typing import Any, Callable, Mapping, Protocol

from signorini.references.analytic import contact_modulus
from signorini.problem.model import ReferenceData
from signorini.errors import InputError, docs_page
from signorini.fem.checks import LENGTH_RANGE
from signorini.fem.model import SceneModel
from signorini.fem.model import CHOICES
from signorini.scenes.meshing import MESHERS

__all__ = ["A_OVER_R_RANGE", "CANDIDATE_REMEDY", "Case", "GRADING_RANGE", "HALF", "LOADING",
           "LOAD_NAMES", "MAX_BLOCK", "MAX_DIGITS", "MAX_INT", "MESHER", "Param", "SceneFamily",
           "SizeEstimate", "VOLUMETRIC", "at_least", "between", "block_size", "candidates",
           "checked_ratio", "chosen_load", "contact_ratio", "grading", "grading_check",
           "hertz_load", "hertz_record", "length", "one_of", "poisson_ratio", "positive",
           "refinements", "representable", "scene_params", "shown", "two_refinements_coarser",
           "within"]


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
        if isinstance(value, str) and len(value) > MAX_DIGITS:  # before int() spends time on it
            raise InputError(f"scene parameter {self.name}={shown(value)} is too long for a number: "
                             f"give at most {MAX_DIGITS} characters")
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
                f"scene parameter {self.name}={shown(value)} is not a valid {self.kind.__name__}: "
                f"pass --set {self.name}=<{self.kind.__name__}> ({self.doc})") from None
        if isinstance(converted, float) and not math.isfinite(converted):
            raise InputError(f"scene parameter {self.name}={shown(value)} must be a finite number")
        problem = representable(converted)
        if problem is None and self.check is not None:
            problem = self.check(converted)
        if problem:
            raise InputError(f"scene parameter {self.name}={shown(value)} must be {problem}")
        return converted


#: the most characters a parameter's value may have (a float's repr has at most 24)
MAX_DIGITS = 40
#: integer parameters (counts of elements, refinements, flags) stay below 2⁵³: exact as floats
MAX_INT = 2 ** 53


def shown(value: Any) -> str:
    """``value`` as a message shows it: its repr, the middle of a long one left out."""
    text = repr(value)
    return text if len(text) <= MAX_DIGITS else f"{text[:12]}…{text[-6:]} ({len(str(value))} characters)"


def representable(x: Any) -> str | None:
    """Every number a scene takes: an int exact as a float, a float zero or normal (not subnormal)."""
    if isinstance(x, int) and abs(x) >= MAX_INT:
        return f"less than 2^53 = {MAX_INT} in magnitude (a count of elements or refinements)"
    if isinstance(x, float) and x != 0 and abs(x) < sys.float_info.min:
        return (f"0 or at least {sys.float_info.min:.3g} in magnitude (a smaller value loses its "
                "digits in double precision): choose units nearer the value")


def positive(x: float) -> str | None:
    return None if x > 0 else "> 0"


def length(x: float) -> str | None:
    """A length of the scene: > 0, within :data:`LENGTH_RANGE`."""
    lo, hi = LENGTH_RANGE
    return None if lo <= x <= hi else (
        f"a length in [{lo:g}, {hi:g}] (areas and volumes of the model must be representable in "
        "double precision): choose a length unit nearer the body's size, e.g. mm or km")


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


#: how the Hertz scenes mesh their disc (signorini.scenes.meshing.graded_quarter_disc); each
#: scene sets its own default, chosen on the accuracy-time front (docs/mesher.md)
MESHER = Param("mesher", "triangle",
               "triangle: Shewchuk's Triangle, near-equilateral and fast; bisection: the graded "
               "mesh as refined (right-angled triangles); relaxed: the bisection mesh's nodes "
               "moved into near-equilateral triangles (slow to mesh) "
               f"({docs_page('mesher')} compares them)",
               kind=str, check=one_of(*MESHERS))

#: how every scene's K integrates λ (tr ε)² (signorini.fem.volumetric)
VOLUMETRIC = Param("volumetric", "auto",
                   "element: plain P1, the volumetric strain element by element (locks as nu -> "
                   "0.5); nodal: the volumetric strain averaged at the nodes (no locking, K with "
                   f"2.7x the nonzeros in 2D, 5.2x in 3D: {docs_page('accuracy')}); auto: nodal from "
                   "nu = 0.4 "
                   "on in 2D and axisymmetric models, element in 3D",
                   kind=str, check=one_of(*CHOICES))

#: what a scene with a ``candidates`` parameter says when the contact outgrows its candidates
CANDIDATE_REMEDY = ("raise the scene parameter candidates (now {candidates:g}, in contact half-widths) "
                    "or lower the load")


def at_least(bound: float) -> Callable[[float], str | None]:
    return lambda x: None if x >= bound else f">= {bound:g}"


def within(lo: float, hi: float, why: str = "") -> Callable[[float], str | None]:
    """The check of a value in ``[lo, hi]``; ``why`` follows the range in the message."""
    return lambda x: None if lo <= x <= hi else f"in [{lo:g}, {hi:g}]{why}"


#: the largest block around a contact, in contact half-widths: the graded mesh's largest
#: element over its smallest (about size · n_contact) squares into K's condition number
MAX_BLOCK = 1e4


def block_size(smallest: float) -> Callable[[float], str | None]:
    """The check of a block's ``size`` (in contact half-widths): in [smallest, :data:`MAX_BLOCK`]."""
    return within(smallest, MAX_BLOCK, " (a larger block squares the spread of its element sizes "
                  "into K's condition number; the contact sees a half-plane long before)")


def between(lo: float, hi: float) -> Callable[[float], str | None]:
    return lambda x: None if lo < x <= hi else f"in ({lo:g}, {hi:g}]"


#: the graded meshes' growth of the element size: the least is a uniform mesh at the contact's
#: element size (the convergence study's uniform comparison); below it the mesher's series of
#: layers degenerates
GRADING_RANGE = (1e-6, 2.0)
#: the range of every graded scene's ``grading``
grading_check = within(*GRADING_RANGE, " (smaller grows the elements more slowly away from the "
                       "contact: a larger mesh)")


def grading(default: float) -> Param:
    """A graded scene's ``grading`` parameter with its ``default``."""
    return Param("grading", default, "growth of the element size with distance from the contact zone",
                 check=grading_check)


def refinements(most: int = 6, growth: str = "quadruples the dofs") -> Param:
    """A graded scene's ``refine`` parameter: 0 to ``most`` uniform refinements."""
    return Param("refine", 0, f"uniform refinements of the graded mesh (each {growth})", kind=int,
                 check=lambda k: None if 0 <= k <= most else f"in 0..{most}")


def candidates(contact: str = "half-width", default: float = 2.0) -> Param:
    """A Hertz scene's ``candidates`` parameter, in multiples of the ``contact`` half-width or radius."""
    return Param("candidates", default, f"contact candidates extend to this multiple of the {contact}",
                 check=at_least(1.2))


#: whether a block scene models the right half (a symmetry plane at x = 0) or the whole width
HALF = Param("half", 1, "1: right half with a symmetry plane; 0: the whole width", kind=int,
             check=lambda k: None if k in (0, 1) else "0 or 1")


#: contact half-width (radius) over the radius a Hertz scene meshes: below it the gaps over the
#: contact, about (a/R)² R, keep fewer than 8 digits next to R; above it Hertz's half-space
#: theory does not hold
A_OVER_R_RANGE = (1e-4, 0.5)
#: the check of the ``a_over_R`` parameters
contact_ratio = within(*A_OVER_R_RANGE)


def checked_ratio(a_over_R: float, name: str, value: float) -> float:
    """``a_over_R`` that the load parameter ``name=value`` gives, refused outside :data:`A_OVER_R_RANGE`."""
    lo, hi = A_OVER_R_RANGE
    if not a_over_R <= hi:
        raise InputError(f"scene parameter {name}={value:g} gives a/R = {a_over_R:.3g} > {hi:g}: "
                         f"Hertz's half-space theory needs a/R small; lower {name}")
    if not a_over_R >= lo:
        raise InputError(f"scene parameter {name}={value:g} gives a/R = {a_over_R:.2g} < {lo:g}: "
                         f"the gaps over so small a contact lose their digits next to R in double "
                         f"precision; raise {name} (or choose R nearer the contact's size)")
    return a_over_R


def chosen_load(p: dict[str, Any], given: set[str],
                names: tuple[str, ...] = ("P", "a_over_R", "delta")) -> set[str]:
    """The load parameters among ``names`` given a value; InputError when more than one is."""
    chosen = {name for name in given & set(names) if p[name] is not None}
    if len(chosen) > 1:
        raise InputError(f"scene parameters {' and '.join(sorted(chosen))} both set the load: "
                         f"give only one of {', '.join(names)}")
    return chosen


def hertz_load(p: dict[str, Any], given: set[str], R: float, E_star: float, half_width: Callable,
               load: Callable, check_delta: bool = True,
               graded_by_delta: bool = False) -> tuple[float | None, float | None, float]:
    """``(target P or None, prescribed δ or None, a/R the mesh is graded for)`` of a Hertz scene,
    with Hertz's ``half_width(P, R, E*)`` and its inverse ``load(a, R, E*)``: one of ``P``,
    ``a_over_R`` (the default) or ``delta`` sets the load, refused where a/R leaves
    :data:`A_OVER_R_RANGE` (δ as ``a ~ √(δ R)``, up to Hertz's logarithm in 2D). A prescribed δ
    grades the mesh for ``a_over_R``, or for ``√(δ/R)`` when ``graded_by_delta``."""
    chosen = chosen_load(p, given)
    if "delta" in chosen:
        ratio = math.sqrt(p["delta"] / R)
        if check_delta or graded_by_delta:
            ratio = checked_ratio(ratio, "delta", p["delta"])
        return None, p["delta"], ratio if graded_by_delta else p["a_over_R"]
    if "P" in chosen:
        return p["P"], None, checked_ratio(half_width(p["P"], R, E_star) / R, "P", p["P"])
    return load(p["a_over_R"] * R, R, E_star), None, p["a_over_R"]


def hertz_record(p: dict[str, Any], reference: str, target: float | None, a_over_R: float,
                 delta_nominal: float) -> dict[str, Any]:
    """What a Hertz scene's model records: its parameters as the problem reports them (the load
    that ruled, the others None) and the typed fields code reads: the volumetric choice, the push
    δ, and what the reference ``reference`` reads (E* and R)."""
    params = dict(p, P=target, delta=delta_nominal if target is None else None,
                  a_over_R=a_over_R if target is not None else None)
    return {"params": params, "volumetric_choice": p["volumetric"], "delta": delta_nominal,
            "reference": ReferenceData(reference, E_star=contact_modulus(p["E"], p["nu"]), R=p["R"])}


class SizeEstimate(Protocol):
    """A family's dofs from its checked parameters, before any mesh is made
    (:mod:`signorini.scenes.size`): ``estimate`` the model's dofs, ``graded`` those of its
    graded mesh before uniform refinement, ``dim`` the mesh's dimension."""

    dim: int

    def estimate(self, p: dict[str, Any]) -> float: ...

    def graded(self, p: dict[str, Any]) -> float: ...


@dataclass(frozen=True)
class Case:
    """One scene of the validation suite (:mod:`signorini.studies.suite`) with its parameters."""

    name: str
    scene: str
    params: dict[str, Any] = field(default_factory=dict)
    same_as: str | None = None  # a case whose dimensionless answer this one must reproduce
    check_reference: bool = True  # hold the answer to the analytic reference's limits
    agrees_with: str | None = None  # a case modelling the same body otherwise: same a and p0

    @property
    def spec(self) -> dict[str, Any]:
        """The case's problem as a spec a worker rebuilds (:func:`signorini.studies.problems.build_spec`)."""
        return {"kind": "scene", "scene": self.scene, "params": dict(self.params)}


#: parameter names that set the load, left out of a coarse model's parameters and set again
LOAD_NAMES = ("P", "delta", "a_over_R", "load_ratio")


def two_refinements_coarser(params: dict[str, Any]) -> dict[str, Any] | None:
    """Parameters of a model about 16 times coarser than ``params``, or None (a family's ``coarse``).

    Two uniform refinements fewer (or one, and half the elements across the
    contact); the load is the same target P, or the same push ``delta`` when
    no target was set; meshed by bisection where the family offers a choice
    (the coarse model only predicts the contact zone).
    """
    values = {k: v for k, v in params.items() if k not in LOAD_NAMES}
    if params["refine"] >= 2:
        values["refine"] = params["refine"] - 2
    elif params["refine"] == 1 and params["n_contact"] >= 8:
        values.update(refine=0, n_contact=params["n_contact"] // 2)
    else:
        return None
    if "mesher" in params:  # a zone predictor needs no well-shaped triangles: bisection is faster
        values["mesher"] = "bisection"
    if params.get("P") is not None:
        values["P"] = params["P"]
    elif params.get("delta") is not None:
        values["delta"] = params["delta"]
    else:
        return None
    return values


@dataclass(frozen=True)
class SceneFamily:
    """A named family of scenes: how to build one, and what else is known of it.

    ``size_model`` estimates its dofs before meshing (required to register
    it: :func:`signorini.scenes.registry.register`); ``coarse(params)`` gives
    the parameters of a coarser model that predicts the contact zone (None:
    none); ``snap(params)`` gives the function that moves refined boundary
    nodes onto the family's curved boundary, and makes the family rebuild
    itself on each adaptive mesh (its ``build`` takes ``mesh=``);
    ``reference`` names its analytic reference (:data:`signorini.references.catalogue.REFERENCES`);
    ``validation`` its cases in the validation suite; ``convergence_start``
    the coarse mesh a convergence study starts from; ``adaptive_start`` the mesh
    parameters adaptive refinement starts from when none is given (those its dof budgets
    and the error estimate's effectivity were measured from).
    """

    name: str
    summary: str
    params: tuple[Param, ...]
    build: Callable[..., SceneModel]
    reference: str = ""
    #: ``loads(p, given)``: the load the checked parameters set, target P (None: a push) first;
    #: raises InputError for a load the family cannot model. Run by :meth:`parse`.
    loads: Callable[[dict[str, Any], set[str]], tuple] | None = None
    size_model: SizeEstimate | None = None
    coarse: Callable[[dict[str, Any]], dict[str, Any] | None] | None = None
    snap: Callable[[dict[str, Any]], Callable] | None = None
    validation: tuple[Case, ...] = ()
    convergence_start: Mapping[str, Any] = field(default_factory=dict)
    adaptive_start: Mapping[str, Any] = field(default_factory=dict)

    def parse(self, values: dict[str, Any]) -> dict[str, Any]:
        """Defaults overridden by ``values``; unknown names, bad values and loads the family
        cannot model raise InputError (before any mesh is made)."""
        known = {p.name: p for p in self.params}
        unknown = sorted(set(values) - set(known))
        if unknown:
            raise InputError(
                f"scene {self.name!r} has no parameter {unknown[0]!r}: "
                f"--set takes {', '.join(known)}")
        parsed = {name: p.parse(values.get(name, p.default)) for name, p in known.items()}
        target = self.loads(parsed, set(values))[0] if self.loads is not None else None
        if target is not None and not sys.float_info.min <= target < math.inf:
            given = ", ".join(f"{k}={parsed[k]:g}" for k in sorted(values)
                              if isinstance(parsed[k], float))
            raise InputError(f"scene {self.name!r} with {given} has a load P = {target:g} that double "
                             "precision cannot hold: choose units in which E and the lengths are "
                             "nearer 1 (e.g. MPa and mm)")
        return parsed


def scene_params(params: Any) -> dict[str, Any]:
    """A copy of ``params``, the scene parameters by name (``{}`` for None); anything but a dict
    with string keys is refused in one line."""
    if params is None:
        return {}
    if not isinstance(params, dict):
        raise InputError(f"params must be a dict of scene parameters, got {type(params).__name__}: "
                         "e.g. params={'E': 2.1e11, 'n_contact': 20}")
    named = [k for k in params if not isinstance(k, str)]
    if named:
        raise InputError(f"params key {named[0]!r} is not a parameter name: give the names as "
                         "strings, e.g. params={'E': 2.1e11}")
    return dict(params)
