"""The a posteriori error estimate (signorini.fem.estimate): exact where it must be, and effective."""

import importlib.util
import json
import time
from pathlib import Path

import numpy as np
import pytest
from skfem import Basis, ElementTriP1, ElementVector, MeshTet, MeshTri, asm
from skfem.models.elasticity import lame_parameters

import signorini
from signorini.fem.assembly import axisymmetric_elasticity
from signorini.fem.stiffness import simplex_stiffness
from signorini.fem.contact_estimate import contact_term, zone_and_neighbours
from signorini.fem.estimate import (_by_quadrature, _constant_strains, element_energies, estimate,
                                    material_units, quadrature, recover, strains)
from signorini.fem.transfer import uniform_prolongation
from signorini.files import to_json
from signorini.scenes.meshing import refine_uniformly
from signorini.studies.measures import energy_error

ROOT = Path(__file__).resolve().parents[1]
spec = importlib.util.spec_from_file_location("estimate_tool", ROOT / "tools" / "estimate.py")
tool = importlib.util.module_from_spec(spec)
spec.loader.exec_module(tool)

COARSE = {"n_contact": 16, "grading": 0.2}
#: η / ‖u_ref − u_h‖_E measured on the coarse base at refine 0 and 1 (docs/estimate.md: 1.03)
EFFECTIVITY_BAND = (0.95, 1.15)


def test_the_patch_test_has_no_error():
    """The block's solution is a uniform strain, in the P1 space: the estimate is zero."""
    result = signorini.solve("block", tol=1e-10)
    assert result.status == "converged"
    assert result.estimate.relative < 1e-10
    assert result.estimate.contact == 0.0


def test_a_uniform_axisymmetric_strain_has_no_error():
    """u_r = c r, u_z = d z: every strain component, the hoop strain c included, is constant."""
    mesh = MeshTri.init_tensor(np.linspace(0.0, 1.0, 6), np.linspace(0.0, 2.0, 7))
    u = np.column_stack([0.01 * mesh.p[0], -0.02 * mesh.p[1]])
    rule = quadrature(mesh, axisymmetric=True)
    eps = strains(mesh, u, rule, axisymmetric=True)
    assert np.allclose(eps[-1], 0.01) and np.allclose(recover(mesh, eps, rule), eps)


def test_element_energies_are_the_stiffness_energy():
    mesh = MeshTri.init_tensor(np.linspace(0.0, 1.0, 5), np.linspace(0.0, 1.0, 4))
    u = np.random.default_rng(0).normal(size=(mesh.p.shape[1], 2))
    K = simplex_stiffness(mesh, *lame_parameters(3.0, 0.3))
    assert element_energies(mesh, u, 3.0, 0.3).sum() == pytest.approx(u.ravel() @ K @ u.ravel())


def test_axisymmetric_energies_are_the_stiffness_energy():
    """The same with the hoop strain, against scikit-fem's assembly of the axisymmetric form
    (with the same quadrature: the hoop integrand is rational)."""
    mesh = MeshTri.init_tensor(np.linspace(0.1, 1.0, 5), np.linspace(0.0, 1.0, 4))
    u = np.random.default_rng(1).normal(size=(mesh.p.shape[1], 2))
    K = asm(axisymmetric_elasticity(*lame_parameters(3.0, 0.3)),
            Basis(mesh, ElementVector(ElementTriP1()), intorder=4))
    assert element_energies(mesh, u, 3.0, 0.3, axisymmetric=True).sum() == \
        pytest.approx(u.ravel() @ K @ u.ravel(), rel=1e-12)


def test_the_contact_term_lives_on_the_edge_of_the_contact_zone():
    """∫ p_h g_h ds: zero where each edge has pressure or gap only, p_a g_b ℓ/6 across the edge."""
    mesh = MeshTri.init_tensor(np.linspace(0.0, 3.0, 4), np.linspace(0.0, 1.0, 2))
    bottom = np.nonzero(mesh.p[1] == 0.0)[0]
    bottom = bottom[np.argsort(mesh.p[0, bottom])]
    pressure, gap = np.array([2.0, 1.0, 0.0, 0.0]), np.array([0.0, 0.0, 3.0, 5.0])
    elements, values = contact_term(mesh, bottom, pressure, gap)
    assert sorted(values) == pytest.approx([0.0, 0.0, 1.0 * 3.0 / 6.0])


def test_the_estimate_halves_under_uniform_refinement():
    relative = [signorini.solve("hertz-cylinder", params={**COARSE, "refine": k}).estimate.relative
                for k in (0, 1)]
    assert 0.45 < relative[1] / relative[0] < 0.55


def test_the_relative_estimate_does_not_depend_on_the_units():
    default = signorini.solve("hertz-cylinder", params=COARSE)
    si = signorini.solve("hertz-cylinder", params={**COARSE, "E": 2.1e11, "R": 0.01})
    assert si.estimate.relative == pytest.approx(default.estimate.relative, rel=1e-6)
    # the total is in physical units: √(energy) ∝ √E · R (per unit thickness, a/R fixed)
    assert si.estimate.total / default.estimate.total == pytest.approx(np.sqrt(2.1e11) * 0.01,
                                                                       rel=1e-6)


@pytest.mark.slow
@pytest.mark.parametrize("scene", ["hertz-cylinder", "hertz-sphere"])
def test_effectivity_against_a_finer_solution(scene):
    """η / ‖u_ref − u_h‖_E with u_ref two uniform refinements finer, as tools/estimate.py measures."""
    coarse, _ = tool.solve(scene, COARSE["n_contact"], COARSE["grading"], 0)
    fine, _ = tool.solve(scene, COARSE["n_contact"], COARSE["grading"], 2)
    error = energy_error(coarse.problem, coarse.solution, fine.problem, fine.solution, 2)["error"]
    effectivity = coarse.estimate.total / error
    assert EFFECTIVITY_BAND[0] < effectivity < EFFECTIVITY_BAND[1]


def test_uniform_prolongation_numbers_nodes_as_the_scene_refines():
    mesh = MeshTri.init_tensor(np.linspace(0.0, 1.0, 4), np.linspace(0.0, 1.0, 3))
    chain = np.nonzero(mesh.p[1] == 0.0)[0]
    p, t = mesh.p, mesh.t
    for _ in range(2):
        p, t, chain = refine_uniformly(p, t, chain[np.argsort(p[0, chain])])
    P = uniform_prolongation(mesh.t, mesh.p.shape[1], 2)
    assert np.allclose(P @ mesh.p.T, p.T)


def test_every_result_reports_its_estimate():
    result = signorini.solve("hertz-cylinder", params=COARSE)
    record = json.loads(to_json(result.to_dict()))["estimate"]
    assert set(record) >= {"total", "relative", "elements", "max_element"}
    assert record["elements"] == result.problem.model.mesh.t.shape[1]
    assert record["relative"] == pytest.approx(result.estimate.relative)
    assert len(result.estimate.elements) == record["elements"]
    problem = signorini.ContactProblem.from_qp(K=np.diag([2.0, 1.0]), f=np.array([1.0, 1.0]),
                                               N=np.array([[1.0, 0.0]]), d=np.array([0.25]))
    own = signorini.solve(problem)
    assert own.estimate is None and own.to_dict()["estimate"] is None


def test_the_estimate_solves_nothing():
    """The estimate is local work: no factorisation, no back-solve, no CG (counted, not timed)."""
    from signorini.numerics.factor import Work, counting

    result = signorini.solve("hertz-cylinder")
    with counting() as work:
        estimate(result.problem, result.solution)
    assert work == Work()


def test_a_uniform_pressure_has_no_pressure_error():
    """The block on the flat: uniform stress, exact in P1, so p_h and the recovered p* agree."""
    result = signorini.solve("block")
    assert result.estimate.pressure.relative < 1e-12


def test_the_body_normals_follow_the_arc():
    from signorini.fem.contact_estimate import boundary_normals, candidate_nodes

    problem = signorini.build_problem("hertz-cylinder")
    nodes = candidate_nodes(problem.model.mesh, problem.contact_points)
    normals = boundary_normals(problem.model.mesh, nodes)
    x, y = problem.model.mesh.p[:, nodes]
    radial = np.array([x, y - 1.0]) / np.hypot(x, y - 1.0)  # the quarter disc's centre is (0, R = 1)
    assert np.all(np.sum(normals * radial, axis=0) > 1 - 1e-5)
    first = np.argmin(x)  # the corner on the symmetry axis: its axis edge does not count, so its
    # normal is its one arc edge's, tilted from the vertical by half that edge's angle
    assert normals[:, first] == pytest.approx([0.0, -1.0], abs=1e-3)
    assert normals[0, first] > 0


@pytest.mark.parametrize("mesh", [MeshTri().refined(3), MeshTet().refined(2)], ids=["2D", "3D"])
def test_candidate_nodes_are_found_by_coordinates(mesh):
    """Points at nodes (exactly, or within a relative 1e-9) give those nodes; any other point is
    an error, not the nearest node."""
    from signorini.fem.contact_estimate import candidate_nodes

    nodes = np.random.default_rng(0).permutation(mesh.p.shape[1])[:20]
    points = mesh.p[:, nodes].T
    assert np.array_equal(candidate_nodes(mesh, points), nodes)
    assert np.array_equal(candidate_nodes(mesh, points * (1 + 1e-12)), nodes)
    with pytest.raises(ValueError, match="not a mesh node"):
        candidate_nodes(mesh, points + 0.01)


#: the pressure estimate over the true error on the coarse cylinder, by mesher (docs/estimate.md):
#: near 1 on the relaxed meshes adaptive refinement starts from; on Triangle's meshes the recovered
#: stress at the boundary is rougher than the pressure, and the estimate over-estimates
PRESSURE_EFFECTIVITY = {"relaxed": (0.5, 3.0), "triangle": (1.0, 5.0)}


@pytest.mark.parametrize("mesher", sorted(PRESSURE_EFFECTIVITY))
def test_the_pressure_estimate_shrinks_with_the_mesh_and_tracks_the_error(mesher):
    params = {**COARSE, "mesher": mesher}
    coarse = signorini.solve("hertz-cylinder", params=params)
    fine = signorini.solve("hertz-cylinder", params={**params, "refine": 1})
    assert fine.estimate.pressure.relative < 0.7 * coarse.estimate.pressure.relative
    error = tool.pressure_error(coarse, fine)  # the finer mesh's pressure as the reference
    low, high = PRESSURE_EFFECTIVITY[mesher]
    assert low < coarse.estimate.pressure.relative / error < high


def _adaptive(rows, scene, nu, mesh="adaptive"):
    return [r for r in rows if r["scene"] == scene and r["nu"] == nu and r["mesh"].startswith(mesh)]


def _first(rows, target):
    """The step that stops the loop for ``target``: the first whose estimate meets it."""
    return next(r for r in rows if r["pressure_estimate"] <= target)


def _span(values, digits=2):
    values = list(values)
    return f"{min(values):.{digits}f}–{max(values):.{digits}f}"


def test_the_adaptive_runs_meet_issue_15s_budgets():
    """docs/estimate.md and docs/results.md: every target within 20k / 60k dofs, the true error at the
    stopping step within the target, the effectivity within [0.5, 3] at every adaptive step."""
    rows = tool.load("adaptive")
    text = (ROOT / "docs" / "estimate.md").read_text()
    readme = (ROOT / "docs" / "results.md").read_text()
    stops = {0.003: [], 0.001: []}
    for scene in ("hertz-cylinder", "hertz-sphere"):
        for nu in (0.0, 0.3, 0.45):
            run = _adaptive(rows, scene, nu)
            for target, budget in ((0.003, 20_000), (0.001, 60_000)):
                stop = _first(run, target)
                assert stop["dofs"] <= budget and stop["pressure_error"] <= target
                stops[target].append(stop)
    every = [r["effectivity"] for r in rows if r["mesh"] == "adaptive"]
    assert 0.5 <= min(every) and max(every) <= 3.0
    assert f"within {_span(every)} at every adaptive step" in text
    assert f"stays within {_span(every)}× the true error" in readme
    low, high = (f"{f(r['dofs'] for r in stops[0.003]):,}" for f in (min, max))
    assert f"0.3 % takes {low}–{high} dofs" in text
    low, high = (f"{f(r['dofs'] for r in stops[0.001]):,}" for f in (min, max))
    assert f"0.1 % {low}–{high} over both scenes" in text
    worst = max(r["pressure_error"] for r in stops[0.003]), max(r["pressure_error"] for r in stops[0.001])
    assert f"at most {100 * worst[0]:.3f} % for 0.3 % and {100 * worst[1]:.3f} % for 0.1 %" in text
    cylinder = [r for r in rows if r["scene"] == "hertz-cylinder"]
    assert max(max(abs(r["p0_err"]), abs(r["a_err"])) for r in cylinder) < 6e-4


def test_where_adaptivity_pays_is_the_runs():
    """docs/estimate.md's and docs/results.md's comparison with uniform and hand-graded meshes (ν = 0.3)."""
    rows = tool.load("adaptive")
    text = (ROOT / "docs" / "estimate.md").read_text()
    readme = " ".join((ROOT / "docs" / "results.md").read_text().split())
    for scene in ("hertz-cylinder", "hertz-sphere"):
        run = _adaptive(rows, scene, 0.3)
        stop = _first(run, 0.001)
        uniform = _adaptive(rows, scene, 0.3, "uniform, refine 2")[0]
        hand = _adaptive(rows, scene, 0.3, "graded (40, 0.1)")[0]
        # about 0.09 %: fewer dofs than uniform refinement, not less time
        assert 2.5 < uniform["dofs"] / stop["dofs"] < 3.0 and stop["seconds"] > uniform["seconds"]
        assert (f"{100 * stop['pressure_error']:.3f} % at {stop['dofs']:,} against "
                f"{100 * uniform['pressure_error']:.3f} % at {uniform['dofs']:,}") in text
        # the hand-graded mesh: the first adaptive step as good costs more dofs and time
        as_good = next(r for r in run if r["pressure_error"] <= hand["pressure_error"] + 2e-5)
        assert as_good["dofs"] > hand["dofs"] and as_good["seconds"] > hand["seconds"]
        assert as_good["step"] + 1 == 4 and "solves four times to get there" in readme
        assert (f"{100 * hand['pressure_error']:.3f} % at {hand['dofs']:,}" in text
                and f"{100 * as_good['pressure_error']:.3f} % at {as_good['dofs']:,}" in text)
    flat = " ".join(text.split())
    scenes = ("hertz-cylinder", "hertz-sphere")
    stops = [_first(_adaptive(rows, scene, 0.3), 0.001) for scene in scenes]
    uniforms = [_adaptive(rows, scene, 0.3, "uniform, refine 2")[0] for scene in scenes]
    saving = [u["dofs"] / r["dofs"] for u, r in zip(uniforms, stops)]
    assert f"{min(saving):.1f} times fewer dofs" in flat and f"{min(saving):.1f}× fewer dofs" in readme
    assert (f"take {stops[0]['seconds']:.1f} s and {stops[1]['seconds']:.1f} s, one uniform solve "
            f"(nested) {uniforms[0]['seconds']:.1f} s and {uniforms[1]['seconds']:.1f} s") in flat
    assert (f"({stops[0]['seconds']:.1f} s against {uniforms[0]['seconds']:.1f} s on the cylinder)"
            in readme)
    for scene in ("hertz-cylinder", "hertz-sphere"):
        hand = _adaptive(rows, scene, 0.3, "graded (40, 0.1)")[0]
        as_good = next(r for r in _adaptive(rows, scene, 0.3)
                       if r["pressure_error"] <= hand["pressure_error"] + 2e-5)
        assert f"{hand['dofs']:,} dofs in {hand['seconds']:.1f} s" in flat \
            or f"{hand['dofs']:,} in {hand['seconds']:.1f} s" in flat
        assert f"{as_good['dofs']:,} in {as_good['seconds']:.1f} s" in flat
    hand = [_adaptive(rows, scene, 0.3, "graded (40, 0.1)")[0]["effectivity"]
            for scene in ("hertz-cylinder", "hertz-sphere")]
    uniform = _adaptive(rows, "hertz-sphere", 0.3, "uniform, refine 2")[0]["effectivity"]
    assert f"(effectivity {hand[0]:.2f} and {hand[1]:.2f})" in text
    assert f"the sphere's uniform refine 2 ({uniform:.2f})" in text


def test_the_nu_0_and_0_45_findings_are_the_runs():
    rows = tool.load("adaptive")
    text = (ROOT / "docs" / "estimate.md").read_text()
    sphere = _adaptive(rows, "hertz-sphere", 0.0)
    assert (f"meets 0.3 % at {_first(sphere, 0.003)['dofs']:,} dofs and 0.1 % at "
            f"{_first(sphere, 0.001)['dofs']:,}") in text
    assert f"(effectivity {_span(r['effectivity'] for r in sphere)})" in text
    for scene in ("hertz-sphere", "hertz-cylinder"):
        run = _adaptive(rows, scene, 0.45)
        assert f"{_first(run, 0.003)['dofs']:,} and {_first(run, 0.001)['dofs']:,}" in text


def test_where_the_true_error_is_is_the_runs():
    """docs/estimate.md: the true pressure error mostly peaks at the zone's edge, where the
    estimate puts little of its own."""
    rows = [r for r in tool.load("adaptive") if r["mesh"] == "adaptive"]
    text = (ROOT / "docs" / "estimate.md").read_text()
    edge = [r for r in rows if 0.97 <= r["true_top_x"] <= 1.0035]
    assert len(edge) > 0.8 * len(rows)
    assert f"x/a from 0.97 to 1.003 in {len(edge)} of {len(rows)} steps" in text
    shares = [r["true_top_share"] for r in edge]
    there = [r["estimate_share_at_true_top"] for r in edge]
    assert f"carries {100 * min(shares):.0f}–{100 * max(shares):.0f} % of the true error²" in text
    assert f"only {100 * min(there):.0f}–{100 * max(there):.0f} % of the estimate's" in text
    assert max(there) < 0.5 * max(shares)


@pytest.mark.parametrize("scene, params", [("hertz-sphere-3d", {}), ("hertz-cylinder", {"nu": 0.3}),
                                           ("punch", {})])
def test_the_closed_form_for_constant_strains_is_the_quadrature(scene, params):
    """Plane strain and 3D P1 strains are constant per simplex: the estimate's closed form (no
    quadrature points) gives what the order-2 quadrature gives, element by element."""
    result = signorini.solve(scene, params=params)
    problem = result.problem
    mesh, dim = problem.model.mesh, problem.model.mesh.p.shape[0]
    u = problem.model.expand(result.solution.u).reshape(-1, dim)
    material = lame_parameters(*material_units(problem))
    closed = _constant_strains(mesh, u, *material)
    by_points = _by_quadrature(problem, mesh, u, *material)
    for fast, reference in zip(closed, by_points[:3]):
        assert np.allclose(fast, reference, rtol=1e-12, atol=1e-14 * np.abs(reference).max())


def test_the_zone_and_its_first_free_neighbours_are_counted():
    """Along a chain of boundary candidates, the nodes in contact and one free node on each side."""
    mesh = MeshTri.init_tensor(np.linspace(0.0, 1.0, 7), np.linspace(0.0, 1.0, 3))
    bottom = np.nonzero(mesh.p[1] == 0.0)[0]
    bottom = bottom[np.argsort(mesh.p[0, bottom])]
    active = np.array([False, False, True, True, False, False, False])
    assert zone_and_neighbours(mesh, bottom, active).tolist() == [False, True, True, True, True, False,
                                                                 False]
    assert not zone_and_neighbours(mesh, bottom, np.zeros(7, dtype=bool)).any()


def test_free_candidates_beyond_the_first_carry_no_pressure_estimate():
    result = signorini.solve("hertz-cylinder", params=COARSE)
    found = result.estimate.pressure
    counted = found.indicators > 0
    assert found.active.sum() > 3 and np.all(counted[found.active])
    free = ~found.active
    assert 0 < np.sum(counted & free) <= 2  # the first free node (one side: the other is the axis)
    x = result.problem.contact_points[:, 0]
    assert x[counted].max() < x[free & ~counted].min()


def test_the_punch_findings_are_the_runs():
    """docs/estimate.md on the punch: the pressure estimate stalls at the sharp corner and jumps once
    the corner node becomes a candidate; the energy target is met; rounded corners converge."""
    rows = tool.load("punch")
    text = (ROOT / "docs" / "estimate.md").read_text()

    def run(corners, on):
        return [r for r in rows if r["corners"] == corners and r["on"] == on]

    sharp = run("sharp", "pressure")
    widened = [k for k, r in enumerate(sharp) if r["action"] == "candidates widened"]
    assert len(widened) == 1
    before = sharp[:widened[0]]
    assert before[-1]["pressure"] > 0.9 * before[0]["pressure"]  # stalls
    assert sharp[-1]["pressure"] > 0.9 and "max dofs" in sharp[-1]["reason"]
    assert (f"from {100 * before[0]['pressure']:.1f} % to {100 * before[-1]['pressure']:.1f} % in "
            f"{len(before) - 1}") in " ".join(text.split())
    energy = run("sharp", "energy")
    assert "target energy-norm error 2 % met" in energy[-1]["reason"]
    assert f"meets 2 % at {energy[-1]['dofs']:,} dofs" in " ".join(text.split())
    rounded = run("rounded, r = 0.2 a", "pressure")
    assert rounded[-1]["pressure"] < 0.1 * rounded[0]["pressure"]
    flat = " ".join(text.split())
    assert f"jumps to {100 * sharp[-1]['pressure']:.1f} %" in flat
    assert (f"falls from {100 * rounded[0]['pressure']:.1f} % to {100 * rounded[-1]['pressure']:.1f} %"
            in flat)
    assert all(r["status"] == "converged" for r in rows if "status" in r)


def test_the_start_findings_are_the_runs():
    """docs/estimate.md and docs/results.md: from a steeply graded start the estimate under-estimates and a
    0.1 % target stops outside it (said, not hidden)."""
    rows = tool.load("start")
    text = " ".join((ROOT / "docs" / "estimate.md").read_text().split())
    readme = " ".join((ROOT / "docs" / "results.md").read_text().split())
    cylinder = [r for r in rows if r["scene"] == "hertz-cylinder"]
    sphere = [r for r in rows if r["scene"] == "hertz-sphere"]
    late = [r["effectivity"] for r in cylinder[-3:]]
    assert max(late) < 0.6 and f"effectivity {_span(late)} over the cylinder's last three steps" in text
    for run in (cylinder, sphere):
        assert run[-1]["pressure_estimate"] <= 0.001 < run[-1]["pressure_error"]
    stop = f"{100 * cylinder[-1]['pressure_error']:.3f} %"
    assert f"stops there at a true {stop}" in text and f"a 0.1 % target stops at {stop}" in readme
    assert f"({100 * sphere[-1]['pressure_error']:.3f} % on the sphere" in text
