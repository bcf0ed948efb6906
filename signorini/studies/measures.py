"""What the study runner measures about one answer, beside the certificate's worst residual.

Each function takes the problem and an answer (and the exact answer where
it compares) and returns numbers for a row of :mod:`signorini.studies.runner`.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np
import scipy.sparse as sp

from signorini.fem.estimate import element_energies, estimate, material_units
from signorini.fem.transfer import uniform_prolongation
from signorini.certification.kkt import WEAK, WEAK_TOL, active_set, certificate, classify, force_scale, gap_scale
from signorini.numerics.factor import PardisoFactor, factorize, resolve_backend
from signorini.numerics.lcp import delassus
from signorini.output.export import nodal_displacement
from signorini.references.profile import contact_profile
from signorini.problem.contact import ContactProblem, ContactSolution
from signorini.references.catalogue import reference_of
from signorini.solvers.cluster import mpirun_command


def certificate_of(problem: ContactProblem, solution: ContactSolution):
    """The certificate; without the duality gap when K cannot be factorised."""
    try:
        return certificate(problem, solution)
    except (np.linalg.LinAlgError, ArithmeticError, RuntimeError):
        return certificate(problem, solution, duality_gap=False)


def hertz_errors(problem: ContactProblem, solution: ContactSolution,
                 prefix: str = "") -> dict[str, float]:
    """The errors a row records against the problem's reference (its ``row_errors``: Hertz's
    cylinder's a, p₀ and pressure L2), each name after ``prefix``; {} for none."""
    reference = reference_of(problem)
    if reference is None or not reference.row_errors or not np.all(np.isfinite(solution.lam)):
        return {}
    try:
        comparison = reference.compare(problem, solution)
    except Exception:  # an answer too wrong to measure (no contact at all)
        return {}
    return {f"{prefix}{name}": getattr(comparison, name) for name in reference.row_errors}


def bound_at_solution(problem: ContactProblem, reference: ContactSolution) -> float:
    """``λ_max(W) / λ_max(W_AA)`` with A the exact active set: Uzawa's effective step bound.

    Once the active set has settled, the iteration only sees the block
    ``W_AA``, so steps up to ``2/λ_max(W_AA)`` (≥ ``2/λ_max(W)``) still
    contract; returned as a multiple of the textbook bound ``2/λ_max(W)``.
    """
    W = delassus(problem.N, problem.factor())
    active = active_set(problem, reference)
    if not active.any():
        return float("nan")
    return float(np.linalg.eigvalsh(W)[-1] / np.linalg.eigvalsh(W[np.ix_(active, active)])[-1])


def force_error(problem: ContactProblem, reference: ContactSolution,
                solution: ContactSolution) -> float:
    """``‖λ − λ*‖∞ / max(‖λ*‖∞, FORCE_FLOOR ‖f‖∞)``: the force error, judged as the certificate does.

    The floor keeps the measure meaningful when the exact answer has no
    contact force at all (λ* = 0), where a relative difference is 1 for any λ ≠ 0.
    """
    if not np.all(np.isfinite(solution.lam)):
        return float("inf")
    return float(np.max(np.abs(solution.lam - reference.lam), initial=0.0)
                 / force_scale(problem, reference.lam))


def weak_but_penetrating(problem: ContactProblem, solution: ContactSolution) -> int:
    """Nodes :func:`signorini.certification.kkt.classify` calls weakly active although they penetrate.

    ``classify`` measures the gap as ``(d − Nu)⁺``, so a node with zero force
    that overlaps the obstacle by more than the weak tolerance is labelled
    weak and left out of :func:`signorini.certification.comparison.compare` — a misclassification
    the comparison does not count. The atlas counts it here.
    """
    if not (np.all(np.isfinite(solution.u)) and np.all(np.isfinite(solution.lam))):
        return 0
    labels = classify(problem, solution)
    violation = (problem.N @ solution.u - problem.d) / gap_scale(problem, solution.u)
    return int(np.sum((labels == WEAK) & (violation > WEAK_TOL)))


def factorisation_time(problem: ContactProblem) -> float:
    """Seconds for one factorisation + solve of K with the backend a method would use.

    The library is loaded first (on a 2 × 2 identity), so that its start-up
    is not charged; nothing is cached on the problem.
    """
    backend = resolve_backend(None, problem.n, problem.K.nnz)
    factorize(sp.identity(2, format="csc"), backend).solve(np.ones(2))
    start = time.perf_counter()
    factorize(problem.K, backend).solve(problem.f)
    return time.perf_counter() - start


def pressure_profile(problem: ContactProblem, solution: ContactSolution) -> dict[str, Any]:
    """The contact pressure along the candidates; with the reference's a and p₀ where it has a figure."""
    profile = contact_profile(problem, solution)
    out: dict[str, Any] = {"x": profile.x.tolist(), "pressure": profile.pressure.tolist()}
    reference = reference_of(problem)
    if reference is not None and reference.figure:
        comparison = reference.compare(problem, solution)
        out.update(a_ref=comparison.a_ref, p0_ref=comparison.p0_ref)
    return out


def answer_record(solution: ContactSolution) -> dict[str, Any]:
    """An answer as plain data (for a row): method, statuses, message, iterations, times, u and λ."""
    return {"method": solution.method, "status": solution.status,
            "claimed_status": solution.claimed_status, "message": solution.message,
            "iterations": int(solution.iterations), "build_time": solution.build_time,
            "solve_time": solution.solve_time, "u": solution.u.tolist(),
            "lam": solution.lam.tolist(), "traceback": solution.extras.get("traceback", "")}


def answer_from(record: dict[str, Any]) -> ContactSolution:
    """The answer :func:`answer_record` wrote (None entries, non-finite in JSON, become NaN), with
    the push it was solved at in ``extras["push"]`` and its certificate's fields in
    ``extras["certificate"]`` when the record names them (a non-finite one written as text)."""
    extras = {key: record[key] for key in ("traceback", "push") if record.get(key)}
    if record.get("certificate"):
        extras["certificate"] = {name: value if isinstance(value, int) else float(value)
                                 for name, value in record["certificate"].items()}
    return ContactSolution(method=record["method"], u=np.array(record["u"], dtype=float),
                           lam=np.array(record["lam"], dtype=float), status=record["status"],
                           message=record["message"], iterations=record["iterations"],
                           build_time=record["build_time"], solve_time=record["solve_time"],
                           claimed_status=record["claimed_status"], extras=extras)


def forward_error(problem: ContactProblem, reference: ContactSolution,
                  solution: ContactSolution) -> dict[str, float]:
    """The true force error ``‖λ − λ*‖∞ / ‖λ*‖∞`` beside what the certificate estimates of it:
    its forward error, that estimate's floor and the back-solves it took."""
    cert = certificate(problem, solution)
    lam_error = float(np.max(np.abs(solution.lam - reference.lam)) / np.max(np.abs(reference.lam)))
    return {"lam_error": lam_error, "force_error": cert.force_error,
            "force_error_floor": cert.force_error_floor, "back_solves": cert.back_solves}


def resident() -> float:
    """This process's resident set size in bytes (Linux)."""
    with open("/proc/self/statm", encoding="ascii") as statm:
        return float(statm.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")


def factor_memory(problem: ContactProblem) -> dict[str, float]:
    """PARDISO's analysis-phase estimate of its factorisation of K (the package refuses one by
    it) against the growth of this process's resident memory that factorisation took."""
    before = resident()
    factor = PardisoFactor(problem.K)
    growth = resident() - before
    return {"estimate_bytes": factor.memory, "resident_growth_bytes": growth,
            "ratio": factor.memory / growth}


def estimate_record(problem: ContactProblem, solution: ContactSolution) -> dict[str, float] | None:
    """The a posteriori estimate (relative, the pressure's relative, η and its parts in physical
    units, η without the contact term) and the seconds it took; None where there is none."""
    start = time.perf_counter()
    found = estimate(problem, solution)
    seconds = time.perf_counter() - start
    if found is None:
        return None
    return {"estimate": found.relative, "pressure_estimate":
            found.pressure.relative if found.pressure is not None else float("nan"),
            "eta": found.total, "eta_recovery": found.recovery * found.scale,
            "eta_contact": found.contact * found.scale, "energy_norm": found.energy_norm * found.scale,
            "eta_without_contact": estimate(problem, solution, contact=False).total,
            "estimate_s": seconds}


def energy_error(coarse: ContactProblem, coarse_solution: ContactSolution, fine: ContactProblem,
                 fine_solution: ContactSolution, steps: int) -> dict[str, float]:
    """``‖u_fine − P u_coarse‖_E`` (``error``, physical) with P the prolongation over ``steps``
    uniform refinements, summed element by element on the finer mesh, and the fine answer's
    ``λᵀ·gap(P u_coarse)`` (``complementarity``, physical)."""
    P = uniform_prolongation(coarse.model.mesh.t, coarse.model.mesh.p.shape[1], steps)
    moved = P @ nodal_displacement(coarse, coarse_solution)
    E, nu = material_units(fine)
    s = fine.scales
    difference = (nodal_displacement(fine, fine_solution) - moved) / s.displacement
    energy = element_energies(fine.model.mesh, difference, E, nu, fine.model.axisymmetric).sum()
    v = (moved.ravel() / s.displacement)[fine.model.dofs()[1]]
    return {"error": float(np.sqrt(energy * s.force * s.displacement)),
            "complementarity": float(fine_solution.lam @ fine.gap(v)) * s.force * s.displacement,
            "dofs": fine.n}


def whole_process(argv: list[str], record: bool = False, ranks: int = 1) -> dict[str, Any]:
    """``python argv…`` timed whole, start to exit, under ``/usr/bin/time -v`` (``mpirun`` for
    ``ranks`` > 1): its return code, wall time (``wall_s``), the peak resident memory of its
    largest process (``peak_gb``), its last line of output, its last line of error output that
    starts with "signorini" (``said``) and, with ``record``, the JSON it wrote to ``--json``."""
    with tempfile.TemporaryDirectory(prefix="signorini-") as folder:
        path = Path(folder) / "record.json"
        words, env = [sys.executable, *argv] + (["--json", str(path)] if record else []), None
        if ranks > 1:
            words, env = mpirun_command(ranks, words)
        done = subprocess.run(["/usr/bin/time", "-v", *words], capture_output=True, text=True,
                              env=env)
        written = json.loads(path.read_text()) if record and path.exists() else None
    timing = dict(line.strip().rsplit(": ", 1) for line in done.stderr.splitlines()
                  if ": " in line and line.startswith("\t"))
    clock = timing.get("Elapsed (wall clock) time (h:mm:ss or m:ss)", "0:0").split(":")
    said = [line for line in done.stderr.strip().splitlines() if line.startswith("signorini")]
    out = done.stdout.strip().splitlines()
    return {"returncode": done.returncode,
            "wall_s": sum(float(part) * 60 ** i for i, part in enumerate(reversed(clock))),
            "peak_gb": float(timing.get("Maximum resident set size (kbytes)", "nan")) / 1024 ** 2,
            "said": said[-1] if said else "", "output": out[-1] if out else "", "record": written}


__all__ = ["certificate_of", "hertz_errors", "bound_at_solution", "force_error",
           "weak_but_penetrating", "factorisation_time", "pressure_profile", "answer_record",
           "answer_from", "forward_error", "resident", "factor_memory", "estimate_record",
           "energy_error", "whole_process"]
