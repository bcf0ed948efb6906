"""Two elastic bodies: the contact patch test, every method on the same QP, springs in series."""

import dataclasses

import numpy as np
import pytest
import scipy.sparse as sp

import signorini
from signorini.cli import main
from signorini.errors import InputError
from signorini.fem.two_bodies import Body
from signorini.scenes.two_block_patch import FAMILY, build, patch_pressure
from signorini.solvers.registry import get_method, methods

#: two materials, so that the blocks shorten by different amounts and slide against each other
MATERIALS = {"E1": 1.0, "nu1": 0.3, "E2": 3.0, "nu2": 0.2, "H2": 0.7}


def patch(**values):
    """The patch test's problem and its uniform pressure (the scene's units)."""
    params = {**MATERIALS, **values}
    return signorini.build_problem("two-block-patch", params=params), patch_pressure(FAMILY.parse(params))


def pressure_error(problem, method="pdas"):
    """The largest relative error of the nodal pressures λ / w against the uniform one."""
    result = signorini.solve(problem, method)
    assert result.converged, result.solution.message
    return result, result.comparison.pressure_max_rel


@pytest.mark.parametrize("discretisation", ["mortar", "mortar-standard"])
@pytest.mark.parametrize("mesh_ratio", [1.7, 1 / 1.7, 3.3, 1 / 3.3])
def test_mortar_passes_the_patch_test_on_non_matching_faces(discretisation, mesh_ratio):
    problem, p = patch(mesh_ratio=mesh_ratio, discretisation=discretisation)
    result, error = pressure_error(problem)
    assert result.comparison.pressure_ref == pytest.approx(p, rel=1e-14)
    np.testing.assert_allclose(result.pressure, p, rtol=1e-8)
    assert error < 1e-8
    assert result.comparison.force_balance < 1e-10


def test_node_to_segment_fails_the_patch_test():
    problem, _ = patch(mesh_ratio=1.7, discretisation="nts")
    _, error = pressure_error(problem)
    assert error > 1e-6, f"node-to-segment's pressure error {error:.3g}"
    matching, _ = patch(mesh_ratio=1.0, discretisation="nts")  # node to node: it passes
    assert pressure_error(matching)[1] < 1e-8


def test_the_pressure_parameter_sets_the_push_by_the_springs_in_series():
    problem, p = patch(p=0.02)
    assert p == 0.02
    assert pressure_error(problem)[1] < 1e-8
    assert problem.model.push.delta == pytest.approx(0.02 * (1.0 / (1 / 0.91) + 0.7 / (3.0 / 0.96)))
    with pytest.raises(InputError, match="delta and p"):
        signorini.build_problem("two-block-patch", params={"p": 0.02, "delta": 0.01})


@pytest.mark.parametrize("method", ["uzawa", "qp-osqp", "qp-clarabel", "condensed"])
def test_every_method_solves_the_two_body_qp_as_it_is(method):
    for module in get_method(method).requires:
        pytest.importorskip(module, reason=f"{method} needs the module {module!r}")
    problem, p = patch()
    reference = signorini.solve(problem, "pdas")
    result = signorini.solve(problem, method)
    assert result.converged, result.solution.message
    lam = reference.solution.lam
    assert np.abs(result.solution.lam - lam).max() < 1e-6 * np.abs(lam).max()
    np.testing.assert_allclose(result.pressure, p, rtol=1e-6)


def test_the_compliance_is_the_sum_of_the_two_bodies():
    problem, _ = patch(nx=4, ny=2)
    K, N = problem.K.toarray(), problem.N.toarray()
    upper_nodes = build(FAMILY.parse({**MATERIALS, "nx": 4, "ny": 2})).slave.mesh.p.shape[1]
    upper = problem.model.free_dofs < 2 * upper_nodes  # body 1's dofs come first
    W = N @ np.linalg.solve(K, N.T)
    parts = [N[:, body] @ np.linalg.solve(K[np.ix_(body, body)], N[:, body].T)
             for body in (upper, ~upper)]
    assert np.abs(K[np.ix_(upper, ~upper)]).max() == 0.0  # K = diag(K¹, K²)
    np.testing.assert_allclose(W, parts[0] + parts[1], rtol=1e-10, atol=1e-12 * np.abs(W).max())


def test_a_floating_body_is_refused():
    model = build(FAMILY.parse({}))
    loose = Body(mesh=model.master.mesh, E=1.0, nu=0.3, dirichlet=[model.master.dirichlet[1]],
                 contact_facets=model.master.contact_facets)  # its base held in y only
    with pytest.raises(InputError, match="master body floats"):
        dataclasses.replace(model, master=loose, length_scale=1.0).assemble()


def test_the_two_body_problem_has_one_mesh_of_both_bodies():
    problem, _ = patch(nx=4, ny=2, mesh_ratio=1.5)
    mesh = problem.model.mesh
    assert mesh.p.shape[1] == 5 * 3 + 7 * 3  # the lower and the upper grid
    assert problem.n + np.count_nonzero(problem.model.prescribed) <= 2 * mesh.p.shape[1]
    assert sp.issparse(problem.N) and problem.m == 7  # a row per node of the upper (slave) face


def test_the_cli_solves_the_patch_scene(capsys):
    assert main(["solve", "two-block-patch", "--set", "discretisation=nts"]) == 0
    assert "converged" in capsys.readouterr().out


def test_adaptive_refinement_refuses_two_bodies_in_one_line():
    with pytest.raises(InputError, match="of two bodies: .*mesh parameters"):
        signorini.solve_adaptive("two-block-patch", 0.01)


def test_methods_that_take_rows_as_bounds_refuse_two_bodies_in_one_line(capsys):
    problem, _ = patch()
    bounds = [m for m in methods() if m.bound_rows]
    assert bounds and not get_method("pdas").bound_rows  # pdas takes rows that share dofs
    for method in (m for m in bounds if m.installed):
        with pytest.raises(InputError, match=f"method '{method.name}' .*share dofs.*use pdas"):
            signorini.solve(problem, method.name)
    assert main(["solve", "two-block-patch", "--method", bounds[0].name]) == 2
    assert capsys.readouterr().err.count("\n") == 1
    main(["methods"])
    listed = {line.split()[0]: line for line in capsys.readouterr().out.splitlines()[1:]}
    assert all(("one body" in listed[m.name]) == m.bound_rows for m in methods())


def test_the_error_estimate_takes_each_body_s_own_material_and_no_pressure():
    from skfem import MeshTri

    from signorini.fem.two_bodies import series_modulus
    from signorini.scenes import hertz_two_cylinders as cylinders

    params = cylinders.FAMILY.parse({"n_contact": 12, "grading": 0.5, "E2": 5.0, "nu2": 0.2})
    result = signorini.solve(signorini.build_problem("hertz-two-cylinders", params=params), "pdas")
    estimate = result.estimate
    assert estimate.bodies == 2 and estimate.pressure is None and estimate.contact == 0.0
    # ‖u_h‖²_E = Σ u_bᵀ K_b u_b, each body's K assembled with its own material
    model, problem = cylinders.FAMILY.build(params), result.problem
    L, stress = problem.scales.length, series_modulus(1.0, 0.3, 5.0, 0.2)
    u = problem.model.expand(result.solution.u)
    first = 2 * model.slave.mesh.p.shape[1]
    energy = sum(part @ body.stiffness(MeshTri(body.mesh.p / L, body.mesh.t), stress) @ part
                 for body, part in ((model.slave, u[:first]), (model.master, u[first:])))
    assert estimate.energy_norm ** 2 == pytest.approx(energy, rel=1e-10)
    assert "contact pressure not estimated" in result.summary()


def test_the_vtu_holds_both_bodies_each_stressed_by_its_own_material(tmp_path):
    meshio = pytest.importorskip("meshio", reason="the VTU export writes through meshio")
    from signorini.output.export import export_vtk

    problem, p = patch()
    result = signorini.solve(problem, "pdas")
    mesh = meshio.read(export_vtk(problem, result.solution, tmp_path / "patch.vtu"))
    body = mesh.cell_data["body"][0]
    assert body.size == problem.model.mesh.t.shape[1] and set(body) == {1, 2}
    # uniaxial in each block: σ_yy = −p in both, σ_zz = ν σ_yy with the block's own ν
    np.testing.assert_allclose(mesh.cell_data["sigma_yy"][0], -p, rtol=1e-8)
    nu = np.where(body == 1, MATERIALS["nu2"], MATERIALS["nu1"])  # the upper block is the slave
    np.testing.assert_allclose(mesh.cell_data["sigma_zz"][0], -nu * p, rtol=1e-8)
    assert np.count_nonzero(mesh.point_data["contact_candidate"]) == problem.m


def test_a_picture_shows_both_deformed_bodies_and_the_pressure():
    pytest.importorskip("matplotlib", reason="the picture is drawn with matplotlib")
    from signorini.output.export import candidate_nodes, nodal_displacement
    from signorini.output.plots import deformed_bodies
    from signorini.references.pressure import contact_profile

    problem, p = patch()
    result = signorini.solve(problem, "pdas")
    body = np.repeat([1, 2], [material[0] for material in problem.model.materials])
    ax = deformed_bodies(problem.model.mesh.p * problem.scales.length, problem.model.mesh.t,
                         nodal_displacement(problem, result.solution), body,
                         candidate_nodes(problem), contact_profile(problem, result.solution).pressure)
    assert {t.get_text() for t in ax.get_legend().get_texts()} == {"body 1", "body 2"}
    (dots,) = ax.collections[-1:]
    np.testing.assert_allclose(dots.get_array(), p, rtol=1e-8)  # the uniform pressure, on the face
    assert len(ax.figure.axes) == 2  # and its colour bar
