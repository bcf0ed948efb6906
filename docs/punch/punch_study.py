"""What the punch's edge singularity does to each method (the numbers and figures of docs/punch.md).

Run from the repository root:  .venv/bin/python docs/punch/punch_study.py
Writes docs/punch/results.json, methods.md and the figures next to this file.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from signorini.output.plots import plot_punch_edge, plot_punch_pressure
from signorini.files import atomic_write_text, save_figure, to_json
from signorini.references.pressure import compare_punch
from signorini.scenes import build_problem
from signorini.solvers.registry import get_method, methods
from signorini.studies.suite import TIGHT_TOL, run_one

HERE = Path(__file__).resolve().parent
SIZES = (32, 64, 128, 256)
#: the sharp punch, a punch with rounded corners (r = 0.1a) and, for comparison, a smooth
#: contact with about as many active nodes: the block on a rigid cylinder
CASES = (("punch", {}), ("punch", {"corner_radius": 0.1}), ("reverse-hertz", {}))


def per_node_errors(problem, reference, solution):
    """Relative λ error at the edge of the contact (the outermost loaded node) and elsewhere."""
    lam_ref, lam = reference.lam, solution.lam
    loaded = np.nonzero(lam_ref > 0)[0]
    edge = int(loaded[np.argmax(problem.contact_points[loaded, 0])])
    rel = np.abs(lam - lam_ref) / np.abs(lam_ref).max()
    others = np.delete(rel, edge)
    return float(rel[edge]), float(others.max())


def main() -> int:
    chosen = [m for m in methods(installed_only=True) if m.family != "user"]
    rows = []
    for scene, extra in CASES:
        for n in SIZES:
            problem = build_problem(scene, params={"n_contact": n, **extra})
            _, reference = run_one(problem, get_method("pdas"), TIGHT_TOL, None)
            for method in chosen:
                row, solution = run_one(problem, method, TIGHT_TOL, reference)
                row.update(scene=scene + "".join(f" {k}={v}" for k, v in extra.items()), n_contact=n, dofs=problem.n, candidates=problem.m,
                           active=int(np.sum(reference.lam > 0)))
                if solution is not None and np.all(np.isfinite(solution.lam)):
                    row["edge_rel"], row["interior_rel"] = per_node_errors(problem, reference, solution)
                rows.append(row)
                print(f"{row['scene']} n={n} {method.name:<15} {row['status']:<10} "
                      f"it {row.get('iterations', '-')!s:>6} {row.get('time_s', 0):6.2f} s", file=sys.stderr)
            if scene == "punch" and not extra and n == 128:
                ax = plot_punch_pressure(problem, reference)
                ax.set_title(f"punch (sharp corners), {problem.n} dofs: pressure against the half-plane",
                             fontsize=9)
                save_figure(ax.figure, HERE / "punch-pressure.png")
                ax = plot_punch_edge(problem, reference)
                ax.set_title("near the edge: p ∝ (a − x)^(−1/2), the nodes stop at the last element",
                             fontsize=9)
                save_figure(ax.figure, HERE / "punch-edge.png")
                comparison = compare_punch(problem, reference).as_dict()
    atomic_write_text(HERE / "results.json", to_json({"rows": rows, "punch_128": comparison}))
    lines = ["| scene | n_contact | active | method | status | iterations | time [s] | λ vs pdas | "
             "edge node | other nodes |", "|---|---:|---:|---|---|---:|---:|---:|---:|---:|"]
    for r in rows:
        if r["status"] == "skipped":
            continue
        vs = r.get("vs_reference", {})
        lines.append(f"| {r['scene']} | {r['n_contact']} | {r['active']} | {r['method']} | {r['status']} | "
                     f"{r.get('iterations', '')} | {r.get('time_s', 0):.2f} | {vs.get('lam_rel', float('nan')):.1e} | "
                     f"{r.get('edge_rel', float('nan')):.1e} | {r.get('interior_rel', float('nan')):.1e} |")
    atomic_write_text(HERE / "methods.md", "\n".join(lines) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
