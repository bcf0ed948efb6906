"""Axis 5: near-incompressibility — P1 locking in the contact pressure as ν → 0.5."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from signorini.output import plots
from signorini.studies.atlas import figures
from signorini.studies.atlas.axis import (SHORT, TINY_HERTZ, Axis, Rows, cell, every_method, num, pivot,
                                          scene_spec)
from signorini.studies.atlas.findings import VERBS, claim, methods_of, name, one, pct, pick
from signorini.studies.task import Task

POISSON = (0.3, 0.4, 0.45, 0.49, 0.499, 0.4999, 0.49999999999)
POISSON_MESH = {"n_contact": 16, "grading": 0.4}


def tasks(quick: bool, methods: list[str]) -> list[Task]:
    ratios = (0.3, 0.4999) if quick else POISSON
    mesh = TINY_HERTZ if quick else POISSON_MESH
    out = []
    for nu in ratios:  # plain P1 (the volumetric strain element by element): where it locks
        problem = scene_spec("hertz-cylinder", params={**mesh, "nu": nu, "volumetric": "element"})
        for task in every_method("poisson", "mesh A", nu, problem, methods):
            out.append(Task(**{**task.as_dict(), "measure": ("profile",)}) if task.method == "pdas"
                       else task)
    levels = ((0, "mesh A"), (1, "mesh B"), (2, "mesh C"))[: 2 if quick else 3]
    for level, name in levels[1:]:
        out += [Task("poisson", name, nu,
                     scene_spec("hertz-cylinder", params={**mesh, "nu": nu, "refine": level,
                                                          "volumetric": "element"}),
                     "pdas", measure=("profile",)) for nu in ratios]
    for level, name in levels:  # the volumetric strain averaged at the nodes: no locking
        out += [Task("poisson", f"{name}, nodal", nu,
                     scene_spec("hertz-cylinder", params={**mesh, "nu": nu, "refine": level,
                                                          "volumetric": "nodal"}),
                     "pdas", measure=("profile",)) for nu in ratios]
    return out


def findings(rows: Rows) -> list[str]:
    out = []
    for case in dict.fromkeys(r["case"] for r in rows):
        pdas = sorted((r for r in rows if r["case"] == case and r["method"] == "pdas"),
                      key=lambda r: r["value"])
        if pdas and np.isfinite(pdas[0].get("p0_rel", np.nan)):
            out.append(f"**pdas on {case}** ({pdas[0]['dofs']:,.0f} dofs), Hertz p₀ error: " + ", ".join(
                f"ν={r['value']:.12g}: {100 * r['p0_rel']:.1f} %" for r in pdas)
                + "; pressure L2 error: " + ", ".join(
                f"{100 * r['pressure_l2_rel']:.1f} %" for r in pdas) + ".")
    mesh_a = [r for r in rows if r["case"] == "mesh A"]
    for nu in sorted({r["value"] for r in mesh_a}):
        mine = [r for r in mesh_a if r["value"] == nu]
        bad = [f"{r['method']} ({cell(r)})" for r in mine if r["outcome"] != "right"
               and r["status"] != "refused"]
        text = f"ν = {nu:.12g}: {sum(r['outcome'] == 'right' for r in mine)}/{len(mine)} methods right"
        out.append(text + (("; not: " + ", ".join(bad)) if bad else "") + ".")
    uzawa = sorted((r for r in mesh_a if r["method"] == "uzawa"), key=lambda r: r["value"])
    if uzawa:
        out.append("uzawa iterations on mesh A: " + ", ".join(
            f"ν={r['value']:.12g}: {r['iterations']:,.0f} ({SHORT.get(r['status'], r['status'])})"
            for r in uzawa) + ".")
    return out


def table(rows: Rows) -> list[str]:
    mesh_a = [r for r in rows if r["case"] == "mesh A"]
    return pivot(mesh_a, "method", "value", lambda r: cell(r, f"{num(r.get('lam_rel'), 0)}"),
                 corner="method \\ ν")


def figure(rows: Rows) -> Figure:
    figure = Figure(figsize=(11, 4.4), layout="constrained")
    left, right = figure.subplots(1, 2)
    pdas = [dict(r, incompressibility=0.5 - r["value"]) for r in rows if r["method"] == "pdas"]
    figures.atlas_series(pdas, "incompressibility", "p0_rel", ax=left, group="case",
                         xlabel="0.5 − ν", ylabel="Hertz p₀ relative error (pdas, exact)")
    left.invert_xaxis()
    profiles = {r["value"]: r["profile"] for r in pdas if r["case"] == "mesh A"
                and isinstance(r.get("profile"), dict)}
    if profiles:
        low, high = min(profiles), max(profiles)
        scaled = {nu: (np.asarray(p["x"]) / p["a_ref"], np.asarray(p["pressure"]) / p["p0_ref"])
                  for nu, p in profiles.items()}
        plots.pressure_profile(scaled[low][0], scaled[low][1], a_ref=1.0, p0_ref=1.0,
                               label=f"ν = {low:.12g}", ax=right)
        right.plot(scaled[high][0], scaled[high][1], "x-", ms=4, lw=0.6, color="C3",
                   label=f"ν = {high:.12g}")
        nodal = [r["profile"] for r in pdas if r["case"] == "mesh A, nodal" and r["value"] == high
                 and isinstance(r.get("profile"), dict)]
        if nodal:
            x, p = np.asarray(nodal[0]["x"]), np.asarray(nodal[0]["pressure"])
            right.plot(x / nodal[0]["a_ref"], p / nodal[0]["p0_ref"], "s-", ms=3, lw=0.6, color="C2",
                       label=f"ν = {high:.12g}, volumetric=nodal")
        right.legend(fontsize=7)
        right.set_xlim(0, 1.6)
        right.set_title("pressure at the nodes (pdas, mesh A)", fontsize=8)
    figure.suptitle("Axis 5: near-incompressibility — P1 locking in the contact pressure, and "
                    "the nodal average that removes it", fontsize=9)
    return figure


def _nodal_text(nodal: Rows, plain: Rows, order: list[str], dofs: dict[str, int]) -> str:
    """What averaging the volumetric strain at the nodes does on the same meshes (axis 5)."""
    def p0(mesh: str, nu: float, rows: Rows = nodal) -> float:
        return one(rows, case=f"{mesh}, nodal" if rows is nodal else mesh, value=nu)["p0_rel"]

    nus = sorted({r["value"] for r in nodal})[:-1]  # the extreme ν is not certified (below)
    claim(all(p0(m, nu) < 0.01 for m in order for nu in nus),
          "with the nodal average PDAS's p₀ is within 1 % for every ν up to 0.4999 on every mesh")
    claim(all(p0(m, nu) < 0.1 * p0(m, nu, plain) for m in order for nu in (0.499, 0.4999)),
          "with the nodal average p₀ is at least ten times closer than plain P1's at ν ≥ 0.499")
    return ("With the volumetric strain averaged at the nodes (`volumetric=nodal`, the default "
            "from ν = 0.4) nothing locks: p₀'s error at ν = 0.3, 0.49, 0.499, 0.4999 is "
            + "; ".join(", ".join(pct(p0(m, nu), 2) for nu in (0.3, 0.49, 0.499, 0.4999))
                        + f" on {dofs[m]:,} dofs" for m in order) + ".")


def headline(rows: Rows) -> str:
    """The axis's finding in a paragraph, as docs/results.md states it."""
    every = pick(rows, method="pdas")
    pdas = [r for r in every if not r["case"].endswith(", nodal")]
    nodal = [r for r in every if r["case"].endswith(", nodal")]
    meshes = sorted({r["case"] for r in pdas})
    dofs = {m: pick(pdas, case=m)[0]["dofs"] for m in meshes}
    finest, coarsest = max(meshes, key=dofs.get), min(meshes, key=dofs.get)

    def p0(mesh: str, nu: float) -> float:
        return one(pdas, case=mesh, value=nu)["p0_rel"]

    order = sorted(meshes, key=dofs.get)
    claim(all(p0(m, nu) < 0.01 for m in meshes for nu in (0.3, 0.4, 0.45)),
          "PDAS's p₀ is within 1 % for ν ≤ 0.45 on every mesh")
    claim(all(p0(a, 0.499) > p0(b, 0.499) for a, b in zip(order, order[1:])),
          "refinement lowers the p₀ error at ν = 0.499")
    exact = [m for m in ("pdas", "nested", "condensed") if m in methods_of(rows)]
    extreme = max(r["value"] for r in rows)
    usual = sorted({r["value"] for r in rows} - {extreme})
    claim(all(r["outcome"] == "right" for r in pick(rows, case=coarsest)
              if r["method"] in exact and r["value"] != extreme),
          "the exact methods solve every ν short of the extreme one")
    at_extreme = [r for r in rows if r["value"] == extreme]
    claim(all(r["status"] != "converged" and r["outcome"] != "wrong" for r in at_extreme),
          "no method is converged at the extreme ν, and none is wrong there")
    worst = [r for r in pick(rows, case=coarsest, value=usual[-1])
             if r["method"] in ("uzawa", "petsc-vi") and r["outcome"] != "right"]
    return ("**ν → 0.5** (axis 5): plain P1 locks, the solvers do not fail: PDAS's p₀ error on the "
            f"finest mesh ({dofs[finest]:,} dofs) is {pct(p0(finest, 0.3))} at ν = 0.3, "
            f"{pct(p0(finest, 0.49))} at 0.49, {pct(p0(finest, 0.499))} at 0.499 and "
            f"{pct(p0(finest, 0.4999), 0)} at 0.4999; at 0.499 each refinement cuts it ("
            + " → ".join(pct(p0(m, 0.499)) for m in order) + "), at 0.4999 it stays large ("
            + " → ".join(pct(p0(m, 0.4999), 0) for m in order) + "). "
            + _nodal_text(nodal, pdas, order, dofs) + " The exact methods solve every ν up to "
            f"{usual[-1]:g}; at {usual[-1]:g} "
            + " and ".join(f"{name(r['method'])} {VERBS.get(r['status'], r['status'])}"
                           for r in worst) + f" on the {dofs[coarsest]:,}-dof mesh. At ν = {extreme!r} "
            "double precision cannot certify the contact forces (the certificate's forward error, "
            f"docs/certificate.md): all {len(at_extreme)} runs there, the exact methods' too, end "
            "`inaccurate` or worse, none `converged`.")


AXIS = Axis(
    5, "poisson", "Near-incompressibility",
    "How does P1 locking show in the pressure as ν → 0.5, and do the solvers cope?",
    setup=f"Hertz's cylinder {POISSON_MESH} (mesh A) in plain P1 (`volumetric=element`) with "
          "every method, and PDAS alone on refine 1 (mesh B) and refine 2 (mesh C); PDAS on the "
          "same three meshes with the volumetric strain averaged at the nodes "
          "(`volumetric=nodal`, the cases '…, nodal'); ν = 0.3 … 0.4999 and 0.49999999999, "
          "tol 1e-8.",
    advice="Plain P1 triangles lock as ν → 0.5: the contact pressure oscillates from node to "
           "node and refining the mesh cures it only slowly. Averaging the volumetric strain at "
           "the nodes (`--set volumetric=nodal`; the default `auto` does so from ν = 0.4) "
           "removes the locking at no extra dofs: Hertz's p₀ stays as close at ν = 0.4999 as at "
           "0.3 on every mesh (the cases '…, nodal'). The solvers are not the problem up to "
           "ν = 0.4999: the exact methods solve every ν; first-order methods slow down with "
           "the conditioning. At ν = 0.49999999999 double precision cannot resolve the contact "
           "force to 1e-8 on any method (the certificate's force_error_floor is about 1e-4, "
           "docs/certificate.md): no method is converged there.",
    legend="Mesh A; cells: status, λ error against PDAS on the same mesh.",
    tasks=tasks, findings=findings, table=table, figure=figure, headline=headline)


__all__ = ["tasks", "findings", "table", "figure", "headline"]
