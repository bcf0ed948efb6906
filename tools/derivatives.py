"""The cost of a derivative against the solve, and the discrete contact width against the fitted a.

    python tools/derivatives.py --set refine=3 --set n_contact=110 --set grading=0.1  # one mesh
    python tools/derivatives.py --width     # width.json + width.png
    python tools/derivatives.py --doc       # docs/derivatives.md's table from cost.json

``--set`` runs hertz-cylinder with those parameters once and puts its row (dofs, solve and
derivative seconds and work) into ``cost.json``, replacing a row with the same parameters, so
that each mesh is run once; ``--width`` writes the cylinder's discrete width and fitted a
against P. Both then write the page's table (``tests/test_readme_numbers.py`` holds it to the JSON).
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import sys
import time
from pathlib import Path

import numpy as np

import signorini
from signorini.numerics.factor import counting

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "docs" / "derivatives"
PAGE = ROOT / "docs" / "derivatives.md"


def cost(params: dict) -> dict:
    problem = signorini.build_problem("hertz-cylinder", params=params)
    start = time.perf_counter()
    with counting() as work:
        result = signorini.solve(problem)
    solve_s, solve_work = time.perf_counter() - start, work.listed()
    start = time.perf_counter()
    with counting() as work:
        first = signorini.derivative(result, "total_force", "P")
    first_s, first_work = time.perf_counter() - start, work.listed()
    start = time.perf_counter()
    with counting() as work:
        again = signorini.derivative(result, "a", "P")
    again_s, again_work = time.perf_counter() - start, work.listed()
    return {"params": params, "dofs": problem.n, "method": result.method, "solve_s": solve_s,
            "solve_work": solve_work, "first_derivative_s": first_s, "first_work": first_work,
            "next_derivative_s": again_s, "next_work": again_work,
            "d_total_force_dP": first.derivative, "d_ln_a_d_ln_P":
            again.derivative * result.total_force / again.value}


def widths(count: int = 41) -> dict:
    base = signorini.solve("hertz-cylinder")
    problem, push = base.problem, base.problem.model.push
    rows = []
    for ratio in np.linspace(0.8, 1.25, count):
        moved = problem.with_data(push=dataclasses.replace(push, target=push.target * ratio),
                                  pending=True)
        result = signorini.solve(moved, "pdas")
        x = result.x[result.active]
        slope = signorini.derivative(result, "a", "P")
        rows.append({"P": result.total_force, "discrete_width": float(x.max()),
                     "fitted_a": result.hertz.a, "da_dP": slope.derivative})
    return {"scene": "hertz-cylinder (default mesh, one mesh for every load)", "rows": rows}


def figure(data: dict, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

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


def _seconds(seconds: float, work: dict) -> str:
    said = ", ".join(f"{count} {name.replace('_', '-')[:-1] if count == 1 else name.replace('_', '-')}"
                     for name, count in work.items() if name in ("factorisations", "back_solves"))
    return f"{seconds:.1f} s ({said})"


def cost_table(data: dict) -> str:
    """docs/derivatives.md's table: one row per mesh of ``cost.json``, by dofs."""
    lines = ["| mesh | dofs | solve (auto → method) | first derivative | next derivative "
             "| first / solve | d ln a / d ln P |", "|---|---:|---|---|---|---:|---:|"]
    for r in sorted(data["rows"], key=lambda row: row["dofs"]):
        mesh = ", ".join(f"{name}={value}" for name, value in r["params"].items())
        lines.append(f"| {mesh} | {r['dofs']:,} | {_seconds(r['solve_s'], r['solve_work'])} → {r['method']} "
                     f"| {_seconds(r['first_derivative_s'], r['first_work'])} "
                     f"| {_seconds(r['next_derivative_s'], r['next_work'])} "
                     f"| {r['first_derivative_s'] / r['solve_s']:.2f} | {r['d_ln_a_d_ln_P']:.4f} |")
    return "\n".join(lines)


def load() -> dict:
    return json.loads((OUT / "cost.json").read_text())


def _value(text: str):
    try:
        return int(text)
    except ValueError:
        return float(text)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                        help="a hertz-cylinder parameter of the mesh to time (repeat)")
    parser.add_argument("--width", action="store_true", help="write width.json and width.png")
    parser.add_argument("--doc", action="store_true", help="only write the page's table")
    args = parser.parse_args()
    OUT.mkdir(parents=True, exist_ok=True)
    if args.width:
        data = widths()
        (OUT / "width.json").write_text(json.dumps(data, indent=1))
        figure(data, OUT / "width.png")
    sys.path.insert(0, str(ROOT / "tools"))
    import readme  # noqa: E402  (tools/readme.py: the generated blocks, where a run was made)

    if args.set:
        params = {name: _value(value) for name, value in (item.split("=", 1) for item in args.set)}
        data = load() if (OUT / "cost.json").exists() else {"scene": "hertz-cylinder", "rows": []}
        where = readme.provenance("derivatives.py " + " ".join(f"--set {item}" for item in args.set))
        row = {**cost(params), "provenance": where}  # where: taken before the run (its load)
        rows = [row for row in data["rows"] if row["params"] != params] + [row]
        data["rows"] = sorted(rows, key=lambda row: row["dofs"])
        (OUT / "cost.json").write_text(json.dumps(data, indent=1))
    readme.fill_blocks(PAGE, {"derivative-cost": cost_table(load())})


if __name__ == "__main__":
    main()
