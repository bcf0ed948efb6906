"""The forward error of λ against the error itself as ν → ½ (docs/certificate.md).

    PYTHONPATH=. .venv/bin/python tools/certificate_study.py   # ~1 min; writes docs/certificate/study.json

Hertz's cylinder (``n_contact=20``, the default volumetric treatment, its load matched once)
for each ν of ``NUS`` and each method of ``METHODS``, each a task of the studies' runner:
the method's status, the true relative error of λ against pdas's answer refined in long
double on its active set (the ``refined`` reference policy,
:func:`signorini.certification.comparison.refined_on_active_set`), and the certificate's estimate
(``force_error``) and its floor (``force_error_floor``): the ``forward_error`` measure. ``table`` renders
the page's table from the JSON; tests/test_hostile_answers.py holds the page to it.
"""

from __future__ import annotations

import importlib.util
import json
import sys
from pathlib import Path

from signorini.files import atomic_write_text, to_json
from signorini.studies.runner import run_tasks
from signorini.studies.task import Task

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


def tasks(nus: tuple[float, ...] = NUS) -> list[Task]:
    """A task per ν and installed method, held to the refined reference."""
    return [Task(axis="nu", case="hertz-cylinder", value=nu, method=method, tol=tol,
                 problem={"kind": "scene", "scene": "hertz-cylinder", "params": {"nu": nu, **SCENE}},
                 reference={"kind": "refined", "steps": STEPS}, measure=("forward_error",))
            for nu in nus for method, tol in METHODS
            if method != "qp-qpalm" or importlib.util.find_spec("qpalm") is not None]


def row_of(row: dict) -> dict:
    """The study's row from the runner's."""
    return {"nu": row["value"], "method": row["method"], "tol": row["tol"], "status": row["status"],
            "claimed": row["claimed_status"], **row["forward_error"]}


def run(nus: tuple[float, ...] = NUS) -> list[dict]:
    return [row_of(row) for row in run_tasks(tasks(nus), progress=lambda i, n, t, r: print(
        f"{i}/{n} ν={t.value:<14.12g} {t.method:15s} {r['status']}", file=sys.stderr))]


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
