"""Hertz between two elastic cylinders solved by GetFEM, on meshes that do not match.

The two-body peer that ``signorini bench --peer getfem --scene hertz-two-cylinders``
runs: a standalone script for the *system* Python (Debian's ``python3-getfem`` and
``python3-gmsh``), like ``getfem_hertz.py`` beside it, whose fit and mesher it
reuses; it never imports the package.

    /usr/bin/python3 benchmarks/peers/getfem_two_cylinders.py '{"h_contact": 0.0625}'
    /usr/bin/python3 benchmarks/peers/getfem_two_cylinders.py '{"h_contact": 0.0625, "repeat": 6}'

The model, as the package's scene ``hertz-two-cylinders`` at its defaults: the
upper cylinder (R1, E1, ν1) is the quarter of its disc below its centre (0, R1),
the lower one (R2, E2, ν2) the quarter above its centre (0, −R2), plane strain,
first touching at the origin; u_x = 0 on both symmetry planes x = 0. Each cut
through a centre carries a uniform traction towards the other body whose
resultant is the load P of two-body Hertz for ``a_over_R`` (a/R*,
P = πE*a²/(4R*) per unit thickness, 1/E* = (1 − ν1²)/E1 + (1 − ν2²)/E2,
1/R* = 1/R1 + 1/R2). The lower body's centre node is held vertically
(``add_pointwise_constraints_with_multipliers``), the upper body's rigid
vertical mode is removed by a tiny spring ``stabilisation · E1/R1² · u`` (the
scene pushes that centre node by a load-controlled δ that leaves it free of force).

Contact: GetFEM's nodal contact brick between non-matching meshes
(``add_nodal_contact_between_nonmatching_meshes_brick``, small sliding,
Alart–Curnier augmented Lagrangian, Newton): the upper arc with x ≤
``candidates`` · a is the slave, the lower arc with x ≤ ``master_reach`` ·
``candidates`` · a the master; each slave node is projected on the master
surface along its normal. P1 triangles on two gmsh meshes graded like
``getfem_hertz.py``'s: size ``h_contact`` · a at the contact on the upper body
and ``master_ratio`` times that on the lower one, so that the contact faces do
not match. Solved in units of R1 and E1 by ``Model.solve`` (MUMPS), Newton
starting from the upper body pushed down rigidly by a²/R*.

Output, one JSON line on stdout, with the keys of ``getfem_hertz.py``'s: dofs
(both bodies' displacement dofs), slave and master nodes, the slave nodes that
face a master node at the same x (on non-matching meshes the first point of
contact alone; all of them when the meshes match: R1 = R2 and ``master_ratio``
1), p0 and a from the same fit of the slave's nodal pressures λᵢ/wᵢ (wᵢ = ∫ φᵢ
ds on the slave arc; λᵢ acts along the master's normal), the total vertical
contact force of the full cylinders, Hertz's values, Newton's iterations, the
phase timings and, with ``repeat``, every solve's wall time.
"""

from __future__ import annotations

import math
import sys
import time

import numpy as np

from getfem_hertz import fit_hertz, main, mesh_quarter_disc, newton

DEFAULTS = {
    "R1": 1.0, "R2": 1.0, "E1": 1.0, "nu1": 0.3, "E2": 1.0, "nu2": 0.3,
    "a_over_R": 0.05,         # contact half-width over R* (1/R* = 1/R1 + 1/R2)
    "h_contact": 1 / 16,      # element size at the contact on the upper (slave) body, a fraction of a
    "master_ratio": 1.25,     # the lower (master) body's size at the contact over the upper's
    "fine_radius": 1.5,       # the size stays fine within this multiple of a
    "growth": 0.15,           # size growth per unit distance beyond the fine zone
    "h_max": 0.1,             # largest element size, a fraction of each radius
    "candidates": 2.0,        # slave nodes on the upper arc with x ≤ candidates · a
    "master_reach": 1.5,      # the master arc reaches this much further than the slave's
    "stabilisation": 1e-9,    # the upper body's spring stiffness per area, in units of E1/R1²
    "augmentation": 1.0,      # the contact brick's augmentation parameter r, in units of E1
    "max_res": 1e-10,         # Newton's residual target (GetFEM's, relative to the first)
    "lsearch": "default",     # GetFEM's Newton line search
    "lsolver": "auto",        # GetFEM's linear solver (auto: MUMPS here)
    "repeat": 1,              # solves in this process (the first a warm-up), each timed
}


def two_body_hertz(R1, R2, E1, nu1, E2, nu2, a):
    """(P, p0, R*, E*) of two-body Hertz for half-width a (P per unit thickness)."""
    E_star = 1.0 / ((1.0 - nu1 ** 2) / E1 + (1.0 - nu2 ** 2) / E2)
    R_star = 1.0 / (1.0 / R1 + 1.0 / R2)
    P = math.pi * E_star * a ** 2 / (4.0 * R_star)
    return P, 2.0 * P / (math.pi * a), R_star, E_star


def quarter(gf, R, a, q, h_contact, upper):
    """One cylinder's quarter disc as a GetFEM mesh: the upper one as meshed for
    ``getfem_hertz.py``, the lower one the same shape mirrored below y = 0."""
    points, triangles = mesh_quarter_disc(R, a, {**q, "h_contact": h_contact})
    if not upper:  # mirrored, each triangle turned back counter-clockwise
        points, triangles = points * np.array([1.0, -1.0]), triangles[:, [0, 2, 1]]
    return gf.Mesh("pt2D", points.T, triangles.T), points.shape[0]


def regions(m, R, reach, upper):
    """Mark the axis (1), the cut through the centre (2) and the arc near the contact (3)."""
    faces = m.outer_faces()
    normals = m.normal_of_faces(faces)
    toward = -1.0 if upper else 1.0  # the arc's outward normal points towards the other body
    m.set_region(1, faces[:, normals[0] < -0.999])
    m.set_region(2, faces[:, toward * normals[1] < -0.999])
    m.set_region(3, faces[:, (toward * normals[1] > 0.5) & (R * normals[0] <= reach)])


def solve(q):
    """Mesh, assemble, solve and fit one point (getfem and gmsh imported already by :func:`main`)."""
    import getfem as gf
    import gmsh

    gf.util_trace_level(0)
    times = {}
    tic = time.perf_counter()
    # in units of R1 and E1 (GetFEM's Newton test mixes forces and lengths: getfem_hertz.py)
    length, stress = q["R1"], q["E1"]
    R1, R2, E1, E2 = 1.0, q["R2"] / length, 1.0, q["E2"] / stress
    nu1, nu2 = q["nu1"], q["nu2"]
    _, _, R_star, _ = two_body_hertz(R1, R2, E1, nu1, E2, nu2, 1.0)
    a = q["a_over_R"] * R_star
    P, _, _, _ = two_body_hertz(R1, R2, E1, nu1, E2, nu2, a)
    upper, n_upper = quarter(gf, R1, a, q, q["h_contact"], True)
    lower, n_lower = quarter(gf, R2, a, q, q["master_ratio"] * q["h_contact"], False)
    times["mesh_s"] = time.perf_counter() - tic

    tic = time.perf_counter()
    AXIS, CUT, ARC = 1, 2, 3
    reach = q["candidates"] * a
    regions(upper, R1, reach, True)
    regions(lower, R2, q["master_reach"] * reach, False)
    md = gf.Model("real")
    fems, ims = [], []
    for name, m, E, nu, R, sign in (("u1", upper, E1, nu1, R1, -1.0), ("u2", lower, E2, nu2, R2, 1.0)):
        mfu = gf.MeshFem(m, 2)
        mfu.set_fem(gf.Fem("FEM_PK(2,1)"))
        mim = gf.MeshIm(m, gf.Integ("IM_TRIANGLE(2)"))
        fems.append(mfu)
        ims.append(mim)
        md.add_fem_variable(name, mfu)
        md.add_initialized_data(f"mu_{name}", [E / (2 * (1 + nu))])
        md.add_initialized_data(f"lambda_{name}", [E * nu / ((1 + nu) * (1 - 2 * nu))])
        md.add_isotropic_linearized_elasticity_brick(mim, name, f"lambda_{name}", f"mu_{name}")
        md.add_source_term_brick(mim, name, f"[0, {sign * P / (2.0 * R)!r}]", CUT)
        md.add_normal_Dirichlet_condition_with_multipliers(mim, name, 1, AXIS)
    md.add_initialized_data("eps", [q["stabilisation"] * E1 / R1 ** 2])
    md.add_linear_term(ims[0], "eps*u1.Test_u1")
    md.add_initialized_data("centre", [0.0, -R2])  # the lower body's centre node, held vertically
    md.add_initialized_data("vertical", [0.0, 1.0])
    md.add_pointwise_constraints_with_multipliers("u2", "centre", "vertical")
    md.add_initialized_data("r", [q["augmentation"] * E1])
    md.add_nodal_contact_between_nonmatching_meshes_brick(ims[0], ims[1], "u1", "u2", "lambda_n", "r",
                                                          ARC, ARC)
    times["setup_s"] = time.perf_counter() - tic

    tic = time.perf_counter()
    iterations, converged = newton(md, "u1", fems[0].nbdof(), a ** 2 / R_star, q)  # the upper body pushed
    times["solve_s"] = time.perf_counter() - tic

    tic = time.perf_counter()
    lam = -md.variable("lambda_n")  # GetFEM's multiplier is negative in compression
    slave = fems[0].basic_dof_on_region(ARC)
    nodes = fems[0].basic_dof_nodes(slave[::2])
    w = gf.asm_generic(ims[0], 1, "[0, 1].Test_u1", ARC, "u1", 1, fems[0], np.zeros(fems[0].nbdof()))
    pressure = lam / w[slave[1::2]]
    # λ acts along the master's normal, the load vertically: the normal's vertical component at
    # the slave node's place on the master arc (the undeformed circle; the displacements are small)
    vertical = np.sqrt(1.0 - np.minimum(nodes[0] / R2, 1.0) ** 2)
    p0, a_fit, n_active = fit_hertz(nodes[0], pressure)
    master = fems[1].basic_dof_nodes(fems[1].basic_dof_on_region(ARC)[::2])
    apart = np.abs(nodes[0][:, None] - master[0]).min(axis=1)  # across the gap, along x
    P_ref, p0_ref, _, _ = two_body_hertz(q["R1"], q["R2"], q["E1"], q["nu1"], q["E2"], q["nu2"],
                                         a * length)
    times["post_s"] = time.perf_counter() - tic
    return {
        "code": "getfem", "scene": "two-cylinders", "params": q,
        "dofs": int(fems[0].nbdof() + fems[1].nbdof()), "nodes": int(n_upper + n_lower),
        "contact_nodes": int(slave.size // 2), "active_nodes": n_active,
        "master_nodes": int(master.shape[1]), "facing_nodes": int((apart < 1e-9 * a).sum()),
        "newton_iterations": int(iterations), "converged": bool(converged),
        "p0": p0 * stress, "a": a_fit * length, "p0_ref": p0_ref, "a_ref": a * length,
        "load": P_ref, "total_force": float(2.0 * (lam * vertical).sum()) * stress * length,
        "p0_rel": p0 * stress / p0_ref - 1.0, "a_rel": a_fit / a - 1.0,
        "x": (nodes[0] * length).tolist(), "pressure": (pressure * stress).tolist(),
        "time": times, "versions": {"getfem": gf.getfem_env("release"), "gmsh": gmsh.__version__,
                                     "numpy": np.__version__, "python": sys.version.split()[0]},
    }


if __name__ == "__main__":  # the one-body script's runner: repeat, timings, one JSON line
    main(sys.argv, solve, DEFAULTS, "getfem_two_cylinders")
