"""Hertz's contact solved by GetFEM: the peer that ``signorini bench --peer getfem`` runs.

A standalone script for the *system* Python (Debian's ``python3-getfem`` and
``python3-gmsh``), started in a subprocess by :mod:`signorini.studies.peer`
from a checkout of the repository; it imports only getfem, gmsh, numpy and the
standard library, never the package.

    /usr/bin/python3 benchmarks/peers/getfem_hertz.py '{"scene": "sphere", "h_contact": 0.03125}'
    /usr/bin/python3 benchmarks/peers/getfem_hertz.py '{"h_contact": 0.0625, "repeat": 6}'

The second solves the same point six times in one process and reports each
solve's wall time in ``runs_s`` (the in-process measure; the first is a warm-up).

The model: the lower quarter of the
disc (x ≥ 0, y ≤ R; the sphere's meridian for ``"scene": "sphere"``, then
r = x and the weak form carries the weight r and the hoop strain u_r/r), a
symmetry plane on x = 0 (u_x = 0), a uniform downward traction on the cut
through the centre y = R whose resultant is Hertz's load for ``a_over_R``
(cylinder: P = πE*a²/(4R) per unit thickness; sphere: P = 4E*a³/(3R)), a tiny
spring ``stabilisation · E/R² · u`` over the body that removes the rigid
vertical mode, and GetFEM's nodal contact brick (``add_nodal_contact_with_
rigid_obstacle_brick``, Alart–Curnier augmented Lagrangian, Newton) on the arc
with x ≤ ``candidates`` · a against the rigid flat y ≤ 0. P1 triangles on a
gmsh mesh whose size is ``h_contact`` · a within ``fine_radius`` · a of the
first point of contact and grows by ``growth`` per unit distance beyond it up
to ``h_max`` · R. The model is solved in units of R and E (see :func:`solve`)
by ``Model.solve`` (MUMPS), Newton starting from a rigid push by Hertz's
approach a²/R: from zero, the first step moves the body by its nearly free
rigid mode (held by one node and the tiny spring) and the line search damps
Newton for many steps (docs/peer.md).

Output, one JSON line on stdout: dofs (GetFEM's displacement dofs), contact
nodes, p0 and a from the least-squares fit :func:`fit_hertz` of the nodal
pressures λᵢ/wᵢ (wᵢ = ∫ φᵢ ds, with the weight r for the sphere), the total
contact force of the full body, Hertz's values for the applied load, the
Newton iterations, the script's own phase timings and, with ``repeat``, every
solve's wall time.
"""

from __future__ import annotations

import json
import math
import sys
import time

import numpy as np

START = time.perf_counter()

DEFAULTS = {
    "scene": "cylinder",      # "cylinder" (plane strain) or "sphere" (axisymmetric)
    "R": 1.0, "E": 1.0, "nu": 0.3, "a_over_R": 0.05,
    "h_contact": 1 / 16,      # element size at the contact, a fraction of a
    "fine_radius": 1.5,       # the size stays h_contact within this multiple of a
    "growth": 0.15,           # size growth per unit distance beyond the fine zone
    "h_max": 0.1,             # largest element size, a fraction of R
    "candidates": 2.0,        # contact candidates on the arc with x ≤ candidates · a
    "stabilisation": 1e-9,    # spring stiffness per volume, in units of E/R²
    "augmentation": 1.0,      # the contact brick's augmentation parameter r, in units of E
    "max_res": 1e-10,         # Newton's residual target (GetFEM's, relative to the first)
    "lsearch": "default",     # GetFEM's Newton line search
    "lsolver": "auto",        # GetFEM's linear solver (auto: MUMPS here)
    "start": "hertz",         # Newton's start: "hertz" (a rigid push by a²/R) or "zero"
    "repeat": 1,              # solves in this process (the first a warm-up), each timed
}


def fit_hertz(x, p, rel=1e-9):
    """Hertz's p0 and a from nodal pressures: least squares of p² = p0²(1 − x²/a²).

    Over the active nodes (p > rel · max p) except the outermost one, whose
    nodal value mixes the contact zone's edge with the free surface; returns
    (p0, a, active nodes), NaNs when the fit is not a Hertz profile. The same
    formula as :func:`signorini.studies.peer.fit_hertz` (a test holds them equal).
    """
    x, p = np.abs(np.asarray(x, dtype=float)), np.asarray(p, dtype=float)
    active = p > rel * p.max()
    idx = np.nonzero(active)[0]
    idx = idx[np.argsort(x[idx])][:-1]
    if idx.size < 2 or np.ptp(x[idx]) == 0:
        return math.nan, math.nan, int(active.sum())
    # in units of the largest x and p, so that their squares stay representable
    xs, ps = (_unit_of(v) for v in (x[idx], p[idx]))
    slope, intercept = np.polyfit((x[idx] / xs) ** 2, (p[idx] / ps) ** 2, 1)
    if not (intercept > 0 and slope < 0):
        return math.nan, math.nan, int(active.sum())
    return float(ps * np.sqrt(intercept)), float(xs * np.sqrt(-intercept / slope)), int(active.sum())


def _unit_of(values):
    """The largest finite magnitude among ``values`` (1 when there is none)."""
    values = np.abs(values[np.isfinite(values)])
    largest = float(values.max()) if values.size else 0.0
    return largest if largest > 0 else 1.0


def hertz(scene, R, E_star, a):
    """Hertz's load and peak pressure for half-width (radius) a."""
    if scene == "cylinder":
        P = math.pi * E_star * a ** 2 / (4.0 * R)
        return P, 2.0 * P / (math.pi * a)
    P = 4.0 * E_star * a ** 3 / (3.0 * R)
    return P, 3.0 * P / (2.0 * math.pi * a ** 2)


def mesh_quarter_disc(R, a, q):
    """gmsh: the quarter disc x ≥ 0, y ≤ R of the disc centred at (0, R), graded to (0, 0)."""
    import gmsh

    gmsh.initialize(["-noenv"], readConfigFiles=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add("quarter")
        geo = gmsh.model.geo
        bottom, centre, right = geo.addPoint(0, 0, 0), geo.addPoint(0, R, 0), geo.addPoint(R, R, 0)
        lines = [geo.addLine(bottom, centre), geo.addLine(centre, right),
                 geo.addCircleArc(right, centre, bottom)]
        geo.addPlaneSurface([geo.addCurveLoop(lines)])
        geo.synchronize()
        size = gmsh.model.mesh.field.add("MathEval")
        gmsh.model.mesh.field.setString(size, "F", (
            f"Min({q['h_max'] * R!r}, {q['h_contact'] * a!r} + {q['growth']!r}"
            f" * Max(0, Sqrt(x*x + y*y) - {q['fine_radius'] * a!r}))"))
        gmsh.model.mesh.field.setAsBackgroundMesh(size)
        for name in ("MeshSizeExtendFromBoundary", "MeshSizeFromPoints", "MeshSizeFromCurvature"):
            gmsh.option.setNumber(f"Mesh.{name}", 0)
        gmsh.option.setNumber("Mesh.Algorithm", 6)  # frontal-Delaunay
        gmsh.model.mesh.generate(2)
        tags, coords, _ = gmsh.model.mesh.getNodes()
        _, elements = gmsh.model.mesh.getElementsByType(2)
    finally:
        gmsh.finalize()
    index = np.zeros(int(tags.max()) + 1, dtype=int)
    index[tags.astype(int)] = np.arange(tags.size)
    points = coords.reshape(-1, 3)[:, :2]
    triangles = index[elements.astype(int)].reshape(-1, 3)
    return points, triangles


def newton(md, name, dofs, push, q):
    """``Model.solve`` from the variable ``name`` (``dofs`` of a 2D field) pushed down rigidly by
    ``push`` (0: from zero); Newton's iterations and whether it converged."""
    if push:
        start = np.zeros(dofs)
        start[1::2] = -push
        md.set_variable(name, start)
    return md.solve("max_res", q["max_res"], "max_iter", 100, "lsearch", q["lsearch"],
                    "lsolver", q["lsolver"])


def solve(q):
    """Mesh, assemble, solve and fit one point (getfem and gmsh imported already by :func:`main`)."""
    import getfem as gf
    import gmsh

    gf.util_trace_level(0)
    times = {}
    tic = time.perf_counter()
    if q["scene"] not in ("cylinder", "sphere"):
        raise SystemExit(f"getfem_hertz: scene {q['scene']!r} is not cylinder or sphere")
    # GetFEM's Newton test is relative to the first residual, which mixes forces (contact,
    # Dirichlet multipliers) and lengths (their constraints): in SI units (E = 2.1e11 Pa,
    # R = 1 cm) it stalls with tensile contact forces. Solve in units of R and E, then scale.
    R, E, nu, axi = 1.0, 1.0, q["nu"], q["scene"] == "sphere"
    a = q["a_over_R"]
    P, _ = hertz(q["scene"], R, E / (1.0 - nu ** 2), a)
    points, triangles = mesh_quarter_disc(R, a, q)
    times["mesh_s"] = time.perf_counter() - tic

    tic = time.perf_counter()
    m = gf.Mesh("pt2D", points.T, triangles.T)
    faces = m.outer_faces()
    normals = m.normal_of_faces(faces)
    AXIS, TOP, CONTACT = 1, 2, 3
    m.set_region(AXIS, faces[:, normals[0] < -0.999])
    m.set_region(TOP, faces[:, normals[1] > 0.999])
    arc = (normals[1] < -0.5) & (R * normals[0] <= q["candidates"] * a)
    m.set_region(CONTACT, faces[:, arc])

    mfu = gf.MeshFem(m, 2)
    mfu.set_fem(gf.Fem("FEM_PK(2,1)"))
    mim = gf.MeshIm(m, gf.Integ("IM_TRIANGLE(6)" if axi else "IM_TRIANGLE(2)"))
    md = gf.Model("real")
    md.add_fem_variable("u", mfu)
    lame_mu, lame_lambda = E / (2 * (1 + nu)), E * nu / ((1 + nu) * (1 - 2 * nu))
    md.add_initialized_data("mu", [lame_mu])
    md.add_initialized_data("lambda", [lame_lambda])
    md.add_initialized_data("eps", [q["stabilisation"] * E / R ** 2])
    weight = "*X(1)" if axi else ""
    if axi:  # (r, z): the hoop strain u_r/r joins the trace and the energy
        md.add_linear_term(mim, "(lambda*(Div(u) + u(1)/X(1))*(Div(Test_u) + Test_u(1)/X(1))"
                                " + 2*mu*(Sym(Grad(u)):Grad(Test_u) + u(1)*Test_u(1)/sqr(X(1))))*X(1)")
    else:
        md.add_isotropic_linearized_elasticity_brick(mim, "u", "lambda", "mu")
    md.add_linear_term(mim, f"eps*u.Test_u{weight}")
    traction = P / (math.pi * R ** 2) if axi else P / (2.0 * R)
    md.add_source_term_brick(mim, "u", f"[0, {-traction!r}]{weight}", TOP)
    md.add_normal_Dirichlet_condition_with_multipliers(mim, "u", 1, AXIS)
    contact_dofs = mfu.basic_dof_on_region(CONTACT)
    md.add_variable("lambda_n", contact_dofs.size // 2)
    md.add_initialized_data("r", [q["augmentation"] * E])
    md.add_nodal_contact_with_rigid_obstacle_brick(mim, "u", "lambda_n", "r", CONTACT, "y")
    times["setup_s"] = time.perf_counter() - tic

    tic = time.perf_counter()
    # start from a rigid push by Hertz's approach a²/R
    iterations, converged = newton(md, "u", mfu.nbdof(), a ** 2 / R if q["start"] == "hertz" else 0.0, q)
    times["solve_s"] = time.perf_counter() - tic

    tic = time.perf_counter()
    lam = -md.variable("lambda_n")  # GetFEM's multiplier is negative in compression
    nodes = mfu.basic_dof_nodes(contact_dofs[::2])
    zero = np.zeros(mfu.nbdof())
    w = gf.asm_generic(mim, 1, f"[0, 1].Test_u{weight}", CONTACT, "u", 1, mfu, zero)
    w = w[contact_dofs[1::2]]
    pressure = lam / w
    p0, a_fit, n_active = fit_hertz(nodes[0], pressure)
    multiplicity = 2 * math.pi if axi else 2.0
    length, stress = q["R"], q["E"]  # back to the caller's units
    force = stress * length ** (2 if axi else 1)
    P_ref, p0_ref = hertz(q["scene"], length, stress / (1.0 - nu ** 2), a * length)
    times["post_s"] = time.perf_counter() - tic
    return {
        "code": "getfem", "scene": q["scene"], "params": q, "dofs": int(mfu.nbdof()),
        "nodes": int(points.shape[0]), "elements": int(triangles.shape[0]),
        "contact_nodes": int(contact_dofs.size // 2), "active_nodes": n_active,
        "newton_iterations": int(iterations), "converged": bool(converged),
        "p0": p0 * stress, "a": a_fit * length, "p0_ref": p0_ref, "a_ref": a * length,
        "load": P_ref, "total_force": float(multiplicity * lam.sum()) * force,
        "p0_rel": p0 * stress / p0_ref - 1.0, "a_rel": a_fit / a - 1.0,
        "x": (nodes[0] * length).tolist(), "pressure": (pressure * stress).tolist(),
        "time": times, "versions": {"getfem": gf.getfem_env("release"), "gmsh": gmsh.__version__,
                                     "numpy": np.__version__, "python": sys.version.split()[0]},
    }


def main(argv, solve=solve, defaults=DEFAULTS, name="getfem_hertz"):
    """Solve the point of ``argv[1]`` ``repeat`` times in this process; print the last record.

    ``time.import_s`` is the start-up to getfem and gmsh imported, ``time.total_s`` the
    whole script to its output; ``runs_s`` holds each solve's wall time (mesh, assembly,
    solve and fit: everything after the imports), the first a warm-up when there are several.
    ``solve``, ``defaults`` and ``name`` are another script's (the two-body one's) when it runs.
    """
    given = json.loads(argv[1]) if len(argv) > 1 else {}
    unknown = sorted(set(given) - set(defaults))
    if unknown:
        raise SystemExit(f"{name}: unknown parameters {unknown}; known: {sorted(defaults)}")
    q = {**defaults, **given}
    if not (isinstance(q["repeat"], int) and q["repeat"] >= 1):
        raise SystemExit(f"{name}: repeat {q['repeat']!r} must be a whole number >= 1")
    import getfem  # noqa: F401  (imported before any solve is timed)
    import gmsh  # noqa: F401

    imported = time.perf_counter() - START
    runs = []
    for _ in range(q["repeat"]):
        tic = time.perf_counter()
        record = solve(q)
        runs.append(time.perf_counter() - tic)
    record["time"] = {"import_s": imported, **record["time"], "total_s": time.perf_counter() - START}
    record["runs_s"] = runs
    print(json.dumps(record))


if __name__ == "__main__":
    main(sys.argv)
