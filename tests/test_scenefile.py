"""TOML scene files: family scenes, Gmsh meshes through meshio, and errors that say where."""

import dataclasses
import json
import re
from pathlib import Path

import meshio
import numpy as np
import pytest
from skfem import MeshTri

import signorini
from signorini.cli import main
from signorini.references.analytic import contact_modulus
from signorini.errors import InputError
from signorini.references.pressure import compare_uniform, contact_profile
from signorini.problem.contact import ReferenceData
from signorini.scenes import build_problem
from signorini.scenes.mesh_scene import read_mesh
from signorini.solvers.registry import solve

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"

FAMILY = """\
scene = "block"

[material]
E = 2.0
nu = 0.25

[mesh]
nx = 4
ny = 3
"""


def write(tmp_path, text, name="scene.toml"):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_family_file_builds_what_the_parameters_build(tmp_path):
    path = write(tmp_path, FAMILY)
    from_file = signorini.at_load(build_problem(str(path)))
    direct = signorini.at_load(build_problem("block", params={"E": 2.0, "nu": 0.25, "nx": 4, "ny": 3}))
    assert from_file.name == "block"
    assert from_file.model.params == direct.model.params
    assert abs(from_file.K - direct.K).max() == 0.0
    # --set overrides a value of the file
    finer = signorini.at_load(build_problem(str(path), params={"nx": "8"}))
    assert finer.model.params["nx"] == 8


def line_of(text, needle):
    return next(i for i, line in enumerate(text.splitlines(), start=1) if needle in line)


def test_syntax_error_names_the_line(tmp_path):
    text = FAMILY.replace("nu = 0.25", "nu = = 0.25")
    with pytest.raises(InputError, match=rf"line {line_of(text, 'nu = =')}\b"):
        signorini.at_load(build_problem(str(write(tmp_path, text))))


@pytest.mark.parametrize("bad, needle, key", [
    ('E = "stiff"', 'E = "stiff"', "E"),
    ("E = -1.0", "E = -1.0", "E"),
    ("nu = 0.5", "nu = 0.5", "nu"),
])
def test_bad_value_names_table_key_and_line(tmp_path, bad, needle, key):
    text = FAMILY.replace(f"{key} = 2.0" if key == "E" else "nu = 0.25", bad)
    with pytest.raises(InputError) as info:
        signorini.at_load(build_problem(str(write(tmp_path, text))))
    message = str(info.value)
    assert f"[material] {key}" in message
    assert f"line {line_of(text, needle)}" in message


def test_unknown_key_lists_the_parameters(tmp_path):
    text = FAMILY.replace("ny = 3", "ny = 3\nradius = 2.0")
    with pytest.raises(InputError, match=r"\[mesh\] radius.*no parameter 'radius'.*nx, ny") as info:
        signorini.at_load(build_problem(str(write(tmp_path, text))))
    assert f"line {line_of(text, 'radius')}" in str(info.value)


def test_a_parameter_set_twice_is_an_error(tmp_path):
    text = FAMILY + "\n[params]\nE = 3.0\n"
    with pytest.raises(InputError, match="set twice"):
        signorini.at_load(build_problem(str(write(tmp_path, text))))


def test_unknown_family_and_missing_file(tmp_path):
    with pytest.raises(InputError, match="'ball' is not a scene family.*hertz-cylinder"):
        signorini.at_load(build_problem(str(write(tmp_path, 'scene = "ball"\n'))))
    with pytest.raises(InputError, match="does not exist"):
        signorini.at_load(build_problem(str(tmp_path / "nothing.toml")))
    with pytest.raises(InputError, match=r"scene = .*\[mesh\]"):
        signorini.at_load(build_problem(str(write(tmp_path, "[material]\nE = 1.0\n"))))


# --- mesh scenes -----------------------------------------------------------------------------


def write_block_msh(path, n=4, extra_point=True):
    """A unit square of triangles with line groups bottom, top, symmetry (Gmsh 2.2 via meshio)."""
    m = MeshTri.init_tensor(np.linspace(0, 1, n + 1), np.linspace(0, 1, n + 1))
    p = m.p.T
    lines, tags = [], []
    for a, b in m.facets[:, m.boundary_facets()].T:
        for tag, axis, value in ((1, 1, 0.0), (2, 1, 1.0), (3, 0, 0.0)):
            if abs(p[a, axis] - value) < 1e-12 and abs(p[b, axis] - value) < 1e-12:
                lines.append([a, b])
                tags.append(tag)
    points = np.column_stack([p, np.zeros(len(p))])
    if extra_point:  # a geometry point no triangle uses, as Gmsh writes them
        points = np.vstack([points, [5.0, 5.0, 0.0]])
    mesh = meshio.Mesh(points, [("line", np.array(lines)), ("triangle", m.t.T)],
                       cell_data={"gmsh:physical": [np.array(tags), np.full(m.t.shape[1], 9)],
                                  "gmsh:geometrical": [np.array(tags), np.full(m.t.shape[1], 9)]},
                       field_data={"bottom": np.array([1, 1]), "top": np.array([2, 1]),
                                   "symmetry": np.array([3, 1]), "body": np.array([9, 2])})
    meshio.write(path, mesh, file_format="gmsh22", binary=False)
    return path


MESH_SCENE = """\
[mesh]
file = "block.msh"

[material]
E = 4.0
nu = 0.3

[[dirichlet]]
boundary = "symmetry"
component = "x"
value = 0.0

[[dirichlet]]
boundary = "top"
component = "y"
value = -0.02

[contact]
boundary = "bottom"

[obstacle]
type = "flat"

[load]
boundary = "top"
component = "y"
multiplicity = 2.0
"""


def test_gmsh_mesh_is_read_with_named_boundaries(tmp_path):
    info = read_mesh(write_block_msh(tmp_path / "block.msh"))
    assert info.mesh.p.shape == (2, 25)  # the unused geometry point is dropped
    assert set(info.boundaries) == {"bottom", "top", "symmetry"}
    assert all(len(f) == 4 for f in info.boundaries.values())


def test_mesh_scene_passes_the_patch_test(tmp_path):
    write_block_msh(tmp_path / "block.msh")
    problem = signorini.at_load(build_problem(str(write(tmp_path, MESH_SCENE))))
    solution = solve(problem, "pdas", tol=1e-10)
    assert problem.name.startswith("file:")
    # what compare_uniform reads, which a mesh scene does not name: E*, the height and the push
    E_star = contact_modulus(problem.model.E, problem.model.nu)
    problem = problem.with_data(reference=ReferenceData("uniform", E_star=E_star, H=1.0),
                                push=dataclasses.replace(problem.model.push, delta=0.02))
    assert compare_uniform(problem, solution).pressure_max_rel < 1e-10
    assert contact_profile(problem, solution).total_force == pytest.approx(
        2 * 4.0 / (1 - 0.09) * 0.02, rel=1e-10)


def test_mesh_scene_with_line_selectors_a_target_load_and_a_circle(tmp_path):
    write_block_msh(tmp_path / "block.msh")
    text = (MESH_SCENE.replace('boundary = "bottom"', "boundary = {y = 0.0}")
            .replace('type = "flat"', 'type = "circle"\ncentre = [0.0, -10.0]\nradius = 10.0')
            .replace("multiplicity = 2.0", "multiplicity = 2.0\ntarget = 0.05"))
    problem = signorini.at_load(build_problem(str(write(tmp_path, text))))
    solution = solve(problem, "pdas", tol=1e-10)
    from signorini.references.pressure import load_resultant
    assert problem.m == 5
    # the target is the load applied: the contact resultant along the push, not Σλ (tilted normals)
    assert load_resultant(problem, solution.lam) == pytest.approx(0.05, rel=1e-8)
    assert contact_profile(problem, solution).applied_load == pytest.approx(0.05, rel=1e-8)
    assert contact_profile(problem, solution).total_force > 0.05


@pytest.mark.parametrize("change, pattern", [
    (('boundary = "bottom"', 'boundary = "floor"'),
     r"\[contact\] boundary: no boundary 'floor' in the mesh: its named boundaries are bottom, symmetry, top"),
    (('component = "x"', 'component = "z"'), r"\[dirichlet\] component: must be \"x\" or \"y\""),
    (('type = "flat"', 'type = "sphere"'), r"\[obstacle\] type: must be one of flat"),
    (('file = "block.msh"', 'file = "missing.msh"'), r"\[mesh\] file: mesh file .*missing.msh does not exist"),
    (("E = 4.0", "E = 0.0"), r"\[material\] E: must be > 0"),
    (("nu = 0.3", "nu = 0.3\ncolour = 1"), r"\[material\] colour: unknown key"),
])
def test_mesh_scene_errors_say_where(tmp_path, change, pattern):
    write_block_msh(tmp_path / "block.msh")
    text = MESH_SCENE.replace(*change)
    with pytest.raises(InputError, match=pattern) as info:
        signorini.at_load(build_problem(str(write(tmp_path, text))))
    assert re.search(r"line \d+", str(info.value))


def test_second_dirichlet_table_is_located(tmp_path):
    write_block_msh(tmp_path / "block.msh")
    text = MESH_SCENE.replace("value = -0.02", 'value = "down"')
    with pytest.raises(InputError) as info:
        signorini.at_load(build_problem(str(write(tmp_path, text))))
    line = line_of(text, 'value = "down"')
    assert f"line {line}" in str(info.value) and "[dirichlet] value" in str(info.value)


def test_meshes_without_triangles_or_out_of_plane_are_refused(tmp_path):
    lines_only = meshio.Mesh(np.array([[0.0, 0, 0], [1, 0, 0]]), [("line", np.array([[0, 1]]))])
    meshio.write(tmp_path / "lines.msh", lines_only, file_format="gmsh22", binary=False)
    with pytest.raises(InputError, match="no triangles"):
        read_mesh(tmp_path / "lines.msh")
    tilted = meshio.Mesh(np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 1.0]]), [("triangle", np.array([[0, 1, 2]]))])
    meshio.write(tmp_path / "tilted.msh", tilted, file_format="gmsh22", binary=False)
    with pytest.raises(InputError, match="not planar"):
        read_mesh(tmp_path / "tilted.msh")


# --- the command line and the examples ---------------------------------------------------------


def test_cli_solves_a_scene_file_and_reports_errors_in_one_line(tmp_path, capsys):
    path = write(tmp_path, FAMILY)
    assert main(["solve", str(path), "--json", str(tmp_path / "r.json")]) == 0
    assert json.loads((tmp_path / "r.json").read_text())["scene"] == "block"
    capsys.readouterr()
    bad = write(tmp_path, FAMILY.replace("nx = 4", "nx = 4.5"), "bad.toml")
    assert main(["solve", str(bad), "--json", str(tmp_path / "bad.json")]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "[mesh] nx" in err and "line" in err
    assert not (tmp_path / "bad.json").exists()


@pytest.mark.parametrize("example, overrides", [
    ("hertz-cylinder.toml", {"n_contact": 16, "grading": 0.4}),
    ("punch.toml", {"n_contact": 16}),
    ("reverse-hertz.toml", {"n_contact": 16}),
    ("block-mesh.toml", {}),
])
def test_examples_build_and_solve(example, overrides):
    problem = signorini.at_load(build_problem(str(EXAMPLES / example), params=overrides))
    assert solve(problem, "pdas", tol=1e-9).status == "converged"
