"""signorini.crosscheck on every validation case, with the QP methods' defaults and without them.

    .venv/bin/python tools/crosscheck_cases.py        # ≈ 1 min here; docs/crosscheck/cases.json
    .venv/bin/python tools/crosscheck_cases.py --doc  # docs/crosscheck.md's tables from it

Every case of the validation suite (signorini.studies.suite.DEFAULT_CASES) is cross-checked
at tol 1e-8 with uzawa, qp-osqp, qp-clarabel, cvxpy and pdas (signorini.crosschecking: the
runner's ``crosscheck`` task kind, in a worker with a time limit), in three variants of the
QP methods' options:

- ``raw``: what the cross-check judges by default, each backend's own answer (OSQP's dual
  form with its own polishing, Clarabel and cvxpy primal with Clarabel's gap tolerance at
  tol², floored at 1e-14; no polish of ours);
- ``polished``: the same with ``polish=true``, what ``signorini.solve`` returns by default;
- ``before``: raw, with Clarabel's gap tolerance at tol and OSQP without its own polishing
  (the translations before issues 17 and 28).

The issue's condition is read from the pairs with pdas (the exact answer): a method passes a
case when it said ``converged``, the certificate agrees, λ is within 1e-6 of pdas's and no node
is classified apart. tests/test_crosscheck.py holds docs/crosscheck.md's tables to the JSON and
the default variant to that condition.
"""

from __future__ import annotations

import os
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from readme import fill_blocks, provenance, study_main

from signorini.studies.runner import run_tasks
from signorini.studies.suite import DEFAULT_CASES
from signorini.studies.task import CROSSCHECK, Task

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "docs" / "crosscheck" / "cases.json"
DOC = ROOT / "docs" / "crosscheck.md"
TOL = 1e-8
#: seconds a case's cross-check (every method) may take in the runner's worker
TIME_LIMIT = 600.0
METHODS = ("uzawa", "qp-osqp", "qp-clarabel", "cvxpy", "pdas")
QP_METHODS = ("qp-osqp", "qp-clarabel", "cvxpy")
#: the issue's condition on λ against the exact answer
LAM_LIMIT = 1e-6
VARIANTS = {
    "raw": {},
    "polished": {name: {"polish": True} for name in QP_METHODS},
    "before": {"qp-osqp": {"polishing": False},
               "qp-clarabel": {"tol_gap_abs": TOL, "tol_gap_rel": TOL, "tol_ktratio": TOL}},
}


def tasks(cases=DEFAULT_CASES) -> list[Task]:
    """A crosscheck task per case and variant, on the case's scene as built (each method
    matches its load, as signorini.crosscheck does)."""
    return [Task(axis=variant, case=case.name, value="", method=CROSSCHECK, tol=TOL,
                 problem={"kind": "scene", "scene": case.scene, "params": case.params,
                          "matched": False},
                 options={"methods": list(METHODS), "options": options},
                 reference={"kind": "none"})
            for case in cases for variant, options in VARIANTS.items()]


def run(cases=DEFAULT_CASES) -> dict:
    data = {**provenance("crosscheck_cases.py"), "tol": TOL, "variants": {}}
    start, chosen = time.perf_counter(), tasks(cases)
    for task, row in zip(chosen, run_tasks(chosen, time_limit=TIME_LIMIT, progress=lambda i, n, t, r:
                                           print(f"{t.case:<22} {t.axis:<8} {r['message']}",
                                                 file=sys.stderr))):
        if "crosscheck" not in row:
            raise RuntimeError(f"{task.case} ({task.axis}): {row['status']}: {row['message']}")
        data["variants"].setdefault(task.axis, {})[task.case] = {**row["crosscheck"],
                                                                 "case": task.case}
    data["seconds"] = time.perf_counter() - start
    data["load_after"] = list(os.getloadavg())
    return data


def verdict(record: dict, method: str) -> dict:
    """A method's run on a case and its pair with pdas: status, λ vs pdas, nodes apart, ok."""
    run_ = next(r for r in record["methods"] if r["method"] == method)
    pair = next((p for p in record["pairs"] if {p["first"], p["second"]} == {method, "pdas"}), None)
    ok = (pair is not None and run_["status"] == "converged" and run_["claimed_status"] == "converged"
          and pair["lam_rel"] is not None and pair["lam_rel"] <= LAM_LIMIT and pair["apart"] == 0)
    return {"status": run_["status"], "claimed": run_["claimed_status"], "polished": run_["polished"],
            "lam_rel": None if pair is None else pair["lam_rel"],
            "apart": None if pair is None else pair["apart"], "ok": ok}


def cell(v: dict) -> str:
    said = v["status"] if v["claimed"] == v["status"] else f"{v['claimed']} → {v['status']}"
    lam = "–" if v["lam_rel"] is None else f"{v['lam_rel']:.1e}"
    apart = f", {v['apart']} apart" if v["apart"] else ""
    mark = "**ok**" if v["ok"] else said
    polished = " (polished)" if v["polished"] else ""
    return f"{mark}{polished}: λ {lam}{apart}"


def table(data: dict, variant: str) -> str:
    cases = data["variants"][variant]
    head = "| case | dofs | " + " | ".join(m for m in METHODS if m != "pdas") + " | check |"
    lines = [head, "|---|---:|" + "---|" * (len(METHODS) - 1) + "---|"]
    for name, record in cases.items():
        cells = [cell(verdict(record, m)) for m in METHODS if m != "pdas"]
        pairs = "passed" if record["passed"] else "FAILED: " + ", ".join(record["failures"])
        lines.append(f"| {name} | {record['dofs']:,} | " + " | ".join(cells) + f" | {pairs} |")
    return "\n".join(lines)


def summary(data: dict) -> str:
    lines = ["| variant | " + " | ".join(QP_METHODS) + " | cases the cross-check passes |",
             "|---|" + "---:|" * len(QP_METHODS) + "---:|"]
    for variant, cases in data["variants"].items():
        counts = [sum(verdict(r, m)["ok"] for r in cases.values()) for m in QP_METHODS]
        passed = sum(r["passed"] for r in cases.values())
        lines.append(f"| {variant} | " + " | ".join(f"{c}/{len(cases)}" for c in counts)
                     + f" | {passed}/{len(cases)} |")
    head = (f"tol {data['tol']:.0e}; {data['machine']}; commit {data['commit']}; "
            f"{data['seconds']:.0f} s for all; load average {data['load_before'][0]:.1f} → "
            f"{data['load_after'][0]:.1f}\n\n")
    return head + "\n".join(lines)


def blocks(data: dict) -> dict[str, str]:
    return {"summary": summary(data), **{v: table(data, v) for v in data["variants"]}}


def write_doc(data: dict) -> None:
    fill_blocks(DOC, blocks(data))


def main() -> int:
    return study_main("docs/crosscheck.md", OUT, run, write_doc)


if __name__ == "__main__":
    sys.exit(main())
