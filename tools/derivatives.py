"""The cost of a derivative against the solve, and the discrete contact width against the fitted a.

    python tools/derivatives.py [--refine 2 3] [--out docs/derivatives]

Writes ``cost.json`` (per mesh: dofs, solve and derivative seconds and work) and
``width.json`` + ``width.png`` (the cylinder's discrete width and fitted a against P).
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import signorini  # noqa: E402
from signorini.loading import counters, spent  # noqa: E402

FINE = {"n_contact": 110, "grading": 0.1}


def cost(refine: int) -> dict:
    problem = signorini.build_problem("hertz-cylinder", params={"refine": refine, **FINE})
    start, before = time.perf_counter(), counters()
    result = signorini.solve(problem)
    solve_s, solve_work = time.perf_counter() - start, spent(before)
    start, before = time.perf_counter(), counters()
    first = signorini.derivative(result, "total_force", "P")
    first_s, first_work = time.perf_counter() - start, spent(before)
    start, before = time.perf_counter(), counters()
    again = signorini.derivative(result, "a", "P")
    again_s, again_work = time.perf_counter() - start, spent(before)
    return {"refine": refine, "dofs": problem.n, "method": result.method, "solve_s": solve_s,
            "solve_work": solve_work, "first_derivative_s": first_s, "first_work": first_work,
            "next_derivative_s": again_s, "next_work": again_work,
            "d_total_force_dP": first.derivative, "d_ln_a_d_ln_P":
            again.derivative * result.total_force / again.value}


def widths(count: int = 41) -> dict:
    base = signorini.solve("hertz-cylinder")
    problem, push = base.problem, base.problem.push
    rows = []
    for ratio in np.linspace(0.8, 1.25, count):
        moved = problem.with_data(discretisation=dataclasses.replace(
            problem.discretisation, push=dataclasses.replace(push, target=push.target * ratio,
                                                             pending=True)))
        result = signorini.solve(moved, "pdas")
        x = result.x[result.active]
        slope = signorini.derivative(result, "a", "P")
        rows.append({"P": result.total_force, "discrete_width": float(x.max()),
                     "fitted_a": result.hertz.a, "da_dP": slope.derivative})
    return {"scene": "hertz-cylinder (default mesh, one mesh for every load)", "rows": rows}


def figure(data: dict, path: Path) -> None:
    rows = data["rows"]
    P = np.array([r["P"] for r in rows])
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.step(P, [r["discrete_width"] for r in rows], where="mid", label="discrete width (last active node)")
    ax.plot(P, [r["fitted_a"] for r in rows], "o-", ms=3, label="fitted a (hertz_fit)")
    for r in rows[::8]:
        h = 0.04 * (P[-1] - P[0])
        ax.plot([r["P"] - h, r["P"] + h], [r["fitted_a"] - h * r["da_dP"], r["fitted_a"] + h * r["da_dP"]],
                "k-", lw=1)
    ax.set_xlabel("load P (per unit thickness)")
    ax.set_ylabel("contact half-width")
    ax.set_title("hertz-cylinder: the discrete width is piecewise constant in P")
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=120)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--refine", type=int, nargs="*", default=[2, 3])
    parser.add_argument("--out", default="docs/derivatives")
    args = parser.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    data = widths()
    (out / "width.json").write_text(json.dumps(data, indent=1))
    figure(data, out / "width.png")
    if args.refine:
        rows = [cost(refine) for refine in args.refine]
        (out / "cost.json").write_text(json.dumps({"scene": "hertz-cylinder", "params": FINE,
                                                   "rows": rows}, indent=1))


if __name__ == "__main__":
    main()
