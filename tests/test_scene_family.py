"""A scene family is one module: a toy family registered from a file runs through everything.

The module below (written to a temporary directory and imported from there)
declares a slab, a block with other defaults, with its own size model and
validation case and one line that registers it. Nothing else in the package
knows it, yet solving, the validation suite, adaptive refinement and the size
guard all take it; it is unregistered after each test.
"""

from __future__ import annotations

import importlib.util
import sys
import textwrap

import pytest

import signorini
from signorini.errors import InputError
from signorini.scenes import SCENES, SceneFamily, get_scene, register, unregister
from signorini.scenes.size import MEMORY_VARIABLE, SIZE_MODELS, check_size, estimate_dofs
from signorini.studies import suite

SLAB_MODULE = textwrap.dedent('''
    """A wide, thin slab pressed onto a rigid flat: the block's scene with other defaults."""

    from dataclasses import replace

    from signorini.scenes import Case, SceneFamily, register
    from signorini.scenes.block import PARAMS, build
    from signorini.scenes.size import CountedSize

    DEFAULTS = {"W": 4.0, "H": 0.5, "nx": 8, "ny": 2}
    SNAPPED = []  # the meshes adaptive refinement asked the family to snap


    def snap(params):
        def on_flat_sides(mesh):  # no curved boundary: a snap that only records its calls
            SNAPPED.append(mesh.p.shape[1])
            return mesh
        return on_flat_sides


    FAMILY = register(SceneFamily(
        name="slab", summary="a thin slab pressed onto a rigid flat (uniform pressure)",
        params=tuple(replace(p, default=DEFAULTS[p.name]) if p.name in DEFAULTS else p
                     for p in PARAMS),
        build=build, reference="uniform",
        size_model=CountedSize(lambda p: 2.0 * (p["nx"] + 1) * (p["ny"] + 1)),
        snap=snap, validation=(Case("slab", "slab", {"nx": 6}),)))
''')


@pytest.fixture
def slab(tmp_path):
    """The slab's module, imported from a file in ``tmp_path`` (registering the family)."""
    path = tmp_path / "slab_family.py"
    path.write_text(SLAB_MODULE)
    spec = importlib.util.spec_from_file_location("slab_family", path)
    module = importlib.util.module_from_spec(spec)
    sys.modules["slab_family"] = module
    try:
        spec.loader.exec_module(module)
        yield module
    finally:
        unregister("slab")
        sys.modules.pop("slab_family", None)
    assert "slab" not in SCENES


def test_registering_makes_the_family_known_everywhere(slab):
    assert get_scene("slab") is slab.FAMILY
    assert SIZE_MODELS["slab"] is slab.FAMILY.size_model
    assert [case.name for case in suite.DEFAULT_CASES][-1] == "slab"
    assert "slab" in signorini.scene_families()


def test_solve_gives_the_uniform_pressure(slab):
    result = signorini.solve("slab", "pdas", params={"delta": 0.02})
    assert result.status == "converged"
    assert result.problem.model.reference_name == "uniform"
    uniform = result.to_dict()["uniform"]
    assert uniform["pressure_max_rel"] < 1e-8
    assert result.problem.model.params["W"] == 4.0 and result.problem.model.params["nx"] == 8


def test_the_validation_suite_runs_the_family_case(slab):
    assert not signorini.scenes.portable_scene("slab")  # a worker process does not know it
    result = suite.run_suite(suite.select_cases(["slab"]), ["pdas"])  # so the suite runs here
    names = {(check.case, check.name) for check in result.checks}
    assert ("slab", "uniform pressure max relative error (pdas)") in names
    assert result.passed, [c for c in result.checks if not c.passed]
    assert result.results[0].problem.model.params["nx"] == 6


def test_adaptive_refinement_uses_the_family_snap(slab):
    result = signorini.solve_adaptive("slab", 1e-30, "pdas", target_on="energy", max_dofs=400)
    steps = result.solution.extras["adaptive"]
    assert len(steps) >= 2 and steps[-1]["dofs"] > steps[0]["dofs"]
    assert slab.SNAPPED, "the family's snap was not called on the refined meshes"
    assert result.to_dict()["uniform"]["pressure_max_rel"] < 1e-8


def test_the_size_guard_reads_the_family_size_model(slab, monkeypatch):
    params = slab.FAMILY.parse({"nx": 30, "ny": 3})
    dofs, dim = estimate_dofs("slab", params)
    mesh = slab.FAMILY.build(params, set()).mesh
    assert (dofs, dim) == (mesh.p.size, 2)
    monkeypatch.setenv(MEMORY_VARIABLE, "1e-6")  # 1 kB: the slab's 248 dofs need about 1 MB
    with pytest.raises(InputError, match="scene 'slab' .* 248 dofs"):
        check_size("slab", params)
    with pytest.raises(InputError, match="'slab'"):
        signorini.solve("slab", "pdas", params={"nx": 30, "ny": 3})


def test_a_family_without_a_size_model_cannot_be_registered():
    family = SceneFamily(name="unsized", summary="", params=(), build=lambda p, given: None)
    with pytest.raises(InputError, match="'unsized' has no size model"):
        register(family)
    assert "unsized" not in SCENES


def test_a_name_taken_is_refused(slab):
    other = SceneFamily(name="slab", summary="", params=(), build=lambda p, given: None,
                        size_model=slab.FAMILY.size_model)
    with pytest.raises(InputError, match="'slab' is already registered"):
        register(other)
    assert get_scene("slab") is slab.FAMILY
