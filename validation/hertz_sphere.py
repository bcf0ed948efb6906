"""Hertz's sphere modelled twice: axisymmetric in (r, z) and as a 3D quarter, side by side.

A sphere pressed on a flat along its axis is axisymmetric, so the meridian
half-plane carries the whole problem (scene ``hertz-sphere``); the 3D model
of one quarter with two symmetry planes (``hertz-sphere-3d``) solves the same
problem without using that symmetry. Both are held against Hertz (Johnson
1985, §4.2: ``a = (3PR/(4E*))^(1/3)``, ``p₀ = 3P/(2πa²)``) and against each
other, and the script reports what each costs: dofs, time and memory.

Importing this module solves both default models in-process with the exact
``pdas`` and the paper's ``uzawa`` (the tests pin those numbers). Running it
(``.venv/bin/python validation/hertz_sphere.py``) also measures every model of
:data:`SWEEP` in a fresh interpreter of its own, so that each one's peak
memory (the growth of the process's peak resident set, ``getrusage``, over
its resident set after the imports, read from ``/proc/self/status``: NumPy
arrays and the sparse factors alike, which ``tracemalloc`` does not see) is
its own, and prints the side-by-side table of ``docs/spheres.md``. Linux only.
"""

from __future__ import annotations

import json
import subprocess
import sys
import time
from typing import Any

import signorini
from signorini.certification.comparison import compare
from signorini.references.pressure import compare_hertz_sphere, symmetry_plane_profiles
from signorini.scenes import build_problem
from signorini.solvers.registry import solve

#: the body and the load, in SI units: a steel sphere of radius 10 mm at a/R = 0.05
PARAMS = {"a_over_R": 0.05, "E": 2.1e11, "nu": 0.3, "R": 0.01}
AXISYMMETRIC, THREE_D = "hertz-sphere", "hertz-sphere-3d"

#: models measured by ``__main__``: (label, scene, mesh parameters), coarse to fine
SWEEP = (
    ("axisymmetric", AXISYMMETRIC, {"n_contact": 20}),
    ("axisymmetric", AXISYMMETRIC, {"n_contact": 40}),
    ("axisymmetric", AXISYMMETRIC, {"n_contact": 60}),
    ("axisymmetric (default)", AXISYMMETRIC, {"n_contact": 100}),
    ("3D quarter", THREE_D, {"n_contact": 6}),
    ("3D quarter", THREE_D, {"n_contact": 8}),
    ("3D quarter (default)", THREE_D, {"n_contact": 10}),
    ("3D quarter", THREE_D, {"n_contact": 16}),
)


def _timed_solve(scene: str, mesh: dict[str, Any]):
    start = time.perf_counter()
    problem = signorini.at_load(build_problem(scene, params={**PARAMS, **mesh}))
    built = time.perf_counter()
    solution = solve(problem, "pdas", tol=1e-9)
    return problem, solution, built - start, time.perf_counter() - built


axisymmetric, exact_axisymmetric, assemble_axisymmetric_s, solve_axisymmetric_s = \
    _timed_solve(AXISYMMETRIC, {})
three_d, exact_three_d, assemble_three_d_s, solve_three_d_s = _timed_solve(THREE_D, {})
hertz_axisymmetric = compare_hertz_sphere(axisymmetric, exact_axisymmetric)
hertz_three_d = compare_hertz_sphere(three_d, exact_three_d)
uzawa_axisymmetric = solve(axisymmetric, "uzawa", tol=1e-9)
uzawa_three_d = solve(three_d, "uzawa", tol=1e-9)
agreement_axisymmetric = compare(axisymmetric, exact_axisymmetric, uzawa_axisymmetric)
agreement_three_d = compare(three_d, exact_three_d, uzawa_three_d)
plane_profiles = symmetry_plane_profiles(three_d, exact_three_d)

#: run in a fresh interpreter by :func:`measure`: one model, its cost and its errors as JSON
_MEASURE_ONE = """
import json, sys, time
from signorini.references.pressure import compare_hertz_sphere
import signorini
from signorini.scenes import build_problem
from signorini.solvers.registry import solve, methods

def kilobytes(field):
    with open("/proc/self/status") as status:
        return next(int(line.split()[1]) for line in status if line.startswith(field + ":"))

scene, params = sys.argv[1], json.loads(sys.argv[2])
methods()  # import every backend now, so that their memory is in the baseline
with open("/proc/self/clear_refs", "w") as clear:
    clear.write("5")  # reset the peak resident set (VmHWM) to the current one
baseline_kb = kilobytes("VmRSS")
start = time.perf_counter()
problem = signorini.at_load(build_problem(scene, params=params))
built = time.perf_counter()
solution = solve(problem, "pdas", tol=1e-9)
done = time.perf_counter()
peak_kb = kilobytes("VmHWM")
hertz = compare_hertz_sphere(problem, solution)
print(json.dumps({"dofs": problem.n, "candidates": problem.m, "status": solution.status,
                  "assemble_s": built - start, "solve_s": done - built,
                  "peak_mb": (peak_kb - baseline_kb) / 1024, "hertz": hertz.as_dict()}))
"""


def measure(scene: str, mesh: dict[str, Any] | None = None) -> dict[str, Any]:
    """Build and solve one model (pdas) in a fresh interpreter and return its cost and errors.

    ``assemble_s`` covers meshing, assembly and the load targeting, ``solve_s``
    the exact solve; ``peak_mb`` is the growth of the child's peak resident
    set (Linux's ``VmHWM``, reset after the imports) over its resident set
    after importing the package and every backend. ``getrusage``'s
    ``ru_maxrss`` would not do: a child inherits its parent's.
    """
    arguments = json.dumps({**PARAMS, **(mesh or {})})
    result = subprocess.run([sys.executable, "-c", _MEASURE_ONE, scene, arguments],
                            capture_output=True, text=True, check=True)
    return json.loads(result.stdout.strip().splitlines()[-1])


def table(rows: list[tuple[str, str, dict[str, Any], dict[str, Any]]]) -> str:
    """The side-by-side Markdown table of measured models."""
    lines = ["| model | mesh | dofs | candidates | p₀ error | a error | pressure L2 error "
             "| assemble [s] | solve [s] | total [s] | peak memory [MB] |",
             "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for label, _, mesh, m in rows:
        h = m["hertz"]
        fineness = ", ".join(f"{k}={v}" for k, v in mesh.items()) or "defaults"
        lines.append(
            f"| {label} | {fineness} | {m['dofs']:,} | {m['candidates']} | "
            f"{100 * (h['p0'] / h['p0_ref'] - 1):+.2f} % | {100 * (h['a'] / h['a_ref'] - 1):+.2f} % | "
            f"{100 * h['pressure_l2_rel']:.2f} % | {m['assemble_s']:.2f} | {m['solve_s']:.2f} | "
            f"{m['assemble_s'] + m['solve_s']:.2f} | {m['peak_mb']:.0f} |")
    return "\n".join(lines)


if __name__ == "__main__":
    for name, problem, h, uzawa, agreement in (
            ("axisymmetric", axisymmetric, hertz_axisymmetric, uzawa_axisymmetric,
             agreement_axisymmetric),
            ("3D quarter", three_d, hertz_three_d, uzawa_three_d, agreement_three_d)):
        print(f"{name}: {problem.n} dofs, {problem.m} contact candidates")
        print(f"  a  = {h.a:.6e} m   (Hertz {h.a_ref:.6e}, {100 * h.a_rel:.2f} %)")
        print(f"  p0 = {h.p0:.6e} Pa  (Hertz {h.p0_ref:.6e}, {100 * h.p0_rel:.2f} %)")
        print(f"  pressure L2 error {100 * h.pressure_l2_rel:.2f} %, force balance {h.force_balance:.1e}")
        print(f"  uzawa ({uzawa.status}, {uzawa.iterations} iterations) vs pdas: "
              f"λ {agreement.lam_rel:.1e}, {agreement.misclassified} nodes misclassified")
    print(f"3D vs axisymmetric: a {100 * abs(hertz_three_d.a / hertz_axisymmetric.a - 1):.2f} %, "
          f"p0 {100 * abs(hertz_three_d.p0 / hertz_axisymmetric.p0 - 1):.2f} %")
    print("\neach model in a fresh interpreter (pdas, tol 1e-9):", flush=True)
    measured = [(label, scene, mesh, measure(scene, mesh)) for label, scene, mesh in SWEEP]
    print(table(measured))
