"""Effectivity of the a posteriori estimate (signorini.fem.estimate) on the Hertz scenes, and
what adaptive refinement (signorini.scenes.adapt) reaches against uniform and hand-graded meshes.

    .venv/bin/python tools/estimate.py [effectivity] [adaptive]   # both: ~6 min here;
                                                                  # writes docs/estimate/runs.json

For each scene and base mesh, the scene is solved at ``refine`` = 0, 1, ...
(uniform refinements of the graded mesh) and at two more levels. The true
error of level L is measured against the solution at level L + 2 (and, for a
check on the reference's own error, against the finest one): the coarse P1
field is carried onto the finer mesh node by node (every new node is the
midpoint of an old edge, :mod:`signorini.fem.transfer`; nodes moved onto the
arc keep that average) and ``‖u_ref − u_h‖_E`` is summed element by element
on the finer mesh. Every solve is ``pdas`` at tol 1e-10 through the public API
(``nested``, exact too, from refine 2). docs/estimate.md quotes the tables
``tables`` renders from the JSON (tools/readme.py writes them there;
tests/test_readme_numbers.py holds them).
"""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path

import numpy as np

import signorini
from signorini.fem.estimate import element_energies, estimate, material_units
from signorini.fem.transfer import uniform_prolongation
from signorini.files import atomic_write_text, to_json
from signorini.references import reference_of
from signorini.scenes.adapt import solve_adaptive

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "docs" / "estimate" / "runs.json"
SCENES = ("hertz-cylinder", "hertz-sphere")
#: (n_contact, grading, levels): a coarse base with three levels, each scene's default mesh with two
BASES = ((16, 0.2, 3), (None, None, 2))
REFERENCE_STEPS = 2
#: the adaptive runs: targets (relative, energy norm), the dof limit, and what they are held against
TARGETS = (0.003, 0.001)
MAX_DOFS = 250_000
UNIFORM_LEVELS = 3
HAND_GRADED = ((40, 0.1), (60, 0.05), (120, 0.05))


def solve(scene: str, n_contact: int | None, grading: float | None, refine: int):
    """The scene at ``refine`` (mesh parameters None: the scene's defaults), exactly; and the time."""
    method = "nested" if refine >= 2 else "pdas"
    mesh = {"n_contact": n_contact, "grading": grading}
    start = time.perf_counter()
    result = signorini.solve(scene, method=method, tol=1e-10,
                             params={**{k: v for k, v in mesh.items() if v is not None},
                                     "refine": refine})
    seconds = time.perf_counter() - start
    if result.status != "converged":
        raise RuntimeError(f"{scene} refine={refine}: {result.status} ({result.message})")
    return result, seconds


def nodal(result) -> np.ndarray:
    """The displacement of every node (nodes, dim) in physical units."""
    dim = result.problem.mesh.p.shape[0]
    return result.displacement.reshape(-1, dim)


def true_error(coarse, fine, steps: int) -> tuple[float, float]:
    """``‖u_fine − P u_coarse‖_E`` (physical) and the fine solution's λᵀ·gap(P u_coarse) term."""
    cp, fp = coarse.problem, fine.problem
    P = uniform_prolongation(cp.mesh.t, cp.mesh.p.shape[1], steps)
    moved = P @ nodal(coarse)
    E, nu = material_units(fp)
    s = fp.scales
    error = (nodal(fine) - moved) / s.displacement
    energy = element_energies(fp.mesh, error, E, nu, fp.axisymmetric).sum() * s.force * s.displacement
    v = (moved.ravel() / s.displacement)[fp.free_dofs]
    term = float(fine.solution.lam @ fp.gap(v)) * s.force * s.displacement
    return float(np.sqrt(energy)), term


def run() -> list[dict]:
    rows = []
    for scene in SCENES:
        for n_contact, grading, levels in BASES:
            results = {}
            for refine in range(levels + REFERENCE_STEPS):
                results[refine] = solve(scene, n_contact, grading, refine)
                print(f"{scene} ({n_contact}, {grading}) refine {refine}: "
                      f"{results[refine][0].problem.n} dofs, {results[refine][1]:.1f} s", file=sys.stderr)
            finest = levels + REFERENCE_STEPS - 1
            for refine in range(levels):
                result, seconds = results[refine]
                start = time.perf_counter()
                found = estimate(result.problem, result.solution)
                estimate_s = time.perf_counter() - start
                recovery_only = estimate(result.problem, result.solution, contact=False)
                error, term = true_error(result, results[refine + REFERENCE_STEPS][0], REFERENCE_STEPS)
                error_finest, _ = true_error(result, results[finest][0], finest - refine)
                hertz = result.hertz
                rows.append({
                    "scene": scene, "n_contact": result.problem.params["n_contact"],
                    "grading": result.problem.params["grading"], "refine": refine,
                    "dofs": result.problem.n, "estimate": found.total, "relative": found.relative,
                    "recovery": found.recovery * found.scale, "contact": found.contact * found.scale,
                    "energy_norm": found.energy_norm * found.scale,
                    "error": error, "error_finest": error_finest, "finest": finest,
                    "effectivity": found.total / error,
                    "effectivity_recovery": recovery_only.total / error,
                    "effectivity_finest": found.total / error_finest,
                    "complementarity": term,
                    "p0_err": hertz.p0 / hertz.p0_ref - 1, "a_err": hertz.a / hertz.a_ref - 1,
                    "estimate_s": estimate_s, "solve_s": seconds})
                print(f"  level {refine}: η/‖e‖ = {rows[-1]['effectivity']:.3f}", file=sys.stderr)
    return rows


def _pct(x: float, digits: int = 3) -> str:
    return f"{100 * x:+.{digits}f} %"


def tables(rows: list[dict], adaptive: list[dict] | None = None) -> dict[str, str]:
    """Markdown tables by name: effectivity per level, and η against the Hertz errors."""
    lines = ["| scene | mesh (n_contact, grading) | refine | dofs | η / ‖u_h‖ | ‖e‖ / ‖u_h‖ "
             "| η / ‖e‖ | recovery part alone | η / ‖e‖ against the finest | contact share of η² |",
             "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        finer = r["finest"] > r["refine"] + REFERENCE_STEPS
        lines.append(
            f"| {r['scene']} | {r['n_contact']}, {r['grading']:g} | {r['refine']} | {r['dofs']:,} "
            f"| {100 * r['relative']:.2f} % | {100 * r['error'] / r['energy_norm']:.2f} % "
            f"| {r['effectivity']:.3f} | {r['effectivity_recovery']:.3f} "
            + (f"| {r['effectivity_finest']:.3f} (refine {r['finest']}) " if finer else "| — ")
            + f"| {100 * (r['contact'] / r['estimate']) ** 2:.2f} % |")
    out = {"effectivity": "\n".join(lines)}
    lines = ["| scene | mesh | refine | dofs | η / ‖u_h‖ | a | p₀ | 2λ_refᵀg(u_h) / ‖e‖² "
             "| estimate | solve |",
             "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        lines.append(
            f"| {r['scene']} | {r['n_contact']}, {r['grading']:g} | {r['refine']} | {r['dofs']:,} "
            f"| {100 * r['relative']:.2f} % | {_pct(r['a_err'])} | {_pct(r['p0_err'])} "
            f"| {2 * r['complementarity'] / r['error'] ** 2:+.3f} "
            f"| {1e3 * r['estimate_s']:.0f} ms | {r['solve_s']:.2f} s |")
    out["estimate-hertz"] = "\n".join(lines)
    if adaptive:
        out["adaptive"] = adaptive_table(adaptive)
    return out


def _hertz_row(problem, solution, found, **fields) -> dict:
    hertz = reference_of(problem).compare(problem, solution)
    return {**fields, "dofs": problem.n, "relative": found.relative,
            "p0_err": hertz.p0 / hertz.p0_ref - 1, "a_err": hertz.a / hertz.a_ref - 1}


def run_adaptive() -> list[dict]:
    """Every step of one adaptive run per scene (to the smaller target), uniform and hand-graded."""
    rows = []
    for scene in SCENES:
        start = time.perf_counter()

        def step(problem, solution, found, scene=scene, start=start):
            rows.append(_hertz_row(problem, solution, found, scene=scene, mesh="adaptive",
                                   seconds=time.perf_counter() - start))
            print(f"{scene} adaptive: {problem.n} dofs, η {100 * found.relative:.2f} %",
                  file=sys.stderr)

        run = solve_adaptive(scene, {}, min(TARGETS), tol=1e-10, max_dofs=MAX_DOFS, on_step=step)
        rows[-1]["reason"] = run.reason
        for refine in range(UNIFORM_LEVELS + 1):
            result, seconds = solve(scene, None, None, refine)
            rows.append(_hertz_row(result.problem, result.solution, result.estimate, scene=scene,
                                   mesh=f"uniform, refine {refine}", seconds=seconds))
        for n_contact, grading in HAND_GRADED:
            result, seconds = solve(scene, n_contact, grading, 0)
            rows.append(_hertz_row(result.problem, result.solution, result.estimate, scene=scene,
                                   mesh=f"graded ({n_contact}, {grading:g})", seconds=seconds))
    return rows


def adaptive_table(rows: list[dict]) -> str:
    lines = ["| scene | mesh | dofs | η / ‖u_h‖ | a | p₀ | time |", "|---|---|---:|---:|---:|---:|---:|"]
    for r in rows:
        label = r["mesh"] if r["mesh"] != "adaptive" else "adaptive, step"
        lines.append(f"| {r['scene']} | {label} | {r['dofs']:,} | {100 * r['relative']:.2f} % "
                     f"| {_pct(r['a_err'])} | {_pct(r['p0_err'])} | {r['seconds']:.1f} s |")
    return "\n".join(lines)


def load(part: str = "rows") -> list[dict]:
    return json.loads(OUT.read_text()).get(part, [])


if __name__ == "__main__":
    parts = sys.argv[1:] or ["effectivity", "adaptive"]
    record = json.loads(OUT.read_text()) if OUT.exists() else {}
    record["command"] = "python tools/estimate.py " + " ".join(parts)
    if "effectivity" in parts:
        record["rows"] = run()
    if "adaptive" in parts:
        record["adaptive"] = run_adaptive()
    atomic_write_text(OUT, to_json(record))
    print(f"written: {OUT}", file=sys.stderr)
