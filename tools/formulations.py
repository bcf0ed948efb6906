"""QP formulations per backend on Hertz's cylinder: status, λ vs pdas, misclassified nodes, time.

    .venv/bin/python tools/formulations.py                # all cases (~1 h here); writes the JSON
    .venv/bin/python tools/formulations.py --case default # one case, merged into the JSON
    .venv/bin/python tools/formulations.py --doc          # docs/formulations.md's tables from it

Every run goes through the studies' runner (signorini.studies.runner: a worker process,
a time limit, the package's certificate, λ against pdas at 1e-9 and the nodes classified
differently, the method's own time and one factorisation + solve of K in the same
process). Each case also times pdas at 1e-9 three times (first, middle, last); the ratio
to pdas is to their median. Polished runs (``polish=true``) are separate runs.
docs/formulations.md quotes the tables ``tables`` renders from docs/formulations/runs.json
(``--doc`` writes them; tests/test_forms.py holds them to the JSON).
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from readme import fill_blocks, head_commit, pattern  # noqa: E402  (tools/readme.py)

from signorini.files import atomic_write_text, to_json  # noqa: E402
from signorini.solvers import forms, qp  # noqa: E402
from signorini.solvers.registry import get_method  # noqa: E402
from signorini.studies.runner import run_tasks  # noqa: E402
from signorini.studies.task import Task  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "docs" / "formulations" / "runs.json"
DOC = ROOT / "docs" / "formulations.md"
#: case name → the hertz-cylinder's parameters (``--set``)
CASES = {"default": {}, "displacement": {"loading": "displacement"},
         "refine2": {"refine": 2}, "refine2-displacement": {"refine": 2, "loading": "displacement"}}
TOLS = (1e-6, 1e-9, 1e-12)
#: polished runs at these tolerances (all of them on the small cases)
POLISH_TOLS = {"default": TOLS, "displacement": TOLS, "refine2": (1e-6, 1e-9),
               "refine2-displacement": (1e-6, 1e-9)}
TIME_LIMIT = 120.0
KEEP = ("case", "method", "tol", "status", "claimed_status", "lam_rel", "misclassified",
        "kkt_worst", "kkt_name", "method_s", "factor_s", "dofs", "candidates", "message",
        "exact_ok", "time_s")


def methods() -> list[str]:
    """Every installed qp-* method and cvxpy."""
    names = [backend.method_name for backend in qp.BACKENDS] + ["cvxpy"]
    return [name for name in names if get_method(name).installed]


def tasks(case: str) -> list[Task]:
    problem = {"kind": "scene", "scene": "hertz-cylinder", "params": CASES[case]}

    def pdas(i: int) -> Task:
        return Task("formulations", case, f"pdas {i}", problem, "pdas", tol=1e-9,
                    measure=("times", "factorisation"))

    runs = []
    for method in methods():
        for form in forms.FORMS:
            for tol in TOLS:
                for polish in (False, True):
                    if polish and tol not in POLISH_TOLS[case]:
                        continue
                    runs.append(Task("formulations", case, f"{form}{' polish' if polish else ''}",
                                     problem, method, tol=tol,
                                     options={"form": form, "polish": polish},
                                     measure=("times", "factorisation")))
    middle = len(runs) // 2
    return [pdas(0), *runs[:middle], pdas(1), *runs[middle:], pdas(2)]


def run(case: str) -> dict:
    load_before = os.getloadavg()
    start = time.perf_counter()

    def say(index, count, task, row):
        print(f"{case} {index}/{count} {task.method} {task.value} {task.tol:g}: {row.get('status')} "
              f"{row.get('lam_rel', float('nan')):.1e} {row.get('method_s', float('nan')):.2f} s",
              file=sys.stderr, flush=True)

    all_tasks = tasks(case)
    rows = run_tasks(all_tasks, time_limit=TIME_LIMIT, progress=say)
    out = []
    for task, row in zip(all_tasks, rows):
        kept = {key: row.get(key) for key in KEEP}
        form, _, polish = str(task.value).partition(" ")
        kept.update(form=form if task.method != "pdas" else "", polish=bool(polish),
                    case=case, message=(row.get("message") or "")[:300])
        out.append(kept)
    return {"case": case, "params": CASES[case], "rows": out, "seconds": time.perf_counter() - start,
            "load_before": load_before, "load_after": os.getloadavg(), "commit": head_commit()}


def load() -> dict:
    return json.loads(OUT.read_text())


# --- tables -----------------------------------------------------------------------------------


def pdas_time(case: dict) -> float:
    return statistics.median(r["method_s"] for r in case["rows"] if r["method"] == "pdas")


def _label(row: dict) -> str:
    status = row["status"]
    if status == "converged":
        return "**ok**" if row.get("exact_ok") else "conv., λ off"
    return {"inaccurate": "inacc.", "max_iter": "max_iter", "refused": "refused",
            "timeout": "timeout"}.get(status, status)


def cell(row: dict | None, pdas_s: float) -> str:
    """``status λ-error/misclassified time×`` of one run."""
    if row is None:
        return "–"
    if row["status"] in ("refused", "timeout", "crashed", "input-error"):
        return _label(row)
    lam = row.get("lam_rel")
    lam_text = "–" if lam is None or lam != lam else f"{lam:.0e}"
    wrong = row.get("misclassified")
    wrong_text = "" if not wrong else f", {wrong} wrong"
    seconds = row.get("method_s")
    time_text = "" if seconds is None or seconds != seconds else f", {seconds / pdas_s:.1f}×"
    return f"{_label(row)} {lam_text}{wrong_text}{time_text}"


def case_table(case: dict, polish: bool) -> str:
    rows = [r for r in case["rows"] if r["method"] != "pdas" and r["polish"] == polish]
    tols = sorted({r["tol"] for r in rows}, reverse=True)
    pdas_s = pdas_time(case)
    lines = ["| method | form | " + " | ".join(f"tol {t:g}" for t in tols) + " |",
             "|---|---|" + "---|" * len(tols)]
    for method in dict.fromkeys(r["method"] for r in rows):
        for form in forms.FORMS:
            found = {r["tol"]: r for r in rows if r["method"] == method and r["form"] == form}
            if not found:
                continue
            default = " (default)" if form == default_form(method) else ""
            lines.append(f"| {method} | {form}{default} | "
                         + " | ".join(cell(found.get(t), pdas_s) for t in tols) + " |")
    return "\n".join(lines)


def default_form(method: str) -> str:
    if method.startswith("qp-"):
        return qp.BACKEND_BY_NAME[method[3:]].form
    return "primal"


def summary(data: dict) -> str:
    """Per method and form: how many of the runs are converged and agree with pdas, raw and
    polished, over every case and tolerance; the median time over pdas at tol 1e-9."""
    cases = [data["cases"][name] for name in CASES if name in data["cases"]]
    lines = ["| method | form | exact and converged (raw) | … polished | time at 1e-9 / pdas "
             "| … / one factorisation |", "|---|---|---:|---:|---:|---:|"]
    all_rows = [r for case in cases for r in case["rows"] if r["method"] != "pdas"]
    for method in dict.fromkeys(r["method"] for r in all_rows):
        for form in forms.FORMS:
            counts = []
            for polish in (False, True):
                mine = [r for r in all_rows if r["method"] == method and r["form"] == form
                        and r["polish"] == polish]
                good = sum(1 for r in mine if r["status"] == "converged" and r.get("exact_ok"))
                counts.append(f"{good}/{len(mine)}")
            timed = [(r, case) for case in cases for r in case["rows"]
                     if r["method"] == method and r["form"] == form and not r["polish"]
                     and r["tol"] == 1e-9 and r.get("method_s") is not None
                     and r["status"] not in ("refused", "timeout")]
            ratios = [_median([r["method_s"] / pdas_time(case) for r, case in timed]),
                      _median([r["method_s"] / r["factor_s"] for r, _ in timed])]
            default = " (default)" if form == default_form(method) else ""
            lines.append(f"| {method} | {form}{default} | {counts[0]} | {counts[1]} | "
                         + " | ".join("–" if x is None else f"{x:.1f}×" for x in ratios) + " |")
    return "\n".join(lines)


def _median(values: list[float]) -> float | None:
    return statistics.median(values) if values else None


def tables(data: dict) -> dict[str, str]:
    out = {"summary": summary(data)}
    for name in CASES:
        case = data["cases"].get(name)
        if case is None:
            continue
        dofs = next(r["dofs"] for r in case["rows"] if r.get("dofs"))
        m = next(r["candidates"] for r in case["rows"] if r.get("candidates"))
        pdas = " s, ".join(f"{r['method_s']:.3g}" for r in case["rows"] if r["method"] == "pdas")
        factor = _median([r["factor_s"] for r in case["rows"] if r.get("factor_s")])
        head = (f"{dofs:,} dofs, {m} candidates; pdas {pdas} s (× is over their median), one "
                f"factorisation + solve of K {factor:.3g} s (median); load average "
                f"{case['load_before'][0]:.1f} → {case['load_after'][0]:.1f}; commit "
                f"{case['commit']}, {case['seconds']:.0f} s for the case\n\n")
        out[name] = head + case_table(case, polish=False)
        out[f"{name}-polish"] = case_table(case, polish=True)
    return out


def write_doc() -> None:
    fill_blocks(DOC, tables(load()))


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--case", action="append", choices=sorted(CASES))
    parser.add_argument("--doc", action="store_true", help="write docs/formulations.md's tables")
    args = parser.parse_args()
    if args.doc:
        write_doc()
        return 0
    data = load() if OUT.exists() else {"command": "python tools/formulations.py", "cases": {}}
    for case in args.case or list(CASES):
        data["cases"][case] = run(case)
        atomic_write_text(OUT, to_json(data))  # each case kept as soon as it is done
        print(f"written: {OUT} ({case})", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
