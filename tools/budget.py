"""A large command against the one solve it cannot avoid, measured in the same run.

    .venv/bin/python tools/budget.py            # ~3 min here; writes docs/speed/budget.json
    .venv/bin/python tools/budget.py --3d       # also the 3D sphere at 350k and 10^6 dofs (~6 more min)
    .venv/bin/python tools/budget.py --parts 3d-1m   # one case's in-process parts, printed only

2D: the 10⁶-dof cylinder command in whole processes (``/usr/bin/time -v`` for the peak memory;
the fastest of ``--repeat``), with ``--method nested`` interleaved, and PARDISO's factorisation
and one solve of its K in a process of its own between them (the reference); then its parts in
one process (:func:`in_process`). Each stage of a command's record (its JSON ``time``) is held to
its budget: :data:`BUDGETS_2D`, shares of that factorisation; in 3D :data:`BUDGETS_3D`, shares of
the method's own time. 3D: the sphere's command at 350k and 10⁶ dofs, and at 10⁶ its parts in
one process with the one multigrid solve of K no method without a factorisation can avoid
(:func:`in_process_amg`).
docs/speed.md quotes the JSON (tests/test_readme_numbers.py holds it).
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import os
import platform
import re
import subprocess
import sys
import tempfile
import time
from datetime import datetime, timezone
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "docs" / "speed" / "budget.json"
CASES = {
    "2d": ("hertz-cylinder", {"refine": 3, "n_contact": 110, "grading": 0.1}),
    "3d": ("hertz-sphere-3d", {"refine": 2}),
    "3d-1m": ("hertz-sphere-3d", {"refine": 2, "n_contact": 24}),
}


#: what each stage of the 2D command may take, as a share of one PARDISO factorisation and solve
#: of its K: they sum to the goal, 1.5× it (``startup`` is the wall time outside the record's
#: stages: imports, parsing, exit)
BUDGETS_2D = {"startup": 0.07, "mesh": 0.10, "assemble": 0.10, "load_control": 1.10,
              "prediction": 0.0, "method": 0.03, "certificate": 0.05, "estimate": 0.04,
              "output": 0.01}
#: what each stage of the 3D command outside its method may take, as a share of the method's own
#: time: they sum to the goal, 0.30 of it
BUDGETS_3D = {"startup": 0.03, "mesh": 0.05, "assemble": 0.10, "load_control": 0.0,
              "prediction": 0.0, "certificate": 0.05, "estimate": 0.05, "output": 0.02}


def said(scene: str, params: dict, method: str | None = None) -> str:
    """The command as a user types it."""
    return " ".join(["signorini solve", scene, *(f"--set {k}={v}" for k, v in params.items()),
                     *(["--method", method] if method else [])])


def whole_process(scene: str, params: dict, method: str | None = None) -> dict:
    """One run of ``signorini solve`` in its own process: wall time, peak memory, its record."""
    with tempfile.TemporaryDirectory() as folder:
        record = Path(folder) / "result.json"
        argv = [sys.executable, "-m", "signorini.cli", "solve", scene, "--json", str(record)]
        for key, value in params.items():
            argv += ["--set", f"{key}={value}"]
        argv += ["--method", method] if method else []
        start = time.perf_counter()
        done = subprocess.run(["/usr/bin/time", "-v", *argv], capture_output=True, text=True,
                              cwd=ROOT)
        wall = time.perf_counter() - start
        if done.returncode != 0:
            raise SystemExit(f"{' '.join(argv)} failed:\n{done.stderr[-2000:]}")
        peak = re.search(r"Maximum resident set size \(kbytes\): (\d+)", done.stderr)
        result = json.loads(record.read_text())
    return {"command": said(scene, params, method), "wall_s": wall,
            "peak_gb": int(peak.group(1)) / 1e6 if peak else None, "status": result["status"],
            "dofs": result["dofs"], "time": result["time"], "hertz": result.get("hertz"),
            "method": result.get("method")}


def stages(command: dict) -> dict:
    """The command's stages in seconds from its record (``time``); ``startup`` is the record's
    (the interpreter, imports, parsing) and the wall time outside the record (writing, exit)."""
    time_ = command["time"]
    found = {key[:-2]: value for key, value in time_.items()
             if key.endswith("_s") and key[:-2] in BUDGETS_2D and key != "startup_s"}
    found["startup"] = time_.get("startup_s", 0.0) + command["wall_s"] - time_["total_s"]
    return found


def accounted(command: dict) -> str:
    """How much of the command's wall time its record's ``time`` accounts for."""
    return (f"{command['time']['total_s']:.1f} s in all, "
            f"{100 * command['time']['total_s'] / command['wall_s']:.0f} % of the wall time")


def stage_rows(command: dict, reference: float, budgets: dict, skip: tuple = ()) -> list[str]:
    """A table of the command's stages against their budgets (shares of ``reference`` s)."""
    rows = ["| stage (the command's record) | seconds | budget | within |", "|---|---:|---:|:---:|"]
    for stage, seconds in stages(command).items():
        if stage in skip or (seconds < 0.005 and not budgets.get(stage)):
            continue
        allowed = budgets.get(stage, 0.0) * reference
        rows.append(f"| {stage.replace('_', ' ')} | {seconds:.2f} | {allowed:.2f} | "
                    f"{'yes' if seconds <= allowed else '**no**'} |")
    return rows


def factorisation_process(scene: str, params: dict) -> dict:
    """PARDISO's factorisation and one solve of the command's K, timed in a process of its own
    (run between the commands: the same machine, the same moment)."""
    argv = [sys.executable, str(Path(__file__).resolve()), "--factor", scene, json.dumps(params)]
    done = subprocess.run(argv, capture_output=True, text=True, cwd=ROOT)
    if done.returncode != 0:
        raise SystemExit(f"{' '.join(argv)} failed:\n{done.stderr[-2000:]}")
    return json.loads(done.stdout.splitlines()[-1])


def factorised(scene: str, params: dict) -> dict:
    """The scene's K (built, not solved: the load does not change it) factorised by PARDISO with
    the package's settings and solved once, timed."""
    import numpy as np

    from signorini.cli.app import keep_freed_memory
    from signorini.scenes.build import build_problem

    keep_freed_memory()  # as the command's process does: the same allocator for both
    problem = build_problem(scene, params)
    K, f = problem.K, np.asarray(problem.f, dtype=float)
    del problem
    return pardiso_parts(K, f)


def pardiso_parts(K, f) -> dict:
    """``K`` factorised by PARDISO with the package's settings, then solved once for ``f``, timed."""
    from signorini.numerics.factor import PardisoFactor

    start = time.perf_counter()
    factor = PardisoFactor(K)
    parts = {"pardiso_factorise_s": time.perf_counter() - start}
    factor.solve(f)
    parts["pardiso_factorise_and_solve_s"] = time.perf_counter() - start
    return parts


def built_and_solved(scene: str, params: dict, solved_by: str | None = None, **options):
    """The first parts of a command in one process, timed: the model built (mesh and assembly),
    the whole solve through the API (built again, solved, judged) and its estimate; the parts
    and the result."""
    import signorini
    from signorini.scenes.build import build_problem
    from signorini.solvers.registry import get_method

    start = time.perf_counter()
    method = None if solved_by is None else get_method(solved_by)
    problem = build_problem(scene, params, solved_by=method)
    parts = {"dofs": problem.n, "build_s": time.perf_counter() - start}
    del problem
    start = time.perf_counter()
    result = signorini.solve(scene, params=params, **options)
    parts["solve_s"] = time.perf_counter() - start
    start = time.perf_counter()
    result.estimate
    parts["estimate_s"] = time.perf_counter() - start
    return parts, result


def in_process(scene: str, params: dict) -> dict:
    """The command's parts in one process: built, solved through the API, its estimate and
    certificate again, load control alone (work counted), K factorised by PARDISO, solved once."""
    import numpy as np

    import signorini
    from signorini import load_control
    from signorini.scenes.build import build_problem

    parts, result = built_and_solved(scene, params, keep_factor=True)
    start = time.perf_counter()  # a copy of the answer: the judged one keeps its certificate
    signorini.certificate(result.problem, dataclasses.replace(result.solution))
    parts["certificate_s"] = time.perf_counter() - start
    K, f = result.problem.K, np.asarray(result.problem.f, dtype=float)
    del result
    problem = build_problem(scene, params)
    start = time.perf_counter()
    matched = load_control.match(problem, load_control.predicted_zone(problem))
    parts.update(load_control_s=time.perf_counter() - start, load_control_work=matched.work)
    del matched, problem
    return {**parts, **pardiso_parts(K, f)}


def in_process_amg(scene: str, params: dict) -> dict:
    """The 3D command's parts in one process: the model built, the whole solve through the API
    (``pdas-amg``: its method time, steps, hierarchy set-up and CG iterations), the estimate,
    the certificate once more alone (its CG iterations with the method's multigrid), and one
    multigrid solve of K: K of the solved problem (at the push found) with the
    prescribed dofs and the answer's active set pinned, a GAMG hierarchy of it set up with
    the package's options (:class:`~signorini.solvers.amg_system.GamgHierarchy`), and CG
    (:func:`~signorini.numerics.multigrid.pinned_cg`, with the method's products by K) from the
    pinned values and zero elsewhere to the stationarity residual pdas-amg's final solve stops
    at (``SAFETY · tol ·`` the largest contact force, in the max norm)."""
    import numpy as np

    from signorini.numerics.multigrid import pinned_cg, pinned_matrix
    from signorini.solvers import amg, amg_system
    from signorini.solvers.bounds import bound_form
    from signorini.solvers.options import resolved

    import signorini

    parts, result = built_and_solved(scene, params, solved_by="auto",  # as the command builds it
                                     keep_factor=True)
    extras = result.solution.extras
    parts.update(method=result.method, status=result.status,
                 method_s=result.solution.seconds["method"], steps=result.iterations,
                 hierarchy_s=extras["hierarchy_s"], cg_iterations=extras["cg_iterations"])
    factor = result.solution.factor  # the method's multigrid CG on the active set (PinnedCG)
    iterations = getattr(factor, "iterations", 0)
    start = time.perf_counter()  # a copy of the answer: the judged one keeps its certificate
    signorini.certificate(result.problem, dataclasses.replace(result.solution))
    parts["certificate_s"] = time.perf_counter() - start
    parts["certificate_cg_iterations"] = getattr(factor, "iterations", 0) - iterations
    problem, lam = result.problem, result.solution.lam
    del result, factor
    system = amg_system.PinnedSystem(bound_form(problem))
    active = lam > 0
    x = np.zeros(system.form.n)
    free = system.pin(active, problem.d, x)
    force = max(float(np.max(np.abs(lam * system.coef), initial=0.0)),
                1e-5 * float(np.max(np.abs(problem.f), initial=0.0)))
    target = amg.SAFETY * resolved("pdas-amg", "active set", None, None)[0] * force
    start = time.perf_counter()
    pinned, modes = pinned_matrix(system.K, ~free), system.form.rigid_modes()
    parts["amg_pin_s"] = time.perf_counter() - start  # the pinned matrix and the rigid modes
    hierarchy = amg_system.GamgHierarchy(pinned, modes, system.form.block)
    parts["amg_setup_s"] = hierarchy.setup_s  # as the method's hierarchy_s: GAMG's set-up
    del pinned
    start = time.perf_counter()
    solved = pinned_cg(system.product, system.f, x, free, hierarchy.apply,  # the method's product
                       lambda r2, rinf, r0: rinf <= target, amg.CG_MAX_ITER)
    parts["amg_solve_s"] = time.perf_counter() - start
    parts.update(amg_cg_iterations=solved.iterations, amg_levels=hierarchy.levels[0],
                 amg_reduction=solved.final / solved.initial,
                 amg_pinned="the prescribed dofs and the answer's active set")
    return parts


def load() -> dict:
    return json.loads(OUT.read_text())


def table(record: dict) -> str:
    """docs/performance.md's block: the 2D command against one factorisation, and its parts."""
    two = record["2d"]
    command, parts = two["command"], two["in_process"]
    wall, once = command["wall_s"], two["factorisation"]["pardiso_factorise_and_solve_s"]
    lines = [f"`{command['command']}` ({command['dofs']:,} dofs, {command['status']}), fastest of "
             f"{record['repeat']} whole processes: **{wall:.1f} s**, {command['peak_gb']:.2f} GB peak; "
             f"PARDISO's factorisation and one solve of the same K, each in a process of its own "
             f"between the commands, fastest of {record['repeat']}: **{once:.1f} s**, so the "
             f"command is **{wall / once:.2f}×** one factorisation.", "",
             *part_rows(parts, wall, (
                 (BUILT, "build_s"), (SOLVED, "solve_s"),
                 ("the certificate, once more alone (the method's factorisation)",
                  "certificate_s"),
                 ("the error estimate", "estimate_s"),
                 *((("load control alone: K factorised around the predicted zone, the push found",
                     "load_control_s"),) if "load_control_s" in parts else ()),
                 ("PARDISO: factorise K", "pardiso_factorise_s"),
                 ("PARDISO: factorise K and solve once", "pardiso_factorise_and_solve_s"))),
             "", f"Each stage of the command's own record (its JSON `time`: {accounted(command)}; "
                 f"*startup* is its `startup_s`, the interpreter, imports and parsing, and the wall "
                 f"time after the record: writing, exit) against its budget, a share of that "
                 f"factorisation (`tools/budget.py`'s `BUDGETS_2D`, summing to 1.5×):", "",
             *stage_rows(command, once, BUDGETS_2D)]
    if "2d-nested" in record:
        nested = record["2d-nested"]["command"]
        lines += ["", f"`{nested['command']}`: **{nested['wall_s']:.1f} s**, "
                      f"{nested['peak_gb']:.2f} GB peak, so **{nested['wall_s'] / wall:.2f}×** the "
                      f"default's time and **{nested['peak_gb'] / command['peak_gb']:.2f}×** its "
                      "memory."]
    for case in ("3d", "3d-1m"):
        if case in record:
            three = record[case]["command"]
            lines += ["", f"3D, `{three['command']}` ({three['dofs']:,} dofs, {three['status']}): "
                          f"**{three['wall_s']:.1f} s** whole process, {three['peak_gb']:.2f} GB peak."]
            method = three["time"].get("method_s")
            if method:
                outside = three["wall_s"] - method
                lines += ["", f"Outside its method (`{three.get('method') or 'pdas-amg'}`, "
                              f"{method:.1f} s in the command's record of {accounted(three)}): "
                              f"**{outside:.1f} s**, "
                              f"**{100 * outside / method:.0f} %** of the method's time (goal "
                              f"≤ 30 %); each stage against its budget, a share of the method's "
                              f"time (`BUDGETS_3D`):", "",
                          *stage_rows(three, method, BUDGETS_3D, skip=("method",))]
            if "in_process" in record[case]:
                lines += ["", *amg_lines(three["wall_s"], record[case]["in_process"])]
    machine = record["machine"]
    load = record.get("load_average")
    lines += ["", f"Measured {record['date'][:10]} on {machine['cores']} cores "
                  f"({machine['processor']}, Python {machine['python']}) by `tools/budget.py`"
                  + (f", load average {load[0]:.1f} at the start and {load[1]:.1f} at the end "
                     "(a shared machine: ratios within the run are what compare)" if load else "")
                  + "; the run is `docs/speed/budget.json`."]
    return "\n".join(lines)


def amg_lines(wall: float, parts: dict) -> list[str]:
    """The 3D command's parts against one multigrid solve of its K (see :func:`in_process_amg`)."""
    once = parts["amg_pin_s"] + parts["amg_setup_s"] + parts["amg_solve_s"]
    lines = [f"One multigrid solve of the same K ({parts['amg_pinned']} pinned), in the same "
             f"run: pinning {parts['amg_pin_s']:.1f} s, GAMG set-up {parts['amg_setup_s']:.1f} s and CG "
             f"{parts['amg_solve_s']:.1f} s ({parts['amg_cg_iterations']} iterations), "
             f"**{once:.1f} s**; `{parts['method']}` took {parts['method_s']:.1f} s "
             f"({parts['steps']} steps, {parts['cg_iterations']} CG iterations, its hierarchy "
             f"{parts['hierarchy_s']:.1f} s), **{parts['method_s'] / once:.2f}×** it.", ""]
    return lines + part_rows(parts, wall, (
        (BUILT, "build_s"), (SOLVED, "solve_s"),
        (f"`{parts['method']}` alone (within the solve)", "method_s"),
        *(((f"the certificate, once more alone ({parts['certificate_cg_iterations']} CG "
            "iterations of the method's multigrid)", "certificate_s"),)
          if "certificate_s" in parts else ()),
        ("the error estimate", "estimate_s"),
        ("K pinned, and its rigid-body modes", "amg_pin_s"),
        ("GAMG: set up the hierarchy of K", "amg_setup_s"),
        ("GAMG: CG to pdas-amg's final tolerance", "amg_solve_s")))


BUILT = "the model built: meshing and assembly"
SOLVED = "`signorini.solve`: built again, load matched, solved, judged"


def part_rows(parts: dict, wall: float, rows) -> list[str]:
    """A table of the parts ``rows`` ((label, key) pairs) in seconds and as shares of ``wall``."""
    return ["| part (in one process, after the command) | seconds | of the command |",
            "|---|---:|---:|",
            *(f"| {label} | {parts[key]:.2f} | {100 * parts[key] / wall:.0f} % |"
              for label, key in rows)]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=2)
    parser.add_argument("--3d", dest="three", action="store_true")
    parser.add_argument("--repeat-3d", type=int, help="whole processes per 3D case (default: "
                        "--repeat)")
    parser.add_argument("--factor", nargs=2, metavar=("SCENE", "PARAMS"),
                        help=argparse.SUPPRESS)  # one factorisation_process, its JSON printed
    parser.add_argument("--parts", choices=["3d-1m"], help="only this case's in-process parts, "
                        "printed (budget.json is not written)")
    args = parser.parse_args()
    if args.factor:
        print(json.dumps(factorised(args.factor[0], json.loads(args.factor[1]))))
        return
    if args.parts:
        print(json.dumps(in_process_amg(*CASES[args.parts]), indent=1))
        return
    out = {"machine": {"system": platform.platform(), "python": platform.python_version(),
                       "processor": platform.processor() or platform.machine(),
                       "cores": os.cpu_count()},
           "date": datetime.now(timezone.utc).isoformat(timespec="seconds"),
           "repeat": args.repeat, "repeat_3d": args.repeat_3d or args.repeat}
    start_load = os.getloadavg()[0]
    scene, params = CASES["2d"]
    runs, nested, factors = [], [], []
    for _ in range(args.repeat):  # interleaved: the routes and the reference see the same machine
        runs.append(whole_process(scene, params))
        factors.append(factorisation_process(scene, params))
        nested.append(whole_process(scene, params, "nested"))
    out["2d"] = {"command": min(runs, key=lambda r: r["wall_s"]),
                 "walls_s": [r["wall_s"] for r in runs],
                 "factorisation": min(factors, key=lambda r: r["pardiso_factorise_and_solve_s"]),
                 "factorisations_s": [r["pardiso_factorise_and_solve_s"] for r in factors],
                 "in_process": in_process(scene, params)}
    out["2d-nested"] = {"command": min(nested, key=lambda r: r["wall_s"]),
                        "walls_s": [r["wall_s"] for r in nested]}
    OUT.write_text(json.dumps(out, indent=1) + "\n")  # kept case by case: a later one may fail
    for case in ("3d", "3d-1m") if args.three else ():
        scene, params = CASES[case]
        runs = [whole_process(scene, params) for _ in range(args.repeat_3d or args.repeat)]
        out[case] = {"command": min(runs, key=lambda r: r["wall_s"]),
                     "walls_s": [r["wall_s"] for r in runs]}
        OUT.write_text(json.dumps(out, indent=1) + "\n")
        if case == "3d-1m":
            try:
                out[case]["in_process"] = in_process_amg(scene, params)
            except Exception as exc:  # noqa: BLE001 - the whole processes above are kept
                out[case]["in_process_error"] = f"{type(exc).__name__}: {exc}"
    out["load_average"] = [start_load, os.getloadavg()[0]]
    OUT.write_text(json.dumps(out, indent=1) + "\n")
    two = out["2d"]
    once = two["factorisation"]["pardiso_factorise_and_solve_s"]
    print(f"2D: {two['command']['wall_s']:.1f} s whole process, PARDISO's factorisation and solve "
          f"{once:.1f} s: {two['command']['wall_s'] / once:.2f}x")


if __name__ == "__main__":
    main()
