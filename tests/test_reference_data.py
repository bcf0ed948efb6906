"""The typed record a scene hands its analytic reference, and the push's δ and P.

Every family builds its :class:`ReferenceData` from its own parameters; the
comparisons, load control's analytic zone and the sweep read its fields and
the push's ``delta`` and ``P`` (tests/test_layers.py holds that no module
outside ``scenes/`` reads a parameter by name).
"""

from __future__ import annotations

import dataclasses
import json
import logging

import numpy as np
import pytest

from signorini.references.analytic import contact_modulus
from signorini.errors import InputError
from signorini.references.pressure import compare_uniform
from signorini.problem.contact import ContactProblem
from signorini.references.catalogue import REFERENCES
from signorini.scenes import SCENES, build_problem, register, unregister
from signorini.scenes.block import FAMILY as BLOCK
from signorini.scenes.two_block_patch import compliance
from signorini.solvers.registry import solve

#: the parameters each reference's record holds, by record field
RECORD_PARAMS = {"hertz-2d": {"R": "R"}, "hertz-3d": {"R": "R"}, "reverse-hertz": {"R": "R"},
                 "punch": {"a": "a", "corner_radius": "corner_radius"}, "uniform": {"H": "H"}}
#: the records of two-body families, from their parameters
def _hertz_pair(p):
    return {"R": 1.0 / (1.0 / p["R1"] + 1.0 / p["R2"]),
            "E_star": 1.0 / (1.0 / contact_modulus(p["E1"], p["nu1"])
                             + 1.0 / contact_modulus(p["E2"], p["nu2"]))}


TWO_BODIES = {"two-block-patch": lambda p: {"H": p["H1"] + p["H2"],
                                            "E_star": (p["H1"] + p["H2"]) / compliance(p)},
              "hertz-two-cylinders": _hertz_pair, "hertz-two-spheres": _hertz_pair}
#: coarse meshes, so that building every family stays quick
COARSE = {"punch": {"n_contact": 16, "grading": 0.6}, "reverse-hertz": {"n_contact": 16, "grading": 0.6},
          "hertz-sphere-3d": {"n_contact": 4, "grading": 1.0}}


@pytest.mark.parametrize("name", sorted(SCENES))
def test_every_family_hands_its_reference_the_record_of_its_parameters(name):
    problem = build_problem(name, params=COARSE.get(name, SCENES[name].convergence_start))
    record = problem.model.reference
    assert record.name == problem.model.reference_name == SCENES[name].reference
    assert record.name in REFERENCES
    p = problem.model.params
    if name in TWO_BODIES:  # the pair's record: both bodies' compliances in series
        for field, value in TWO_BODIES[name](p).items():
            assert getattr(record, field) == pytest.approx(value, rel=1e-15)
    else:
        assert record.E_star == contact_modulus(p["E"], p["nu"])
        for field, param in RECORD_PARAMS[record.name].items():
            assert getattr(record, field) == p[param]
    # the push carries the scene's δ and target P, as the parameters report them
    assert problem.model.push.delta == problem.model.params["delta"]
    assert problem.model.push.P == problem.model.params.get("P")


def test_a_push_moves_delta_and_the_uniform_pressure_with_it():
    problem = build_problem("block")
    twice = problem.pushed(2.0 * problem.model.push.scale)
    assert twice.model.push.delta == 2.0 * problem.model.push.delta == twice.model.params["delta"]
    assert problem.model.push.delta == problem.model.params["delta"]  # the problem pushed from is unchanged
    once, doubled = (compare_uniform(p, solve(p, "pdas")) for p in (problem, twice))
    assert doubled.pressure_ref == pytest.approx(2.0 * once.pressure_ref, rel=1e-14)
    assert doubled.pressure_max_rel < 1e-8


def test_save_and_load_keep_the_record_and_the_push(tmp_path):
    problem = build_problem("hertz-cylinder", params={"n_contact": 8, "grading": 0.6})
    problem.save(tmp_path / "p.npz")
    again = ContactProblem.load(tmp_path / "p.npz")
    assert again.model.reference == problem.model.reference
    assert (again.model.push.delta, again.model.push.P) == (problem.model.push.delta, problem.model.push.P)


def test_a_file_that_stored_the_reference_by_name_loads_without_one(tmp_path, caplog):
    problem = build_problem("block", params={"nx": 4, "ny": 4})
    problem.save(tmp_path / "p.npz")
    with np.load(tmp_path / "p.npz") as stored:
        arrays = dict(stored)
    meta = json.loads(bytes(arrays["meta"]).decode())
    meta["discretisation"]["reference"] = "uniform"  # what an older version stored
    del meta["discretisation"]["push"]["delta"]
    arrays["meta"] = np.frombuffer(json.dumps(meta).encode(), dtype=np.uint8)
    np.savez(tmp_path / "old.npz", **arrays)
    with caplog.at_level(logging.WARNING, logger="signorini.problem.contact"):
        old = ContactProblem.load(tmp_path / "old.npz")
    assert old.model.reference is None and old.model.reference_name == "" and old.model.push.delta is None
    assert "'uniform'" in caplog.text and "rebuild" in caplog.text


def test_a_family_whose_model_hands_on_another_reference_is_refused():
    family = register(dataclasses.replace(BLOCK, name="mislabelled", reference="punch"))
    try:
        with pytest.raises(InputError, match="declares the reference 'punch'.*ReferenceData"):
            build_problem("mislabelled", params={"nx": 4, "ny": 4})
    finally:
        unregister("mislabelled")
    assert build_problem("block", params={"nx": 4, "ny": 4}).model.reference_name == "uniform"
