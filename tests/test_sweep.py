"""Load sweeps: one factorisation, exact answers at every level."""

import json

import numpy as np
import pytest

import signorini
from signorini.cli import main
from signorini.errors import InputError
from signorini.references.pressure import contact_half_width, contact_profile
from signorini.scenes import build_problem
from signorini.solvers.registry import solve
from signorini.studies.sweep import parse_loads, sweep_loads

SMALL = {"n_contact": 24, "grading": 0.3}


def test_a_sweep_level_equals_a_full_solve_at_that_load():
    # pushed, not load-targeted
    base = signorini.at_load(build_problem("hertz-cylinder", params={"delta": 0.003, **SMALL}))
    # the same mesh and model (the cut pushed flat), its P found by assembly
    targeted = signorini.at_load(build_problem("hertz-cylinder", params={"loading": "displacement", **SMALL}))
    loads = np.array([0.5, 2.0, 1.0]) * targeted.model.params["P"]
    levels = sweep_loads(base, loads)
    assert [lv.total_force for lv in levels] == pytest.approx(list(loads), rel=1e-9)
    exact = solve(targeted, "pdas")
    profile = contact_profile(targeted, exact)
    assert levels[2].p0 == pytest.approx(profile.pressure[0], rel=1e-9)
    assert levels[2].a == pytest.approx(contact_half_width(profile), rel=1e-9)
    assert levels[2].delta == pytest.approx(targeted.model.params["delta"], rel=1e-9)


def test_a_traction_loaded_sweep_level_equals_a_full_solve_at_that_load():
    # a traction on the cut, the centre pinned
    targeted = signorini.at_load(build_problem("hertz-cylinder", params=SMALL))
    assert targeted.model.push.f_load is not None
    loads = np.array([2.0, 0.5, 1.0]) * targeted.model.params["P"]
    levels = sweep_loads(targeted, loads)
    assert [lv.total_force for lv in levels] == pytest.approx(list(loads), rel=1e-9)
    profile = contact_profile(targeted, solve(targeted, "pdas"))
    assert levels[2].p0 == pytest.approx(profile.pressure[0], rel=1e-9)
    assert levels[2].a == pytest.approx(contact_half_width(profile), rel=1e-9)
    assert levels[2].delta == pytest.approx(targeted.model.params["delta"], rel=1e-9)
    assert profile.applied_load == pytest.approx(profile.total_force, rel=1e-9)  # the pin carries 0


def test_half_width_grows_like_the_square_root_of_the_load():
    base = signorini.at_load(build_problem("hertz-cylinder", params=SMALL))
    loads = np.array([0.6, 1.0, 1.4]) * base.model.params["P"]
    levels = sweep_loads(base, loads)
    slope = np.polyfit(np.log(loads), np.log([lv.a for lv in levels]), 1)[0]
    assert slope == pytest.approx(0.5, abs=0.03)
    for lv in levels:
        assert lv.a == pytest.approx(lv.a_ref, rel=0.03)


@pytest.mark.parametrize("text", ["1:2", "a:b:3", "2:1:3", "0:1:3", "1:2:0"])
def test_bad_load_ranges_are_refused(text):
    with pytest.raises(InputError, match="--load"):
        parse_loads(text)


def test_sweep_command_writes_its_files(tmp_path, capsys, saved_figures):
    out = tmp_path / "sweep"
    code = main(["sweep", "hertz-cylinder", "--load", "0.001:0.003:3", "--set", "n_contact=16",
                 "--set", "grading=0.4", "--out", str(out)])
    assert code == 0
    record = json.loads((out / "sweep.json").read_text())
    assert len(record["levels"]) == 3
    assert (out / "sweep.png").stat().st_size > 10_000
    (figure,) = saved_figures  # a against the load, p₀ on a twin axis, both with Hertz's √P
    width, peak = figure.axes
    assert width.get_xlabel() == "load P per unit thickness"
    assert width.get_ylabel() == "contact half-width a" and peak.get_ylabel() == "peak pressure p₀"
    lines = {line.get_label(): line for ax in figure.axes for line in ax.get_lines()}
    assert {"a (numeric)", "Hertz a ∝ √P", "p₀ (numeric)", "Hertz p₀ ∝ √P"} <= set(lines)
    levels = record["levels"]
    assert list(lines["a (numeric)"].get_ydata()) == pytest.approx([r["a"] for r in levels])
    assert list(lines["p₀ (numeric)"].get_ydata()) == pytest.approx([r["p0"] for r in levels])
    assert (out / "sweep.csv").read_text().count("\n") == 4
