"""The size guard holds wherever a mesh is made: at every adaptive step, and with estimates that
bound the meshes the families build from above (signorini.scenes.size)."""

import pytest

import signorini
import signorini.scenes.adapt as adapt
from signorini.errors import InputError
from signorini.scenes.families import get_scene
from signorini.scenes.size import MEMORY_VARIABLE, bytes_per_dof, check_size, estimate_dofs


def test_the_memory_limit_stops_the_adaptive_loop_before_a_mesh_beyond_it_is_assembled(monkeypatch):
    limit_gb = 0.1
    fits = limit_gb * 1e9 / bytes_per_dof(2, 0, {})  # 25,000 dofs at 4 kB a dof
    assembled = []

    def counting(model, *args, **kwargs):
        assembled.append(model.mesh.p.size)
        return assemble(model, *args, **kwargs)

    assemble = adapt.assemble
    monkeypatch.setattr(adapt, "assemble", counting)
    monkeypatch.setenv(MEMORY_VARIABLE, str(limit_gb))
    result = signorini.solve_adaptive("hertz-cylinder", "0.0001%", max_dofs=10 ** 9)
    steps = result.solution.extras["adaptive"]
    assert len(assembled) >= 3 and max(assembled) <= fits, assembled
    assert steps[-1]["action"] == "memory limit" and result.problem.model.mesh.p.size == assembled[-1]
    assert f"memory limit of {limit_gb:.1f} GB ({MEMORY_VARIABLE}" in result.message, result.message
    assert "> target 0.0001 %" in result.message
    next_dofs = int(result.message.split("the next mesh has ")[1].split()[0])
    assert next_dofs > fits
    assert result.status == "converged" and result.estimate.pressure.relative > 1e-6


# meshes quick to build (a second or so each); the finer ones take 10 s to a minute
GRADED = [
    ("hertz-sphere-3d", {"grading": 0.2}), ("hertz-sphere-3d", {"grading": 1.0}),
    ("hertz-sphere-3d", {"grading": 2.0}), ("hertz-sphere-3d", {}),
    ("hertz-sphere-3d", {"n_contact": 3}), ("hertz-sphere-3d", {"n_contact": 5, "grading": 0.1}),
    ("hertz-sphere-3d", {"refine": 1}), ("hertz-sphere-3d", {"refine": 1, "grading": 1.0}),
    ("hertz-sphere-3d", {"refine": 1, "grading": 2.0}),
    ("hertz-sphere-3d", {"refine": 1, "n_contact": 3}),
    ("hertz-sphere-3d", {"a_over_R": 0.2}), ("hertz-sphere-3d", {"a_over_R": 0.01}),
    *[(family, {"grading": g}) for family in ("hertz-cylinder", "hertz-sphere", "punch", "reverse-hertz")
      for g in (0.1, 0.3, 0.6, 1.0, 2.0)],
    *[(family, {"grading": 0.1, "n_contact": 10}) for family in ("hertz-cylinder", "hertz-sphere", "punch",
                                                                "reverse-hertz")],
    ("punch", {"half": 0}), ("punch", {"size": 200}),
    # the relaxed mesher at the sizes its model was measured on (Triangle's are the default now)
    *[(family, {"grading": g, "mesher": "relaxed", "n_contact": n})
      for family, n in (("hertz-cylinder", 40), ("hertz-sphere", 60)) for g in (0.1, 0.3, 0.6, 1.0, 2.0)],
]
#: Triangle's Hertz discs follow the grading less regularly than the relaxed ones: the size model
#: (the relaxed meshes' times TRIANGLE_DOFS) bounds them from above within this factor, not 1.3
TRIANGLE_OVER = 1.8
SLOW = [
    ("hertz-sphere-3d", {"grading": 0.05}), ("hertz-sphere-3d", {"grading": 0.1}),
    ("hertz-sphere-3d", {"refine": 1, "grading": 0.2}),
    ("hertz-sphere-3d", {"refine": 1, "grading": 0.1, "n_contact": 5}),
    *[(family, {"grading": 0.05}) for family in ("hertz-cylinder", "hertz-sphere", "punch", "reverse-hertz")],
]


def over(family, values, tight):
    """How far above the mesh built the estimate may be."""
    triangle = family in ("hertz-cylinder", "hertz-sphere") and values.get("mesher", "triangle") == "triangle"
    return max(tight, TRIANGLE_OVER) if triangle else tight


def _built_and_estimated(family, values):
    scene = get_scene(family)
    params = scene.parse(values)
    return scene.build(params, set(values)).mesh.p.size, estimate_dofs(family, params)[0]


@pytest.mark.parametrize("family, values", GRADED, ids=[f"{f}-{v}" for f, v in GRADED])
def test_the_estimate_bounds_the_graded_mesh_built_from_above(family, values):
    built, estimate = _built_and_estimated(family, values)
    assert built <= estimate <= over(family, values, 1.3) * built, (estimate, built)


@pytest.mark.slow
@pytest.mark.parametrize("family, values", SLOW, ids=[f"{f}-{v}" for f, v in SLOW])
def test_the_estimate_bounds_the_finely_graded_meshes_built_from_above(family, values):
    built, estimate = _built_and_estimated(family, values)
    assert built <= estimate <= over(family, values, 1.3) * built, (estimate, built)


def test_the_sphere_refused_at_one_gb_for_its_grading_is_sized_over_what_it_builds(monkeypatch):
    """grading=0.05 builds 433,245 dofs; it was estimated at 199,717 and let through at 1 GB."""
    monkeypatch.setenv(MEMORY_VARIABLE, "1")
    params = get_scene("hertz-sphere-3d").parse({"grading": 0.05})
    assert estimate_dofs("hertz-sphere-3d", params)[0] >= 433_245
    with pytest.raises(InputError, match="over the limit of 1.0 GB"):
        check_size("hertz-sphere-3d", params)


@pytest.mark.parametrize("family, values", [
    ("hertz-sphere-3d", {"delta": 1e-5}),  # a/R 0.003: the estimate took the default a/R 0.05
    ("hertz-sphere", {"delta": 1e-5}), ("hertz-cylinder", {"P": 1e-5}),  # a/R 0.003 and 0.0025
    ("punch", {"half": 0, "n_contact": 64}),  # the whole width: twice the half's
    ("punch", {"size": 200}),  # a larger block: a larger far field
])
def test_the_estimate_follows_the_parameters_that_change_the_mesh(family, values):
    built, estimate = _built_and_estimated(family, values)
    assert built <= estimate <= over(family, values, 1.5) * built, (estimate, built)


def test_the_first_adaptive_mesh_is_sized_before_it_is_made(monkeypatch):
    monkeypatch.setenv(MEMORY_VARIABLE, "0.1")
    with pytest.raises(InputError, match="over the limit of 0.1 GB"):
        signorini.solve_adaptive("hertz-cylinder", "1%", params={"refine": 2})


def test_a_family_scene_file_is_sized_before_it_is_meshed(tmp_path):
    """A scene file naming a family goes through the family's size guard, as the name does."""
    path = tmp_path / "big.toml"
    path.write_text('scene = "hertz-cylinder"\n[mesh]\nrefine = 6\n')
    with pytest.raises(InputError, match=r"refine=6.*dofs"):
        signorini.build_problem(str(path))
