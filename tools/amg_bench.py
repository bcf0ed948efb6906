"""pdas-amg at scale on hertz-sphere-3d: the measurements behind docs/amg/ (issue 14).

    .venv/bin/python tools/amg_bench.py run [--part NAME ...]   # measure, merge into docs/amg/bench.json
    .venv/bin/python tools/amg_bench.py md                      # docs/amg/bench.md from the JSON

Parts (each one a key of the JSON, re-run alone with --part):

- ``backends``: one multigrid set-up and one CG solve of K (the bound form with the
  prescribed dofs pinned, no contact) to a relative residual of 1e-10, on the 350k-dof
  sphere: pyamg's smoothed aggregation, PETSc GAMG as the package sets it up
  (``signorini.solvers.amg_system.GAMG_OPTIONS``) and with PETSc's own coarsest level and smoothing;
- ``crossover``: pdas against pdas-amg (method time) at 7k, 12k and 47k dofs;
- ``whole-350k`` and ``whole-1m``: the default command, ``/usr/bin/time -v signorini solve
  hertz-sphere-3d ... --json``, whole process (wall time, peak memory, the record);
- ``petsc-350k``: the same problem solved in one process by pdas-amg and petsc-vi (1 rank):
  λ's relative difference and the nodes classified apart;
- ``whole-350k-load``, ``whole-1m-load``, ``whole-largest-load`` (refine=3, the finest the size
  guard lets through here) and ``petsc-350k-load``: the same for the scene's own
  default, a target load (Hertz's a/R = 0.05) instead of a push: ``auto`` picks ``pdas-amg``,
  which matches the load with the answer (the push one more unknown, no factorisation).

Every part records the load average before and after it: the machine has 2 cores, shared.
A whole-process run is a task of the studies' runner (the ``(command)`` kind: a process of its
own, timed start to exit, stopped at its time limit); ``backends``, ``crossover`` and the
``petsc`` parts time set-ups and solves inside one process, as the parts describe.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from signorini.studies.runner import run_tasks
from signorini.studies.task import COMMAND, Task

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "docs" / "amg"
JSON = OUT / "bench.json"
SPHERE_350K = {"refine": 2, "delta": 0.0025}
SPHERE_1M = {"refine": 2, "n_contact": 24, "delta": 0.0025}
SPHERE_350K_LOAD = {"refine": 2}
SPHERE_1M_LOAD = {"refine": 2, "n_contact": 24}
#: the finest default the size guard lets through at 19 GB (about 3.7M dofs estimated)
SPHERE_LARGEST_LOAD = {"refine": 3}
PARTS = ("backends", "crossover", "whole-350k", "petsc-350k", "whole-1m", "whole-350k-load",
         "whole-1m-load", "whole-largest-load", "petsc-350k-load", "scale", "nested-1m")
#: the scale table (part ``scale``): a push, so that every method solves the same problem
SCALE_SIZES = {"50k": {"refine": 1, "delta": 0.0025}, "350k": SPHERE_350K, "1m": SPHERE_1M}
#: (label, method, options, MPI ranks)
SCALE_METHODS = (("pdas-amg", "pdas-amg", (), 1),
                 ("petsc-vi, 1 rank", "petsc-vi", ("ksp=gamg",), 1),
                 ("petsc-vi, 2 ranks", "petsc-vi", ("ksp=gamg",), 2),
                 ("nested", "nested", (), 1), ("pdas", "pdas", (), 1))
SCALE_TIMEOUT = 900.0
#: one AMG solve's relative residual: pdas-amg drives stationarity to 0.1 · tol (tol 1e-9)
AMG_RTOL = 1e-10


def machine() -> dict:
    cpu = ""
    for line in Path("/proc/cpuinfo").read_text().splitlines():
        if line.startswith("model name"):
            cpu = line.split(":", 1)[1].strip()
            break
    return {"cpu": cpu, "cores": os.cpu_count(), "python": platform.python_version(),
            "memory_gb": round(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES") / 1e9, 1)}


def load() -> float:
    return round(os.getloadavg()[0], 2)


def command_line(params: dict) -> list[str]:
    words = ["solve", "hertz-sphere-3d"]
    for key, value in params.items():
        words += ["--set", f"{key}={value}"]
    return words


def timed(argv: list[str], timeout: float | None = None, record: bool = False,
          ranks: int = 1) -> dict:
    """``python argv…`` as a process of its own (a task of the studies' runner, ``(command)``),
    timed whole under /usr/bin/time -v and stopped after ``timeout`` seconds: its return code
    (None when stopped), wall time, peak memory of its largest process, last lines, record."""
    task = Task(axis="amg", case="command", value="", problem={}, method=COMMAND, fresh=True,
                options={"argv": argv, "record": record, "ranks": ranks}, reference={"kind": "none"})
    row = run_tasks([task], time_limit=float("inf") if timeout is None else timeout)[0]
    if "process" in row:
        return row["process"]
    return {"returncode": None, "wall_s": float(timeout or "nan"), "peak_gb": float("nan"),
            "said": "timed out" if row["status"] == "timeout" else row["message"], "output": "",
            "record": None}


def whole(params: dict, method: str | None = None, options: tuple[str, ...] = (), ranks: int = 1,
          timeout: float | None = None) -> dict:
    """The command (by default the default one) under /usr/bin/time -v: wall time, peak memory
    and its record; ``ranks`` > 1 runs it under mpirun."""
    words = command_line(params) + (["--method", method] if method else [])
    for option in options:
        words += ["--opt", option]
    before = load()
    run = timed(["-m", "signorini.cli", *words], timeout, record=True, ranks=ranks)
    keep = ("scene", "params", "method", "status", "message", "iterations", "dofs",
            "contact_candidates", "time", "kkt", "total_force", "hertz", "extras")
    env = [f"{k}={os.environ[k]}" for k in ("SIGNORINI_MAX_MEMORY_GB",) if k in os.environ]
    mpirun = ["mpirun", "-n", str(ranks)] if ranks > 1 else []
    record = run["record"]
    return {"command": " ".join(env + ["/usr/bin/time", "-v", *mpirun, ".venv/bin/signorini", *words]),
            "returncode": run["returncode"], "wall_s": run["wall_s"], "peak_gb": run["peak_gb"],
            "load_before": before, "load_after": load(), "said": run["said"],
            "record": None if record is None else {k: record.get(k) for k in keep if k in record}}


#: PETSc's own values of the options signorini.solvers.amg_system.GAMG_OPTIONS changes
PETSC_DEFAULTS = {"pc_gamg_coarse_eq_limit": "50", "mg_levels_ksp_max_it": "2"}


def _gamg_with(values: dict, A, modes, block: int):
    """signorini's GAMG hierarchy with some of its options set otherwise (then unset again)."""
    from petsc4py import PETSc

    from signorini.solvers import amg, amg_system

    options = PETSc.Options("signorini_amg_")
    for name, value in values.items():
        options.setValue(name, value)
    try:
        return amg_system.GamgHierarchy(A, modes, block)
    finally:
        for name in values:
            options.delValue(name)


def backends() -> dict:
    """One set-up + one CG solve of K per multigrid, on the 350k-dof sphere's bound form."""
    from signorini.numerics.multigrid import PyamgHierarchy, pinned_cg, pinned_matrix
    from signorini.scenes import build_problem
    from signorini.solvers import amg, amg_system
    from signorini.solvers.bounds import bound_form

    problem = build_problem("hertz-sphere-3d", params=SPHERE_350K)
    form = bound_form(problem)
    pinned = form.lower == form.upper
    A = pinned_matrix(form.K, pinned)
    modes = form.rigid_modes()
    rows = {}
    variants = {"pyamg (smoothed aggregation)": lambda: PyamgHierarchy(A, modes, form.block),
                "petsc GAMG (plain aggregation)": lambda: amg_system.GamgHierarchy(A, modes, form.block),
                "petsc GAMG, PETSc's coarsest level and smoothing":
                    lambda: _gamg_with(PETSC_DEFAULTS, A, modes, form.block)}
    for name, make in variants.items():
        before = load()
        start = time.perf_counter()
        hierarchy = make()
        setup = time.perf_counter() - start
        x = np.zeros(form.n)
        f = np.where(pinned, 0.0, form.f)
        target = 1e-10 * np.linalg.norm(f)
        start = time.perf_counter()
        result = pinned_cg(A, f, x, ~pinned, hierarchy.apply, lambda r2, ri, r0: r2 <= target,
                           5000)
        rows[name] = {"setup_s": setup, "solve_s": time.perf_counter() - start,
                      "iterations": result.iterations, "relative_residual": result.final / np.linalg.norm(f),
                      "load_before": before, "load_after": load()}
        del hierarchy
    return {"dofs": problem.n, "bound_form_unknowns": form.n, "nonzeros": int(A.nnz),
            "rtol": 1e-10, "rows": rows}


def crossover() -> dict:
    from signorini.scenes import build_problem
    from signorini.solvers.registry import get_method, solve

    rows = []
    for params in ({"delta": 0.0025}, {"n_contact": 16, "delta": 0.0025},
                   {"refine": 1, "delta": 0.0025}):
        problem = build_problem("hertz-sphere-3d", params=params)
        row = {"params": params, "dofs": problem.n, "load_before": load()}
        for method in ("pdas", "pdas-amg"):
            solve(problem, method)  # warm: imports, the coarse model's first build
            solution = solve(problem, method)
            row[method] = {"status": solution.status, "method_s": solution.extras["method_s"]}
        row["load_after"] = load()
        rows.append(row)
    return {"rows": rows}


def petsc_350k(params: dict = SPHERE_350K, method: str = "pdas-amg") -> dict:
    from signorini.certification.comparison import compare
    from signorini import solve as solve_scene
    from signorini.scenes import build_problem
    from signorini.solvers.registry import solve

    problem = build_problem("hertz-sphere-3d", params=params, solved_by=get_method(method))
    before = load()
    matched = solve_scene(problem, method)  # a target load matched with the answer
    problem, ours = matched.problem, matched.solution
    theirs = solve(problem, "petsc-vi")
    agreement = compare(problem, ours, theirs)
    return {"dofs": problem.n, "load_before": before, "load_after": load(), "ours": ours.method,
            "pdas-amg": {"status": ours.status, "method_s": ours.extras["method_s"]},
            "petsc-vi": {"status": theirs.status, "method_s": theirs.extras["method_s"],
                         "iterations": theirs.iterations},
            "lam_rel": agreement.lam_rel, "u_rel": agreement.u_rel,
            "misclassified": agreement.misclassified}


def one_amg_solve(params: dict, rtol: float = AMG_RTOL) -> dict:
    """One GAMG set-up and CG solve of K (prescribed dofs pinned, no contact) from zero to ``rtol``:
    the least an exact method without a factorisation can spend (run in a process of its own)."""
    from signorini.numerics.multigrid import pinned_cg, pinned_matrix
    from signorini.scenes import build_problem
    from signorini.solvers import amg, amg_system
    from signorini.solvers.bounds import bound_form

    problem = build_problem("hertz-sphere-3d", params=params)
    form = bound_form(problem)
    pinned = form.lower == form.upper
    A = pinned_matrix(form.K, pinned)
    hierarchy = amg_system.GamgHierarchy(A, form.rigid_modes(), form.block)
    setup = hierarchy.setup_s  # PETSc's import is not the hierarchy's
    f = np.where(pinned, 0.0, form.f)
    target = rtol * np.linalg.norm(f)
    start = time.perf_counter()
    result = pinned_cg(A, f, np.zeros(form.n), ~pinned, hierarchy.apply,
                       lambda r2, ri, r0: r2 <= target, 5000)
    return {"dofs": problem.n, "setup_s": setup, "solve_s": time.perf_counter() - start,
            "iterations": result.iterations, "rtol": rtol}


def scale() -> dict:
    """Issue 14's table: at ~50k, ~350k and ~1M dofs, one AMG solve of K and each method's whole
    command (its own process, /usr/bin/time -v), pdas and nested where they fit."""
    sizes = {}
    for name, params in SCALE_SIZES.items():
        before = load()
        timing = timed([str(Path(__file__).resolve()), "amg-solve", json.dumps(params)],
                       timeout=SCALE_TIMEOUT)
        one = json.loads(timing.pop("output")) if timing["returncode"] == 0 else None
        runs = {}
        for label, method, options, ranks in SCALE_METHODS:
            runs[label] = whole(params, method, options, ranks, timeout=SCALE_TIMEOUT)
            print(f"{name} {label}: {runs[label]['wall_s']:.0f} s", file=sys.stderr, flush=True)
        sizes[name] = {"params": params, "one_amg_solve": one, "one_amg_process": {k: timing[k] for k in ("wall_s", "peak_gb")},
                       "load_before": before, "load_after": load(), "runs": runs}
    return {"sizes": sizes}


MEASURE = {"backends": backends, "scale": scale, "crossover": crossover, "petsc-350k": petsc_350k,
           "whole-350k": lambda: whole(SPHERE_350K), "whole-1m": lambda: whole(SPHERE_1M),
           "whole-350k-load": lambda: whole(SPHERE_350K_LOAD),
           "whole-1m-load": lambda: whole(SPHERE_1M_LOAD),
           "whole-largest-load": lambda: whole(SPHERE_LARGEST_LOAD),
           "petsc-350k-load": lambda: petsc_350k(SPHERE_350K_LOAD, "auto"),
           # the scale table's 1M nested run again, after its band columns stopped being kept whole
           "nested-1m": lambda: whole(SPHERE_1M, "nested", timeout=SCALE_TIMEOUT)}


def read() -> dict:
    return json.loads(JSON.read_text()) if JSON.exists() else {}


def write(data: dict) -> None:
    from signorini.files import atomic_write_text

    OUT.mkdir(parents=True, exist_ok=True)
    atomic_write_text(JSON, json.dumps(data, indent=1, sort_keys=True) + "\n")


def run(parts: list[str]) -> None:
    data = read()
    for part in parts:
        start = time.strftime("%Y-%m-%d %H:%M")
        data[part] = {"date": start, "commit": subprocess.run(
            ["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True,
            cwd=ROOT).stdout.strip(), **MEASURE[part]()}
        data["machine"] = machine()
        write(data)
        print(f"{part} done", flush=True)


# --- the report ---------------------------------------------------------------------------------

def whole_sentence(run: dict) -> str:
    record = run["record"]
    extras = record["extras"]
    hertz = record.get("hertz") or {}
    worst = max(v for v in record["kkt"].values() if v is not None)
    return (f"`{run['command']}`: {record['dofs']:,} dofs, {record['status']} with "
            f"{record['method']} ({extras.get('auto', '')}) in {run['wall_s']:.0f} s whole command "
            f"and {run['peak_gb']:.1f} GB peak (load average {run['load_before']:.1f} → "
            f"{run['load_after']:.1f}); every KKT residual ≤ {worst:.1e}; "
            + (f"{record['iterations']} active-set steps, {extras['cg_iterations']} CG iterations, "
               f"{extras['hierarchies']} hierarchy; " if "cg_iterations" in extras else
               f"{extras.get('band', 0)} candidates in the band; ")
            + f"assembly {record['time']['assemble_s']:.1f} s, method {extras['method_s']:.1f} s"
            + (f"; Hertz's p₀ within {100 * hertz['p0_rel']:.2f} %, a within "
               f"{100 * hertz['a_rel']:.2f} %" if hertz else ""))


def readme_paragraph(data: dict) -> str:
    """The block ``amg`` of docs/performance.md (tools/readme.py)."""
    lines = []
    if "whole-350k-load" in data:
        lines.append("- The scene's default (a target load): " + whole_sentence(data["whole-350k-load"])
                     + ".")
    if "whole-1m-load" in data and data["whole-1m-load"]["record"] is not None:
        lines.append("- The same at about 1M dofs: " + whole_sentence(data["whole-1m-load"]) + ".")
    if "whole-largest-load" in data and data["whole-largest-load"]["record"] is not None:
        from signorini.scenes import SCENES
        from signorini.scenes.size import bytes_per_dof, estimate_dofs
        from signorini.solvers.registry import get_method

        params = SCENES["hertz-sphere-3d"].parse(SPHERE_LARGEST_LOAD)
        dofs, dim = estimate_dofs("hertz-sphere-3d", params)
        need = dofs * bytes_per_dof(dim, dofs, params, get_method("auto"))
        machine_gb = data.get("machine", {}).get("memory_gb", float("nan"))
        lines.append(f"- The finest default the size guard lets through on this machine (refine=3: "
                     f"estimated {dofs / 1e6:.1f}M dofs and {need / 1e9:.1f} GB, the limit ¾ of "
                     f"{machine_gb:.1f} GB): " + whole_sentence(data["whole-largest-load"]) + ".")
    if "petsc-350k-load" in data:
        p = data["petsc-350k-load"]
        lines.append(f"- Its answer against `petsc-vi` (1 rank) on the same {p['dofs']:,}-dof "
                     f"problem in one process: λ within {p['lam_rel']:.1e} (relative), "
                     f"{p['misclassified']} nodes classified apart; method time "
                     f"{p['pdas-amg']['method_s']:.1f} s ({p['ours']}) against "
                     f"{p['petsc-vi']['method_s']:.0f} s (load {p['load_before']:.1f}).")
    if "whole-350k" in data:
        lines.append("- " + whole_sentence(data["whole-350k"]) + ".")
    if "whole-1m" in data and data["whole-1m"]["record"] is not None:
        lines.append("- " + whole_sentence(data["whole-1m"]) + ".")
    if "petsc-350k" in data:
        p = data["petsc-350k"]
        lines.append(f"- Against `petsc-vi` (1 rank) on the same {p['dofs']:,}-dof problem in one "
                     f"process: λ within {p['lam_rel']:.1e} (relative), {p['misclassified']} nodes "
                     f"classified apart; method time {p['pdas-amg']['method_s']:.0f} s against "
                     f"{p['petsc-vi']['method_s']:.0f} s (load {p['load_before']:.1f}).")
    return "\n".join(lines)


def _scale_cells(run: dict, one_s: float | None) -> list[str]:
    """status, whole command, method, method / one AMG solve, peak memory of one scale run."""
    record = run["record"]
    if record is None:  # refused before solving (exit 2), timed out, or killed
        said = run["said"].removeprefix("signorini: error: ")
        if run["returncode"] is None:
            status = f"timed out (limit {SCALE_TIMEOUT:.0f} s)"
        elif run["returncode"] in (137, -9):
            status = "killed by the kernel (out of memory)"
        else:
            status = f"refused: {said}" if said else f"exit {run['returncode']}, no answer"
        peak = "–" if run["peak_gb"] != run["peak_gb"] else f"{run['peak_gb']:.1f}"
        return [status, f"{run['wall_s']:.0f}", "–", "–", peak]
    method_s = record["extras"]["method_s"]
    ratio = f"{method_s / one_s:.1f}×" if one_s else "–"
    return [record["status"], f"{run['wall_s']:.0f}", f"{method_s:.1f}", ratio, f"{run['peak_gb']:.1f}"]


def scale_table(data: dict) -> str:
    """The block ``amg-scale`` of docs/performance.md: every size and method of part ``scale``."""
    part = data["scale"]
    lines = [f"`.venv/bin/python tools/amg_bench.py run --part scale` (commit {part['commit']}, "
             f"{part['date']}): `signorini solve hertz-sphere-3d` pushed by `delta=0.0025`, each run "
             "a process of its own under `/usr/bin/time -v`; *one AMG solve* is one GAMG set-up and "
             f"CG of K from zero to a relative residual of {AMG_RTOL:g} (the least an exact method "
             "without a factorisation spends); *method* is the method's own time (its set-up "
             "included, not the assembly or the certificate); memory is the largest process's peak.",
             "", "| dofs | method | status | whole command [s] | method [s] | method / one AMG solve "
             "| peak memory [GB] |", "|---:|---|---|---:|---:|---:|---:|"]
    for size in sorted(part["sizes"].values(), key=lambda size: size["params"].get("refine", 0)
                       * 100 + size["params"].get("n_contact", 0)):
        one = size["one_amg_solve"]
        one_s = one["setup_s"] + one["solve_s"] if one else None
        dofs = next((r["record"]["dofs"] for r in size["runs"].values() if r["record"]),
                    one["dofs"] if one else 0)
        lines.append(f"| {dofs:,} | one AMG solve ({one['iterations']} CG iterations) | – | "
                     f"{size['one_amg_process']['wall_s']:.0f} | {one_s:.1f} | 1× | "
                     f"{size['one_amg_process']['peak_gb']:.1f} |" if one else
                     f"| {dofs:,} | one AMG solve | failed | – | – | – | – |")
        for label, run in size["runs"].items():
            lines.append(f"| {dofs:,} | {label} | " + " | ".join(_scale_cells(run, one_s)) + " |")
    return "\n".join(lines)


def nested_again(data: dict) -> str:
    """The sentence on the 1M nested run measured again (part ``nested-1m``)."""
    run = data.get("nested-1m")
    if not run:
        return ""
    record = run["record"]
    status = record["status"] if record else _scale_cells(run, None)[0]
    extras = record.get("extras", {}) if record else {}
    from signorini.numerics.zone import COLUMN_BYTES

    dofs = f"{record['dofs']:,} dofs" if record else "1M dofs"
    return (f"`nested` at {dofs} measured again at commit {run['commit']} ({run['date']}), "
            f"after its band columns stopped being kept whole beyond {COLUMN_BYTES / 2 ** 20:.0f} MB "
            f"(`signorini.numerics.zone.COLUMN_BYTES`): {status} in {run['wall_s']:.0f} s whole "
            f"command and {run['peak_gb']:.1f} GB peak"
            + (f", a band of {extras['band']:,} nodes" if "band" in extras else "") + ".")


def markdown(data: dict) -> str:
    m = data.get("machine", {})
    out = ["# pdas-amg on hertz-sphere-3d", "",
           f"Generated by `tools/amg_bench.py md` from [bench.json](bench.json). Machine: "
           f"{m.get('cpu', '?')}, {m.get('cores', '?')} cores shared with other work, "
           f"{m.get('memory_gb', '?')} GB. One run each; timings are noisy (the load average is "
           "given with each): compare ratios within a row.", ""]
    if "backends" in data:
        b = data["backends"]
        out += ["## One multigrid set-up and one CG solve of K", "",
                f"The bound form of the {b['dofs']:,}-dof sphere ({b['bound_form_unknowns']:,} "
                f"unknowns, {b['nonzeros']:,} nonzeros, prescribed dofs pinned), CG from zero to a "
                f"relative residual of {b['rtol']:g} (commit {b['commit']}, {b['date']}).", "",
                "| multigrid | set-up (s) | CG (s) | iterations | s per iteration | load |",
                "|---|---:|---:|---:|---:|---:|"]
        for name, row in b["rows"].items():
            out.append(f"| {name} | {row['setup_s']:.1f} | {row['solve_s']:.1f} | "
                       f"{row['iterations']} | {row['solve_s'] / max(row['iterations'], 1):.3f} | "
                       f"{row['load_before']:.1f} |")
        out.append("")
    if "crossover" in data:
        out += ["## pdas against pdas-amg on small 3D models (method time, second run)", "",
                "| dofs | pdas (s) | pdas-amg (s) | load |", "|---:|---:|---:|---:|"]
        for row in data["crossover"]["rows"]:
            out.append(f"| {row['dofs']:,} | {row['pdas']['method_s']:.2f} | "
                       f"{row['pdas-amg']['method_s']:.2f} | {row['load_before']:.1f} |")
        out.append("")
    if "scale" in data:
        out += ["## Every method at ~50k, ~350k and ~1M dofs", "", scale_table(data), "",
                nested_again(data), ""]
    out += ["## The default command at scale", "", readme_paragraph(data), ""]
    if "backends" in data and "whole-350k" in data:
        gamg = data["backends"]["rows"].get("petsc GAMG (plain aggregation)")
        method = data["whole-350k"]["record"]["extras"]["method_s"]
        if gamg:
            one = gamg["setup_s"] + gamg["solve_s"]
            out += [f"The method alone at 350k dofs took {method / one:.1f}× one GAMG set-up and "
                    f"CG solve of K to 1e-10 ({method:.1f} s against {one:.1f} s, different runs "
                    "and loads).", ""]
    return "\n".join(out)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = parser.add_subparsers(dest="what", required=True)
    runner = sub.add_parser("run")
    runner.add_argument("--part", action="append", choices=PARTS)
    sub.add_parser("md")
    solver = sub.add_parser("amg-solve")
    solver.add_argument("params")
    args = parser.parse_args()
    if args.what == "amg-solve":
        print(json.dumps(one_amg_solve(json.loads(args.params))))
        return 0
    if args.what == "run":
        run(args.part or list(PARTS))
    from signorini.files import atomic_write_text

    atomic_write_text(OUT / "bench.md", markdown(read()))
    return 0


if __name__ == "__main__":
    sys.exit(main())
