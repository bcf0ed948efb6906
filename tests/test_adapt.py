"""Adaptive refinement (signorini.scenes.adapt): solve, estimate, mark, refine, until the target."""

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from skfem import MeshTri

import signorini
from signorini.errors import InputError
from signorini.scenes.adapt import parse_target
from signorini.scenes.marking import contact_weights, dorfler
from signorini.scenes.families import get_scene
from signorini.scenes.meshing import graded_quarter_disc, quarter_disc_on


def test_dorfler_marks_the_fewest_elements_that_carry_the_fraction():
    assert list(dorfler(np.array([1.0, 3.0, 1.0, 1.0]), 0.5)) == [1]
    two = dorfler(np.array([1.0, 3.0, 1.0, 1.0]), 0.8)  # 9 + 1 ≥ 0.8 · 12; the ones tie
    assert len(two) == 2 and 1 in two
    assert len(dorfler(np.ones(10), 1.0)) == 10


@pytest.mark.parametrize("value, expected", [("0.1%", 0.001), (0.001, 0.001), ("2e-3", 0.002)])
def test_targets_are_fractions_or_percentages(value, expected):
    assert parse_target(value) == pytest.approx(expected)


@pytest.mark.parametrize("value", ["abc", "150%", 0, -0.1, 2])
def test_bad_targets_are_input_errors(value):
    with pytest.raises(InputError):
        parse_target(value)


def test_the_bulk_weight_is_one_near_the_contact_and_falls_as_the_distance_squared():
    mesh = MeshTri.init_tensor(np.linspace(0.0, 8.0, 33), np.linspace(0.0, 8.0, 33))
    zone = np.nonzero((mesh.p[1] == 0.0) & (mesh.p[0] <= 1.0))[0]  # extent 1
    weights = contact_weights(mesh, zone)
    centroids = mesh.p[:, mesh.t].mean(axis=1)
    distance = np.min(np.linalg.norm(centroids[:, :, None] - mesh.p[:, zone][:, None, :], axis=0), axis=1)
    assert np.all(weights[distance <= 1.0] == 1.0)
    far = distance > 1.0
    assert weights[far] == pytest.approx(distance[far] ** -2.0)
    assert np.all(contact_weights(mesh, np.zeros(0, dtype=int)) == 1.0)


def test_the_quarter_disc_is_found_again_on_its_own_mesh():
    disc = graded_quarter_disc(0.01, 0.05, 16, 0.2, 1, 2.0)
    again = quarter_disc_on(disc.mesh, 0.01, 0.05, 2.0)
    for part in ("candidates", "contact_facets", "axis", "top", "top_facets"):
        assert np.array_equal(np.sort(getattr(disc, part)), np.sort(getattr(again, part)))


@pytest.mark.slow
def test_the_cylinder_refines_until_the_energy_target():
    result = signorini.solve_adaptive("hertz-cylinder", "2%", target_on="energy")
    steps = result.solution.extras["adaptive"]
    assert result.status == "converged" and "target energy-norm error 2 % met" in result.message
    assert result.target_met is True and signorini.solve("hertz-cylinder").target_met is None
    assert result.estimate.relative <= 0.02 and result.problem.n < 30_000
    estimates = [s["estimate"] for s in steps]
    assert all(later < earlier for earlier, later in zip(estimates, estimates[1:]))
    assert steps[-1]["action"] == "target met" and steps[-1]["dofs"] == result.problem.n
    # the refined arc nodes lie on the cylinder (radius R = 1 about (0, 1))
    mesh = result.problem.model.mesh
    boundary = mesh.boundary_nodes()
    x, y = mesh.p[:, boundary]
    arc = (x > 1e-9) & (y < 1 - 1e-9)
    assert np.max(np.abs(np.hypot(x[arc], y[arc] - 1.0) - 1.0)) < 1e-12
    assert abs(result.hertz.p0_rel) < 2e-3 and abs(result.hertz.a_rel) < 2e-3


@pytest.mark.slow
def test_the_dof_limit_stops_the_loop_and_says_so():
    result = signorini.solve_adaptive("hertz-sphere", 0.001, max_dofs=10_000)
    assert result.status == "converged"
    assert "max dofs 10000 reached" in result.message and result.target_met is False
    assert result.problem.n <= 10_000 and result.estimate.pressure.relative > 0.001


@pytest.mark.slow
def test_the_candidates_grow_with_the_contact():
    """Pushed much further than the default a/R = 0.05: the contact outgrows the candidates."""
    result = signorini.solve_adaptive("hertz-cylinder", 0.05, params={"delta": 0.02})
    actions = [s["action"] for s in result.solution.extras["adaptive"]]
    assert actions[0] == "candidates widened"
    assert result.status == "converged"
    assert result.to_dict()["adequacy"]["penetrating_nodes"] == 0
    assert abs(result.hertz.a_rel) < 0.01


def test_what_cannot_be_refined_says_so():
    with pytest.raises(InputError, match="is 3D: .*refine=N"):
        signorini.solve_adaptive("hertz-sphere-3d", 0.01)
    problem = signorini.build_problem("hertz-cylinder")
    with pytest.raises(InputError, match="by name"):
        signorini.solve_adaptive(problem, 0.01)
    with pytest.raises(InputError, match="solve_adaptive"):
        signorini.solve("hertz-cylinder", max_dofs=1000)
    with pytest.raises(InputError, match="solve_adaptive"):
        signorini.solve("hertz-cylinder", target_on="pressure")
    with pytest.raises(InputError, match="target quantity"):
        signorini.solve_adaptive("hertz-cylinder", 0.01, target_on="stress")


#: issue 15's done-when on the default Hertz scenes (a/R = 0.05), ν from 0 to 0.45: the pressure
#: target met within these dofs. Hertz's p₀ and a are then held within the target on the cylinder;
#: the sphere's p₀ carries the finite body's difference to Hertz's half-space (docs/accuracy.md:
#: about −0.14 % at ν = 0.3, −0.87 % at ν = 0), which no mesh removes: it is held to that.
DONE_WHEN = [("0.3%", 20_000), ("0.1%", 60_000)]
SPHERE_FROM_HERTZ = {0.0: (0.005, 0.009), 0.3: (0.001, 0.0016), 0.45: (0.001, 0.001)}


@pytest.mark.slow
@pytest.mark.parametrize("target, dofs", DONE_WHEN)
@pytest.mark.parametrize("nu", [0.0, 0.3, 0.45])
@pytest.mark.parametrize("scene", ["hertz-cylinder", "hertz-sphere"])
def test_the_pressure_target_is_met_within_its_dofs(scene, nu, target, dofs):
    result = signorini.solve_adaptive(scene, target, params={"nu": nu})
    assert result.status == "converged" and f"target pressure error {target[:-1]} % met" in result.message
    assert result.problem.n <= dofs
    assert result.estimate.pressure.relative <= float(target[:-1]) / 100
    a_within, p0_within = ((float(target[:-1]) / 100,) * 2 if scene == "hertz-cylinder"
                           else SPHERE_FROM_HERTZ[nu])
    assert abs(result.hertz.a_rel) <= a_within and abs(result.hertz.p0_rel) <= p0_within


@pytest.mark.slow
def test_the_pressure_target_does_not_depend_on_the_units():
    default = signorini.solve_adaptive("hertz-cylinder", "0.3%")
    aluminium = signorini.solve_adaptive("hertz-cylinder", "0.3%",
                                params={"E": 70e9, "R": 25.0})
    assert aluminium.problem.n == default.problem.n
    assert aluminium.hertz.p0_rel == pytest.approx(default.hertz.p0_rel, abs=1e-6)
    assert aluminium.estimate.pressure.relative == pytest.approx(default.estimate.pressure.relative,
                                                                 rel=1e-6)


@pytest.mark.slow
def test_a_harder_push_ends_converged_within_its_target():
    """`signorini solve hertz-cylinder --set delta=0.02 --target-error 0.5%` (issue 15)."""
    result = signorini.solve_adaptive("hertz-cylinder", "0.5%", params={"delta": 0.02})
    assert result.status == "converged" and "target pressure error 0.5 % met" in result.message
    assert result.to_dict()["adequacy"]["penetrating_nodes"] == 0
    assert abs(result.hertz.a_rel) <= 0.005 and abs(result.hertz.p0_rel) <= 0.005


@pytest.mark.slow
def test_the_adaptive_families_take_a_mesh():
    for name in ("hertz-cylinder", "hertz-sphere"):
        family = get_scene(name)
        model = family.build(family.parse({}), set())
        again = family.build(family.parse({}), set(), mesh=model.mesh)
        assert np.array_equal(model.contact_nodes, again.contact_nodes)


@pytest.mark.slow
def test_the_command_line_refines_and_reports(tmp_path):
    out = tmp_path / "adaptive.json"
    run = subprocess.run([sys.executable, "-m", "signorini.cli", "solve", "hertz-cylinder",
                          "--target-error", "3%", "--json", str(out)], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    record = json.loads(out.read_text())
    assert record["estimate"]["pressure"] <= 0.03
    assert record["extras"]["adaptive"][-1]["action"] == "target met"
    shown = subprocess.run([sys.executable, "-m", "signorini.cli", "solve", "hertz-cylinder",
                            "--target-error", "0.5%"], capture_output=True, text=True)
    steps = [line for line in shown.stdout.splitlines() if line.startswith("    step ")]
    assert shown.returncode == 0 and "adaptive refinement, " in shown.stdout
    assert len(steps) >= 2 and steps[-1].endswith("target met") and steps[0].endswith("refined")
    assert record["extras"]["target_met"] is True and record["extras"]["target_error"] == 0.03
    short = tmp_path / "short.json"
    missed = subprocess.run([sys.executable, "-m", "signorini.cli", "solve", "hertz-cylinder",
                             "--target-error", "0.01%", "--max-dofs", "8000", "--json", str(short)],
                            capture_output=True, text=True)
    assert missed.returncode == 1 and "target error was not met (max dofs)" in missed.stderr
    record = json.loads(short.read_text())
    assert record["status"] == "converged" and record["extras"]["target_met"] is False
    assert record["estimate"]["pressure"] > 1e-4 and record["dofs"] <= 8000
    bad = subprocess.run([sys.executable, "-m", "signorini.cli", "solve", "hertz-cylinder",
                          "--max-dofs", "1000"], capture_output=True, text=True)
    assert bad.returncode == 2 and "--target-error" in bad.stderr


EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


@pytest.mark.parametrize("scene", ["reverse-hertz", str(EXAMPLES / "reverse-hertz.toml")])
def test_a_scene_without_its_own_mesh_builder_is_carried_onto_each_refinement(scene):
    """reverse-hertz (a block on a rigid cylinder) has no build(mesh=): the loop carries its model
    (candidates, prescribed displacements, load dofs) onto each refined mesh."""
    result = signorini.solve_adaptive(scene, "0.2%")
    steps = result.solution.extras["adaptive"]
    assert result.status == "converged" and "target pressure error 0.2 % met" in result.message
    assert len(steps) >= 3 and steps[-1]["dofs"] > steps[0]["dofs"]
    assert steps[-1]["candidates"] > steps[0]["candidates"]  # new bottom nodes became candidates
    assert abs(result.hertz.a_rel) < 0.01 and abs(result.hertz.p0_rel) < 0.01
    assert result.to_dict()["adequacy"]["penetrating_nodes"] == 0


def test_a_mesh_scene_file_refines_and_stays_a_patch_test():
    """The block from a Gmsh file: uniform pressure, exact in P1, on every refined mesh. Its
    estimate is zero, so the loop stops at once; the carried model is solved on a refinement of
    half the elements here, which the loop would make."""
    from signorini.fem.assembly import assemble
    from signorini.fem.transfer import refined_model
    from signorini.scenes.scenefile import build_scene_model
    from signorini.solvers.registry import solve as solve_problem

    result = signorini.solve_adaptive(str(EXAMPLES / "block-mesh.toml"), "1%", target_on="energy")
    assert result.status == "converged"
    assert result.estimate.pressure.relative < 1e-10
    pressure = result.pressure[result.active]
    assert np.ptp(pressure) < 1e-9 * pressure.mean()
    _, model = build_scene_model(str(EXAMPLES / "block-mesh.toml"))
    mesh = model.mesh.refined(np.arange(0, model.mesh.t.shape[1], 2))
    carried = refined_model(model, mesh)
    assert len(carried.contact_nodes) > len(model.contact_nodes)
    problem = assemble(carried)
    solution = solve_problem(problem, "pdas")
    pressure = solution.lam / problem.weights
    assert solution.status == "converged" and np.ptp(pressure) < 1e-9 * pressure.mean()


def test_the_carried_model_has_the_refined_boundary_sets():
    from signorini.fem.transfer import refined_model
    model = get_scene("reverse-hertz").build(get_scene("reverse-hertz").parse({}))
    mesh = model.mesh.refined(np.arange(model.mesh.t.shape[1]))  # every element: every edge split
    carried = refined_model(model, mesh)
    x = mesh.p[0]
    for (c, before, value), (c2, after, value2) in zip(model.dirichlet, carried.dirichlet):
        assert (c, value) == (c2, value2) and len(after) == 2 * len(before) - 1
        assert np.ptp(mesh.p[1 - c, after]) == pytest.approx(np.ptp(mesh.p[1 - c, before]))
    assert len(carried.contact_nodes) == 2 * len(model.contact_nodes) - 1
    assert np.all(np.diff(x[carried.contact_nodes]) > 0)  # still sorted along x
    assert carried.obstacle.normals_and_gaps(mesh.p[:, carried.contact_nodes].T)[1].shape == \
        (len(carried.contact_nodes),)


def test_a_sharp_punch_grows_its_candidates_around_the_corner():
    """Refined near a sharp corner, the bottom just beyond it goes into the punch (the linear
    solution moves it sideways by more than its distance to the corner): the loop makes those
    nodes candidates and goes on; the energy target is met, the pressure's is not meaningful."""
    result = signorini.solve_adaptive("punch", "2%", target_on="energy")
    actions = [s["action"] for s in result.solution.extras["adaptive"]]
    assert result.status == "converged" and "candidates widened" in actions
    assert result.estimate.relative <= 0.02
    assert result.to_dict()["adequacy"]["penetrating_nodes"] == 0
    beyond = result.problem.contact_points[:, 0] > float(result.problem.model.params["a"]) * (1 + 1e-9)
    assert beyond.any() and np.any(result.solution.lam[beyond] > 0)


def test_a_steeper_start_than_measured_is_warned():
    steep = signorini.solve_adaptive("hertz-cylinder", "1%", params={"grading": 0.3})
    assert "warning: the mesh started graded at 0.3" in steep.message
    default = signorini.solve_adaptive("hertz-cylinder", "1%")
    assert "warning" not in default.message
