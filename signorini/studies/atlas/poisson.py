"""Axis 5: near-incompressibility — P1 locking in the contact pressure as ν → 0.5."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from signorini.output import plots
from signorini.studies.atlas import figures
from signorini.studies.atlas.axis import (SHORT, TINY_HERTZ, Axis, Rows, cell, every_method, num, pivot,
                                          scene_spec)
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
    tasks=tasks, findings=findings, table=table, figure=figure)
