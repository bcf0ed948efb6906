"""Each QP backend per formulation at 66k and 261k dofs, as a multiple of one factorisation.

    .venv/bin/python tools/bench_forms.py        # ≈ 1 h here; docs/bench-forms/runs.json
    .venv/bin/python tools/bench_forms.py --doc  # docs/bench-forms.md's tables from it

Hertz's cylinder at the benchmark's large sizes (``--set n_contact=110 --set grading=0.1``,
refine 1 and 2: 65,770 and 261,300 dofs, as docs/bench-nested), each problem assembled once
and stored; every run in a process of its own (signorini.studies.runner, ``fresh``: the
method starts cold) within TIME_LIMIT seconds, at tol 1e-8:

- every installed sparse qp-* backend and cvxpy, in each form (primal, shifted, dual), with its
  default polish (on for qp-osqp, qp-clarabel and cvxpy), the form's own factorisation
  and W included in its time; the dense backends (DAQP, quadprog, ECOS) on the dual only
  (their primal is refused above 3000 dofs);
- nested and pdas, the exact methods.

``ratio`` is the method's own time over one factorisation + solve of the same K with the same
backend, timed in the same process just before it (not the certificate that judges it).
The exact answer is nested's at 1e-9, stored beside each problem. tests/test_bench_forms.py
holds docs/bench-forms.md's tables to the JSON.
"""

from __future__ import annotations

import os
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from readme import fill_blocks, provenance, study_main

from signorini.files import atomic_write_text, to_json
from signorini.solvers import cvxpy_, qp
from signorini.solvers.forms import FORMS
from signorini.solvers.registry import get_method
from signorini.studies.bench import problem_file, reference_policy, stored_size
from signorini.studies.runner import run_tasks
from signorini.studies.task import Task

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "docs" / "bench-forms" / "runs.json"
DOC = ROOT / "docs" / "bench-forms.md"
#: stored problems (large: not committed)
PROBLEMS = Path(os.environ.get("SIGNORINI_BENCH_PROBLEMS", "/tmp/signorini-bench-forms"))
SCENE = "hertz-cylinder"
BASE = {"n_contact": 110, "grading": 0.1}
SIZES = {"refine1": 1, "refine2": 2}
TOL = 1e-8
TIME_LIMIT = 120.0
EXACT = ("nested", "pdas")
KEEP = ("status", "claimed_status", "iterations", "method_s", "factor_s", "ratio_to_factor",
        "kkt_worst", "kkt_name", "lam_rel", "misclassified", "exact_ok", "message")


def qp_methods() -> list[tuple[str, tuple[str, ...]]]:
    """(method, forms) for every installed QP method: dense backends on the dual only."""
    out = []
    for backend in qp.BACKENDS:
        method = get_method(backend.method_name)
        if method.installed:
            out.append((backend.method_name, ("dual",) if backend.dense else FORMS))
    if get_method("cvxpy").installed:
        out.append(("cvxpy", FORMS))
    return out


def default_polish(method: str) -> bool | None:
    """Whether ``method`` polishes by default (None for the exact methods)."""
    if method.startswith("qp-"):
        return qp.BACKEND_BY_NAME[method[3:]].polish
    return cvxpy_.DEFAULT_POLISH if method == "cvxpy" else None


def tasks(size: str, path: Path) -> list[Task]:
    problem = {"kind": "stored", "path": str(path)}
    common = {"tol": TOL, "reference": reference_policy(path), "fresh": True,
              "measure": ("factorisation", "times")}
    out = [Task("bench-forms", size, "exact", problem, name, **common) for name in EXACT]
    for method, forms in qp_methods():
        out += [Task("bench-forms", size, form, problem, method, options={"form": form}, **common)
                for form in forms]
    return out


def run() -> dict:
    data = {**provenance("bench_forms.py"), "tol": TOL, "time_limit": TIME_LIMIT, "scene": SCENE,
            "params": BASE, "sizes": {}}
    start = time.perf_counter()
    for size, level in SIZES.items():
        path = problem_file(PROBLEMS, SCENE, size, {**BASE, "refine": level})
        dofs, candidates = stored_size(path)
        todo = tasks(size, path)

        def say(index, count, task, row, size=size):
            print(f"{size} {index}/{count} {task.method} {task.value}: {row.get('status')} "
                  f"ratio {row.get('ratio_to_factor', float('nan')):.2f}", file=sys.stderr, flush=True)

        rows = run_tasks(todo, time_limit=TIME_LIMIT, progress=say)
        data["sizes"][size] = {
            "dofs": dofs, "candidates": candidates,
            "rows": [{"method": t.method, "form": "" if t.value == "exact" else t.value,
                      "polish": default_polish(t.method),
                      **{k: row.get(k) for k in KEEP},
                      "message": (row.get("message") or "")[:300]}
                     for t, row in zip(todo, rows)]}
        atomic_write_text(OUT, to_json(data))  # each size kept as soon as it is done
    data["seconds"] = time.perf_counter() - start
    data["load_after"] = list(os.getloadavg())
    return data


# --- tables -------------------------------------------------------------------------------------


def _ratio(row: dict | None) -> str:
    if row is None:
        return "–"
    status = row["status"]
    if row.get("ratio_to_factor") is None or status in ("timeout", "refused", "crashed"):
        return status
    ratio = f"{row['ratio_to_factor']:.1f}×"
    if status == "converged" and row.get("exact_ok"):
        return f"**{ratio}**"
    wrong = f", {row['misclassified']:.0f} wrong" if row.get("misclassified") else ""
    return f"{ratio} {status}{wrong}"


def table(data: dict) -> str:
    sizes = list(data["sizes"])
    head = ["method", "form"] + [f"{data['sizes'][s]['dofs']:,} dofs" for s in sizes]
    lines = ["| " + " | ".join(head) + " |", "|---|---|" + "---:|" * len(sizes)]
    keys = []
    for s in sizes:
        for row in data["sizes"][s]["rows"]:
            key = (row["method"], row["form"])
            if key not in keys:
                keys.append(key)
    for method, form in keys:
        cells = []
        for s in sizes:
            match = [r for r in data["sizes"][s]["rows"] if (r["method"], r["form"]) == (method, form)]
            cells.append(_ratio(match[0] if match else None))
        default = form and _default_form(method) == form
        label = (form or "exact") + (" (default)" if default else "")
        lines.append(f"| {method} | {label} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def header(data: dict) -> str:
    sizes = data["sizes"]
    factor = ", ".join(f"{s['dofs']:,} dofs {min(r['factor_s'] for r in s['rows'] if r.get('factor_s')):.2f}–"
                       f"{max(r['factor_s'] for r in s['rows'] if r.get('factor_s')):.2f} s"
                       for s in sizes.values())
    return (f"tol {data['tol']:.0e}, time limit {data['time_limit']:.0f} s a run; {data['machine']}; "
            f"commit {data['commit']}; {data['seconds'] / 60:.0f} min for all; load average "
            f"{data['load_before'][0]:.1f} → {data['load_after'][0]:.1f}; one factorisation + "
            f"solve of K: {factor}")


def _default_form(method: str) -> str:
    return qp.BACKEND_BY_NAME[method[3:]].form if method.startswith("qp-") else cvxpy_.DEFAULT_FORM


def summary(data: dict) -> str:
    """docs/methods.md's lines: the exact methods, the three named QP methods in their default form,
    and the fastest QP run that ended converged and exact, per size."""
    named = ("qp-osqp", "qp-clarabel", "cvxpy")
    head = ["dofs", "nested", "pdas"] + [f"{m} ({_default_form(m)})" for m in named]
    head.append("fastest exact QP run")
    lines = ["| " + " | ".join(head) + " |", "|---:|" + "---:|" * (len(head) - 1)]
    for size in data["sizes"].values():
        rows = size["rows"]

        def find(method: str, form: str, rows: list[dict] = rows) -> dict | None:
            return next((r for r in rows if (r["method"], r["form"]) == (method, form)), None)

        exact_qp = [r for r in rows if r["form"] and r["status"] == "converged" and r.get("exact_ok")]
        best = min(exact_qp, key=lambda r: r["ratio_to_factor"], default=None)
        cells = [f"{size['dofs']:,}", _ratio(find("nested", "")), _ratio(find("pdas", ""))]
        cells += [_ratio(find(m, _default_form(m))) for m in named]
        cells.append("none" if best is None else
                     f"{best['method']} {best['form']}: {best['ratio_to_factor']:.1f}×")
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def blocks(data: dict) -> dict[str, str]:
    return {"bench-forms": header(data) + "\n\n" + table(data),
            "bench-forms-summary": summary(data)}


def write_doc(data: dict) -> None:
    """Every block of docs/bench-forms.md, and its summary in docs/methods.md."""
    fill_blocks(DOC, blocks(data))
    fill_blocks(ROOT / "docs" / "methods.md", blocks(data), required=False)


def main() -> int:
    return study_main("docs/bench-forms.md", OUT, run, write_doc)


if __name__ == "__main__":
    sys.exit(main())
