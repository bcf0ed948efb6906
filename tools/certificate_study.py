"""The forward error of λ against the error itself as ν → ½ (docs/certificate.md).

    PYTHONPATH=. .venv/bin/python tools/certificate_study.py   # ~1 min; writes docs/certificate/study.json

Hertz's cylinder (``n_contact=20``, the default volumetric treatment) for each ν of
``NUS`` and each method of ``METHODS``: the method's status, the true relative error of λ
against a reference refined in long double on the same active set
(:func:`signorini.forward_error.refined_on_active_set`), and the certificate's
estimate (``force_error``) and its floor (``force_error_floor``). ``table`` renders
the page's table from the JSON; tests/test_hostile_answers.py holds the page to it.
"""

from __future__ import annotations

import importlib.util
import json
import sys
from pathlib import Path

import numpy as np

from signorini.files import atomic_write_text, to_json
from signorini.forward_error import refined_on_active_set
from signorini.kkt import active_set, certificate
from signorini.numerics.factor import factorize
from signorini.scenes import build_problem
from signorini.solvers.registry import solve

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "docs" / "certificate" / "study.json"
PAGE = ROOT / "docs" / "certificate.md"
NUS = (0.3, 0.49, 0.4999, 0.499999, 0.49999999999)
#: (method, tol): None is the method's own default
METHODS = (("pdas", None), ("nested", None), ("uzawa", 1e-8), ("uzawa-nesterov", 1e-8),
           ("condensed", 1e-8), ("qp-qpalm", None))
SCENE = {"n_contact": 20}
#: long-double refinement steps of the reference
STEPS = 20


def reference(problem) -> np.ndarray:
    """λ on pdas's active set, refined with long-double residuals (as a float array)."""
    start = solve(problem, "pdas")
    _, lam = refined_on_active_set(problem.K, problem.f, problem.N, problem.d, start.u, start.lam,
                                   active_set(problem, start), factorize(problem.K), steps=STEPS)
    return lam.astype(float)


def run() -> list[dict]:
    rows = []
    for nu in NUS:
        problem = build_problem("hertz-cylinder", params={"nu": nu, **SCENE})
        lam_ref = reference(problem)
        for method, tol in METHODS:
            module = "qpalm" if method == "qp-qpalm" else None
            if module and importlib.util.find_spec(module) is None:
                continue
            solution = solve(problem, method, tol=tol)
            cert = certificate(problem, solution)
            error = float(np.max(np.abs(solution.lam - lam_ref)) / np.max(np.abs(lam_ref)))
            rows.append({"nu": nu, "method": method, "tol": tol, "status": solution.status,
                         "claimed": solution.own_status, "lam_error": error,
                         "force_error": cert.force_error, "force_error_floor": cert.force_error_floor,
                         "back_solves": cert.back_solves})
            print(f"ν={nu:<14.12g} {method:15s} {solution.status:11s} error {error:.1e} "
                  f"estimate {cert.force_error:.1e} floor {cert.force_error_floor:.1e}", file=sys.stderr)
    return rows


def _method(row: dict) -> str:
    return row["method"] + (f" (tol {row['tol']:g})" if row["tol"] is not None else "")


def table(rows: list[dict]) -> list[str]:
    """Markdown: one line per method and ν: status (the method's claim), λ error, estimate, floor."""
    lines = ["| method | ν | status (claimed) | λ error | force_error | force_error_floor |",
             "|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {_method(r)} | {r['nu']:.12g} | {r['status']} ({r['claimed']}) | "
                     f"{r['lam_error']:.1e} | {r['force_error']:.1e} | {r['force_error_floor']:.1e} |")
    return lines


if __name__ == "__main__":
    found = run()
    atomic_write_text(OUT, to_json({"scene": "hertz-cylinder", "params": SCENE, "steps": STEPS,
                                    "rows": found}) + "\n")
    print("\n".join(table(json.loads(OUT.read_text())["rows"])))
