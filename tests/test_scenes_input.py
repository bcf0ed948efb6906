"""Bad scene input raises InputError whose message names the parameter (and how to fix it)."""

import numpy as np
import pytest

from signorini.errors import InputError
from signorini.scenes import SCENES, build_problem, get_scene

# a small mesh so that the few calls that do build stay fast
SMALL = {"block": {"nx": 2, "ny": 2}, "hertz-cylinder": {"n_contact": 4}}


def build(scene, **values):
    return build_problem(scene, params={**SMALL.get(scene, {}), **values})


def test_unknown_scene_lists_the_known_ones():
    with pytest.raises(InputError, match="no-such-scene") as info:
        build_problem("no-such-scene")
    for name in SCENES:
        assert name in str(info.value)
    with pytest.raises(InputError):
        get_scene("Block")


@pytest.mark.parametrize("scene", sorted(SCENES))
def test_unknown_parameter_lists_the_known_ones(scene):
    with pytest.raises(InputError, match="radius_of_curvature") as info:
        build(scene, radius_of_curvature=1.0)
    for param in get_scene(scene).params:
        assert param.name in str(info.value)


@pytest.mark.parametrize("scene, name, value", [
    ("block", "E", 0.0),
    ("block", "E", -70e9),
    ("hertz-cylinder", "E", 0),
    ("block", "nu", 0.5),
    ("block", "nu", -1.0),
    ("block", "nu", 0.7),
    ("hertz-cylinder", "nu", 0.5),
    ("hertz-cylinder", "nu", -1),
    ("hertz-cylinder", "nu", 0.7),
    ("hertz-cylinder", "R", 0.0),
    ("hertz-cylinder", "R", -0.01),
    ("hertz-cylinder", "a_over_R", 0.51),
    ("hertz-cylinder", "a_over_R", 1.0),
    ("hertz-cylinder", "a_over_R", 0.0),
    ("hertz-cylinder", "P", 0.0),
    ("hertz-cylinder", "P", -1.0),
    ("block", "W", 0.0),
    ("block", "H", -1.0),
    ("block", "delta", 0.0),
    ("block", "nx", 0),
    ("hertz-cylinder", "n_contact", 3),
])
def test_out_of_range_value_names_the_parameter(scene, name, value):
    with pytest.raises(InputError, match=rf"\b{name}=") as info:
        build(scene, **{name: value})
    assert "must be" in str(info.value)


@pytest.mark.parametrize("scene, name", [("block", "E"), ("block", "nu"), ("block", "delta"),
                                         ("hertz-cylinder", "R"), ("hertz-cylinder", "E"),
                                         ("hertz-cylinder", "P"), ("hertz-cylinder", "a_over_R")])
@pytest.mark.parametrize("value", [float("nan"), np.nan, float("inf"), -float("inf"), "nan"])
def test_non_finite_value_names_the_parameter(scene, name, value):
    with pytest.raises(InputError, match=rf"\b{name}="):
        build(scene, **{name: value})


@pytest.mark.parametrize("scene, name", [("block", "E"), ("hertz-cylinder", "R"),
                                         ("hertz-cylinder", "nu")])
@pytest.mark.parametrize("value", ["abc", "", "1,5", [1.0], object()])
def test_non_number_for_a_float_names_the_parameter(scene, name, value):
    with pytest.raises(InputError, match=rf"\b{name}=") as info:
        build(scene, **{name: value})
    assert "float" in str(info.value)


@pytest.mark.parametrize("value", [20.5, "20.5", "abc", "", "inf", float("nan")])
def test_non_integer_n_contact_names_the_parameter(value):
    with pytest.raises(InputError, match=r"\bn_contact=") as info:
        build_problem("hertz-cylinder", params={"n_contact": value})
    assert "int" in str(info.value)


@pytest.mark.parametrize("name", ["nx", "ny"])
@pytest.mark.parametrize("value", [2.5, "3.0", "x"])
def test_non_integer_block_resolution_names_the_parameter(name, value):
    with pytest.raises(InputError, match=rf"\b{name}="):
        build_problem("block", params={name: value})


def test_numbers_given_as_strings_are_accepted():
    from_strings = build_problem("block", params={"nx": "2", "ny": " 2 ", "E": "70e9", "nu": "0.33"})
    from_numbers = build_problem("block", params={"nx": 2, "ny": 2, "E": 70e9, "nu": 0.33})
    assert from_strings.model.params == from_numbers.model.params
    assert abs(from_strings.K - from_numbers.K).max() == 0.0


def test_load_too_large_for_hertz_theory_names_P():
    # P = πE*a²/(4R): a/R = 1 needs P = π/(4 · 0.91) ≈ 0.86 at E = R = 1
    with pytest.raises(InputError, match=r"\bP=") as info:
        build("hertz-cylinder", P=0.9)
    assert "a/R" in str(info.value)


@pytest.mark.parametrize("values", [{"P": 0.004, "a_over_R": 0.05}, {"P": 0.004, "delta": 1e-3},
                                    {"a_over_R": 0.05, "delta": 1e-3}])
def test_two_load_parameters_raise(values):
    with pytest.raises(InputError) as info:
        build("hertz-cylinder", **values)
    for name in values:
        assert name in str(info.value)


def test_good_input_builds():
    problem = build("hertz-cylinder", E=2.1e11, R=0.01, nu=0.3, a_over_R=0.5)
    assert problem.m > 0
    assert problem.model.params["a_over_R"] == 0.5


@pytest.mark.parametrize("scene, name, value", [
    pytest.param("hertz-cylinder", "n_contact", float("inf"), id="n_contact=inf"),
    pytest.param("block", "nx", -float("inf"), id="nx=-inf"),
    pytest.param("block", "E", 10**400, id="E=10**400"),
])
def test_overflowing_value_names_the_parameter(scene, name, value):
    with pytest.raises(InputError, match=rf"\b{name}="):
        build_problem(scene, params={name: value})


def test_none_for_a_required_parameter_names_it():
    with pytest.raises(InputError, match=r"\bE="):
        build("block", E=None)


def test_P_none_is_the_default():
    # P=None is the documented default (the load from a_over_R), not an error: pinned as such
    default = build("hertz-cylinder")
    explicit = build("hertz-cylinder", P=None)
    assert explicit.model.params["P"] == pytest.approx(default.model.params["P"], rel=1e-12)
    np.testing.assert_allclose(explicit.f, default.f, rtol=1e-10)
