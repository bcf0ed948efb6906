"""VTK export: what meshio reads back, the stresses of a patch test, and files written whole."""

import meshio
import numpy as np
import pytest
from skfem import MeshTet, MeshTri

from signorini.cli import main
from signorini.errors import InputError
from signorini.output.export import element_gradients, export_vtk, project_to_nodes, von_mises
from signorini.references.pressure import contact_profile
from signorini.problem.contact import ContactSolution
from signorini.scenes import build_problem
from signorini.solvers.registry import solve

POINT_DATA = {"displacement", "von_mises_nodal", "sigma_yy_nodal", "gap", "pressure", "contact_force",
              "contact_candidate"}
CELL_DATA = {"von_mises", "sigma_xx", "sigma_yy", "sigma_zz", "sigma_xy"}


@pytest.fixture(scope="module")
def block():
    problem = build_problem("block", params={"nx": 4, "ny": 4, "E": 70e9, "nu": 0.3, "delta": 1e-3,
                                             "H": 2.0, "W": 1.5})
    return problem, solve(problem, "pdas", tol=1e-10)


@pytest.mark.parametrize("suffix", [".vtu", ".vtk"])
def test_file_reads_back_with_the_named_data(block, tmp_path, suffix):
    problem, solution = block
    path = export_vtk(problem, solution, tmp_path / f"block{suffix}")
    mesh = meshio.read(path)
    assert POINT_DATA <= set(mesh.point_data)
    assert CELL_DATA <= set(mesh.cell_data)
    assert not set(mesh.point_data) & set(mesh.cell_data)  # each array listed once in ParaView
    assert mesh.cells[0].type == "triangle" and len(mesh.cells[0].data) == problem.model.mesh.t.shape[1]
    assert mesh.point_data["displacement"].shape == (problem.model.mesh.p.shape[1], 3)


def test_patch_test_stresses_and_contact_fields(block, tmp_path):
    """Uniaxial plane strain: σ_yy = −E*δ/H everywhere, σ_xx = 0, σ_zz = ν σ_yy."""
    problem, solution = block
    mesh = meshio.read(export_vtk(problem, solution, tmp_path / "block.vtu"))
    p = 70e9 / (1 - 0.09) * 1e-3 / 2.0
    np.testing.assert_allclose(mesh.cell_data["sigma_yy"][0], -p, rtol=1e-9)
    np.testing.assert_allclose(mesh.point_data["sigma_yy_nodal"], -p, rtol=1e-9)
    np.testing.assert_allclose(mesh.cell_data["sigma_xx"][0], 0.0, atol=1e-9 * p)
    np.testing.assert_allclose(mesh.cell_data["sigma_zz"][0], -0.3 * p, rtol=1e-9)
    np.testing.assert_allclose(mesh.cell_data["von_mises"][0], p * np.sqrt(1 - 0.3 + 0.09), rtol=1e-9)
    # the undeformed points (physical units): Warp By Vector adds the displacement once
    reference = problem.model.mesh.p.T * problem.scales.length
    np.testing.assert_allclose(mesh.points[:, :2], reference, atol=1e-12)
    assert mesh.point_data["displacement"][:, 1].min() == pytest.approx(-1e-3)
    # gap and pressure at the candidates; NaN / zero elsewhere
    profile = contact_profile(problem, solution)
    marked = mesh.point_data["contact_candidate"] == 1
    assert marked.sum() == problem.m
    np.testing.assert_allclose(np.sort(mesh.point_data["pressure"][marked]), np.sort(profile.pressure))
    assert np.all(np.isnan(mesh.point_data["gap"][~marked]))
    assert np.all(mesh.point_data["pressure"][~marked] == 0)


def test_deformed_points_when_asked(block, tmp_path):
    problem, solution = block
    from signorini.output.export import export_mesh
    mesh = export_mesh(problem, solution, deformed=True)
    np.testing.assert_allclose(mesh.points[:, :2] - mesh.point_data["displacement"][:, :2],
                               problem.model.mesh.p.T * problem.scales.length, atol=1e-12)
    assert np.abs(mesh.point_data["displacement"]).max() > 0


@pytest.mark.parametrize("mesh", [MeshTri.init_sqsymmetric().refined(1), MeshTet().refined(1)])
def test_gradients_of_linear_fields_are_exact(mesh):
    rng = np.random.default_rng(3)
    dim = mesh.p.shape[0]
    A = rng.standard_normal((dim, dim))
    values = (A @ mesh.p).T + rng.standard_normal(dim)
    grad = element_gradients(mesh.p, mesh.t, values)
    np.testing.assert_allclose(grad, np.broadcast_to(A, grad.shape), atol=1e-12)
    # a constant projects to itself
    np.testing.assert_allclose(project_to_nodes(mesh.p, mesh.t, np.full(mesh.t.shape[1], 2.5)), 2.5)


def test_von_mises_of_pure_shear_and_hydrostatic_stress():
    shear = np.zeros((1, 3, 3))
    shear[0, 0, 1] = shear[0, 1, 0] = 2.0
    assert von_mises(shear)[0] == pytest.approx(2.0 * np.sqrt(3.0))
    assert von_mises(np.eye(3)[None] * -5.0)[0] == pytest.approx(0.0)


def test_export_writes_whole_files_or_nothing(block, tmp_path):
    problem, solution = block
    target = tmp_path / "result.vtu"
    target.write_text("previous result")
    failed = ContactSolution.failure("pdas", problem, "failed", "no answer")
    with pytest.raises(InputError, match="no finite answer"):
        export_vtk(problem, failed, target)
    assert target.read_text() == "previous result"
    assert [p.name for p in tmp_path.iterdir()] == ["result.vtu"]  # no temporary left behind
    with pytest.raises(InputError, match=r"\.vtu or \.vtk"):
        export_vtk(problem, solution, tmp_path / "result.txt")
    with pytest.raises(InputError, match="does not exist"):
        export_vtk(problem, solution, tmp_path / "missing" / "result.vtu")


def test_cli_vtk_option(tmp_path, capsys):
    path = tmp_path / "punch.vtu"
    assert main(["solve", "punch", "--set", "n_contact=8", "--vtk", str(path)]) == 0
    mesh = meshio.read(path)
    assert mesh.point_data["pressure"].max() > 0
    capsys.readouterr()
    # a bad export path fails before the solve, in one line, exit 2
    assert main(["solve", "punch", "--vtk", str(tmp_path / "punch.png")]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and ".vtu or .vtk" in err
