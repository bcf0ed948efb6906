"""The answer of one solve, in the problem's units, and its record (what ``signorini solve --json``
writes).

A :class:`Result` gives every quantity in the units of the problem's input
(SI if the scene's parameters are SI): ``force`` in N (N/m per unit thickness
in 2D, N per radian in axisymmetric models), ``pressure`` in Pa, ``gap`` and
``displacement`` in m; a QP of your own (:meth:`ContactProblem.from_qp`) answers in
your units (``result.u`` is your unknown, ``result.force`` your λ). The answer's own
vectors ``result.solution.u`` and ``result.solution.lam`` are in the problem's arrays' units:
a scene's are dimensionless (see :class:`signorini.problem.scales.Scales`), a ``from_qp``
problem's are yours. ``Result.to_dict()`` is the JSON that ``signorini solve --json`` writes.
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass
from typing import Any

import numpy as np

from signorini.certification.kkt import Certificate
from signorini.derivatives import implicit as derivatives
from signorini import fem  # the estimate's module loaded at first use: a QP has no mesh
from signorini.numerics.factor import timed
from signorini.problem.contact import ContactProblem, ContactSolution
from signorini.problem.scales import record_units
from signorini.references.catalogue import Reference, reference_of, summary_lines
from signorini.references.pressure import ContactProfile, contact_profile, load_resultant

#: the version of the solve record's layout (docs/json.md): raised when a key changes meaning or goes
SCHEMA_VERSION = 3

log = logging.getLogger(__name__)


#: the stages of a solve, in the order they run (the solve record's ``time``); ``startup`` is the
#: command's process before it builds the scene (interpreter, imports, parsing): 0 in a library call
STAGES = ("startup", "mesh", "assemble", "load control", "prediction", "method", "certificate",
          "estimate", "output")


def stage_key(stage: str) -> str:
    """The record's key of a stage's seconds: ``load_control_s``."""
    return f"{stage.replace(' ', '_')}_s"


def stage_times(seconds: dict[str, float]) -> dict[str, float]:
    """Every stage of :data:`STAGES` by its key (0 for one that did not run) and their sum,
    ``total_s``."""
    stages = {stage_key(stage): seconds.get(stage, 0.0) for stage in STAGES}
    return {**stages, "total_s": sum(stages.values())}


def time_line(times: dict[str, float], parts: int = 3) -> str:
    """``time 0.31 s: mesh 0.23, method 0.03, assemble 0.02``: the total of :func:`stage_times`
    and its ``parts`` largest stages."""
    largest = sorted(((times.get(stage_key(stage), 0.0), stage) for stage in STAGES),
                     reverse=True)[:parts]
    return f"time {times['total_s']:.2f} s: " + ", ".join(f"{stage} {s:.2f}" for s, stage in largest)


def _scalar_rows(value: Any) -> bool:
    """A list of flat records (e.g. per-rank timings): kept in the JSON."""
    return isinstance(value, list) and all(
        isinstance(row, dict) and all(isinstance(x, (int, float, str, bool)) for x in row.values())
        for row in value)


@dataclass
class Result:
    """One solve: the problem, the method's answer, its certificate, in the problem's units.

    Attributes that hold arrays are per contact candidate, in the order of
    ``problem.N``'s rows: ``x`` (horizontal distance from the first point of
    contact, or the radius; signed for a plane QP given as arrays; NaN without geometry), ``gap``,
    ``force`` (the nodal contact force λ), ``pressure`` (λ over the lumped
    boundary weight; NaN when the problem has no weights) and ``active``.
    """

    problem: ContactProblem
    solution: ContactSolution
    certificate: Certificate

    def __repr__(self) -> str:  # a line, not the arrays
        name, worst = self.certificate.worst()
        return (f"Result({self.method!r}: {self.status}, {self.iterations} iterations, "
                f"{self.problem.n} dofs, {self.problem.m} candidates, worst KKT {name} {worst:.1e})")

    # -- the method's verdict --------------------------------------------------------------
    @property
    def status(self) -> str:
        """``converged`` only when the certificate agrees with the method's claim."""
        return self.solution.status

    @property
    def claimed_status(self) -> str:
        """What the method itself said (differs from ``status`` when the certificate overruled it)."""
        return self.solution.own_status

    @property
    def converged(self) -> bool:
        return self.solution.success

    @property
    def method(self) -> str:
        return self.solution.method

    @property
    def message(self) -> str:
        return self.solution.message

    @property
    def iterations(self) -> int:
        return int(self.solution.iterations)

    @property
    def target_met(self) -> bool | None:
        """Adaptive refinement met its target error (:func:`signorini.solve_adaptive`); None
        for a solve without one. ``converged`` judges the last mesh's answer, this its accuracy."""
        met = self.solution.extras.get("target_met")
        return None if met is None else bool(met)

    @property
    def finite(self) -> bool:
        """The method returned finite vectors (a failed run carries NaN)."""
        return bool(np.all(np.isfinite(self.solution.lam)) and np.all(np.isfinite(self.solution.u)))

    # -- the answer in physical units -------------------------------------------------------
    @property
    def profile(self) -> ContactProfile:
        """Gaps, forces and pressures at the candidates (see
        :func:`signorini.references.pressure.contact_profile`)."""
        if not hasattr(self, "_profile"):
            self._profile = contact_profile(self.problem, self.solution)
        return self._profile

    # the profile's arrays, one entry per candidate (see the class's docstring)
    x = property(lambda self: self.profile.x)
    gap = property(lambda self: self.profile.gap)
    force = property(lambda self: self.profile.force)
    pressure = property(lambda self: self.profile.pressure)
    active = property(lambda self: self.profile.active)

    @property
    def total_force(self) -> float:
        """The contact force on the whole body (symmetry copies and 2π included)."""
        return self.profile.total_force

    @property
    def applied_load(self) -> float:
        """The same load measured as the reaction on the loaded boundary (NaN when unknown)."""
        return self.profile.applied_load

    @property
    def displacement(self) -> np.ndarray:
        """Every dof of the mesh (free and prescribed), in length units."""
        return self.problem.model.expand(self.solution.u) * self.problem.scales.displacement

    @property
    def u(self) -> np.ndarray:
        """The QP's unknown (the free dofs) in the problem's units: for
        :meth:`ContactProblem.from_qp`, the ``u`` of your ``½uᵀKu − fᵀu``."""
        return self.solution.u * self.problem.scales.displacement

    @property
    def energy(self) -> float:
        """The optimal energy ``½uᵀKu − fᵀu`` of the QP, in force × length units."""
        scales = self.problem.scales
        return self.problem.energy(self.solution.u) * scales.force * scales.displacement

    # -- derivatives (signorini.derivatives.implicit) ------------------------------------------------
    @property
    def sensitivity(self) -> derivatives.Sensitivity:
        """The KKT system on the active set, factorised at the first derivative asked for."""
        if not hasattr(self, "_sensitivity"):  # handed the method's factor, if it was kept
            self._sensitivity = derivatives.Sensitivity(self.problem, self.solution,
                                                        self.solution.factor)
            self.solution.factor = None
        return self._sensitivity

    def jvp(self, df: Any = None, dd: Any = None, side: str = "auto") -> derivatives.Tangent:
        """``(du, dforce)``: how ``u`` and the nodal contact forces move when f moves by ``df``
        (force units, one per free dof) and d by ``dd`` (length units, one per candidate).

        Implicit differentiation on the active set (back-solves once factorised);
        where candidates are weakly active the answer is one-sided and lists
        them (``side``: ``auto``, ``in``, ``out``; see :mod:`signorini.derivatives.implicit`).
        """
        return derivatives.jvp(self.sensitivity, df, dd, side)

    def vjp(self, gu: Any = None, gforce: Any = None, side: str = "out") -> derivatives.Cotangent:
        """``(gf, gd)``: the gradients with respect to f and d of ``⟨gu, u⟩ + ⟨gforce, force⟩``
        (the adjoint of :meth:`jvp` on the branch ``side``, ``in`` or ``out``)."""
        return derivatives.vjp(self.sensitivity, gu, gforce, side)

    # -- theory -----------------------------------------------------------------------------
    @property
    def reference(self) -> Reference | None:
        """The analytic reference the problem declares (None for none)."""
        return reference_of(self.problem)

    @property
    def comparison(self) -> Any:
        """The answer against the reference (e.g. :class:`signorini.references.pressure.HertzComparison`).

        None when the problem declares no reference or the answer is not finite.
        """
        if self.reference is None or not self.finite:
            return None
        if not hasattr(self, "_comparison"):
            self._comparison = self.reference.compare(self.problem, self.solution)
        return self._comparison

    @property
    def hertz(self) -> Any:
        """The comparison with Hertz's solution, when that is the problem's reference."""
        return self.comparison if self.reference is not None and self.reference.key == "hertz" else None

    @property
    def estimate(self) -> fem.ErrorEstimate | None:
        """The a posteriori estimate of the discretisation error in the energy norm.

        ``total`` (physical units, √(force · length)), ``relative`` = η / ‖u_h‖_E
        and ``elements`` (η_K per element, in the problem's units); see
        :mod:`signorini.fem.estimate`. None for problems without a mesh
        (:meth:`ContactProblem.from_qp`) or an answer that is not finite.
        """
        if not hasattr(self, "_estimate"):
            log.info("estimating the discretisation error (ZZ)")
            with timed(self.solution.seconds, "estimate"):
                self._estimate = (fem.estimate.estimate(self.problem, self.solution)
                                  if self.finite else None)
        return self._estimate

    # -- records ----------------------------------------------------------------------------
    def to_dict(self) -> dict[str, Any]:
        """The record ``signorini solve --json`` writes (arrays as NumPy until serialised).

        ``time`` has the seconds of every stage of a solve (``mesh_s``, ..., ``output_s``:
        building this record, the estimate apart, and the exports already timed into
        ``solution.seconds["output"]``) and their sum ``total_s``
        (:func:`stage_times`).
        """
        problem, solution, estimated = self.problem, self.solution, self.estimate  # timed apart
        start = time.perf_counter()
        record: dict[str, Any] = {
            "schema_version": SCHEMA_VERSION, "units": record_units(problem),
            "scene": problem.name, "params": problem.model.params, "method": solution.method,
            "status": solution.status, "claimed_status": solution.own_status,
            "message": solution.message,
            "iterations": self.iterations, "dofs": problem.n,
            "contact_candidates": problem.m,
            "time": {},
            "work": solution.work,
            "kkt": self.certificate.as_dict(),
            "estimate": None if estimated is None else estimated.as_dict(),
        }
        if self.finite:
            record["total_force"] = self.total_force
            record["applied_load"] = self.applied_load
            record["contact"] = self.profile.as_dict()
            if self.reference is not None:
                if self.reference.resultant:  # curved or cornered obstacles: the vertical load
                    record["load_resultant"] = load_resultant(problem, solution.lam)
                record[self.reference.key] = self.comparison.as_dict()
        else:
            record["total_force"] = None
            record["contact"] = None
        if "adequacy" in solution.extras:  # the boundary beyond the candidates (certification.adequacy)
            record["adequacy"] = solution.extras["adequacy"]
        record["extras"] = {k: v for k, v in solution.extras.items()
                            if isinstance(v, (int, float, str, bool)) or _scalar_rows(v)}
        disc = problem.model
        built = {"mesh": disc.mesh_s, "assemble": disc.assemble_s} if disc is not None else {}
        output = solution.seconds.get("output", 0.0) + time.perf_counter() - start  # and exports
        record["time"] = {**stage_times({**built, **solution.seconds, "output": output}),
                          "build_s": solution.build_time, "solve_s": solution.solve_time}
        return record

    def summary(self) -> str:
        """A few lines for people (what ``signorini solve`` prints)."""
        return solve_summary(self.to_dict())


def solve_summary(record: dict[str, Any]) -> str:
    """A few human lines about one solve record (see :meth:`Result.to_dict`)."""
    lines = [f"{record['scene'] or 'problem'} with {record['method']}: {record['status']} "
             f"after {record['iterations']} iterations ({record['message']})",
             f"  {record['dofs']} dofs, {record['contact_candidates']} contact candidates; "
             + time_line(record["time"])]
    kkt = record["kkt"]
    lines.append("  KKT (relative): " + ", ".join(f"{k} {v:.1e}" for k, v in kkt.items()))
    if record.get("contact"):
        active, applied = sum(record["contact"]["active"]), record.get("applied_load")
        said = f" (applied {applied:.6g})" if applied is not None and np.isfinite(applied) else ""
        lines.append(f"  total force {record['total_force']:.6g}{said}, {active} nodes in contact")
    if record.get("estimate"):
        lines.append(f"  error estimate (energy norm, ZZ): {100 * record['estimate']['relative']:.2f} % "
                     f"of ‖u_h‖ over {record['estimate']['elements']} elements")
        if record["estimate"].get("pressure") is not None:
            lines[-1] += f"; contact pressure {100 * record['estimate']['pressure']:.2f} % (L2)"
        elif record["estimate"].get("bodies", 1) > 1:
            lines[-1] += ", each body with its own material; contact pressure not estimated"
    lines += summary_lines(record)  # the comparison with the analytic reference
    units = record.get("units") or {}
    if units.get("length") == "length":  # a scene's: in the units its parameters were given in
        lines.append(f"  units: lengths and gaps in the scene's length unit, pressures in E's unit, "
                     f"forces in {units['force']}")
    steps = record["extras"].get("adaptive", [])
    if steps:
        extras = record["extras"]
        met = "" if "target_met" not in extras else (
            f", target {100 * extras['target_error']:.3g} % ({extras['target_on'] or 'none reached'}) "
            f"{'met' if extras['target_met'] else 'NOT met'}")
        lines.append(f"  adaptive refinement, {len(steps)} solve{'s' * (len(steps) != 1)} in "
                     f"{sum(step['seconds'] for step in steps):.2f} s{met} (estimates: energy norm, "
                     "pressure):")
        lines += [f"    step {step['step']}: {step['dofs']:,} dofs, {step['candidates']} candidates, "
                  f"{100 * step['estimate']:.3g} %, {100 * step['pressure_estimate']:.3g} %: "
                  f"{step['action']}" for step in steps]
    for rank in record["extras"].get("per_rank", []):
        if "local_rows" in rank:
            lines.append(f"  rank {rank['rank']}: {rank['local_rows']} rows, set-up "
                         f"{rank['setup_s']:.2f} s, solve {rank['solve_s']:.2f} s, "
                         f"peak memory {rank['peak_memory_mb']:.0f} MB")
    return "\n".join(lines)


__all__ = ["SCHEMA_VERSION", "STAGES", "Result", "solve_summary", "stage_key", "stage_times", "time_line"]
