"""Repeated solves re-use what does not change: the mesh across E, the mesh and K across loads.

Work is counted, not timed: meshings (misses of the graded disc's cache) and assemblies.
"""

from __future__ import annotations

import numpy as np
import pytest

import signorini
from signorini.errors import InputError
from signorini.scenes import build
from signorini.scenes.build import with_load
from signorini.scenes.meshing import graded_quarter_disc, graded_unit_disc

SMALL = {"n_contact": 12, "grading": 0.4}


@pytest.fixture
def meshings():
    """The number of graded discs meshed since the test began (the cache starts empty)."""
    graded_unit_disc.cache_clear()
    return lambda: graded_unit_disc.cache_info().misses


def test_a_change_of_E_alone_meshes_nothing(meshings):
    first = signorini.solve("hertz-cylinder", params={**SMALL, "E": 1.0})
    second = signorini.solve("hertz-cylinder", params={**SMALL, "E": 3.0})
    assert meshings() == 1
    assert np.array_equal(first.problem.model.mesh.p, second.problem.model.mesh.p)
    assert second.status == "converged" and second.total_force == pytest.approx(3 * first.total_force)


def test_the_load_that_grades_the_mesh_meshes_again(meshings):
    """a_over_R (or P) sets the graded zone: a new load through params is a new mesh."""
    first = signorini.build_problem("hertz-cylinder", params={**SMALL, "a_over_R": 0.05})
    second = signorini.build_problem("hertz-cylinder", params={**SMALL, "a_over_R": 0.08})
    assert meshings() == 2
    assert first.model.mesh.p.shape != second.model.mesh.p.shape or not np.allclose(first.model.mesh.p, second.model.mesh.p)


def test_a_kept_mesh_is_the_mesh_made_afresh_and_cannot_be_changed(meshings):
    kept = graded_quarter_disc(2.0, 0.05, 12, 0.4, refine=1)
    again = graded_quarter_disc(2.0, 0.05, 12, 0.4, refine=1)
    graded_unit_disc.cache_clear()
    fresh = graded_quarter_disc(2.0, 0.05, 12, 0.4, refine=1)
    assert meshings() == 1  # the first call meshed, the second did not, the cache was then cleared
    for disc in (again, fresh):
        assert np.array_equal(kept.mesh.p, disc.mesh.p) and np.array_equal(kept.mesh.t, disc.mesh.t)
        assert np.array_equal(kept.candidates, disc.candidates)
    p, _, _ = graded_unit_disc(0.05, 12, 0.4, "relaxed")
    with pytest.raises(ValueError):
        p[0, 0] = 1.0


def test_a_load_slider_meshes_and_assembles_nothing(monkeypatch, meshings):
    problem = signorini.build_problem("hertz-cylinder", params=SMALL)
    first = signorini.solve(problem)
    assembled = []
    monkeypatch.setattr(build, "assemble", lambda *a, **k: assembled.append(1))
    for a_over_R in (0.04, 0.06):
        moved = with_load(problem, a_over_R=a_over_R)
        assert np.shares_memory(moved.K.data, problem.K.data) and moved.model.mesh is problem.model.mesh
        result = signorini.solve(moved)
        assert result.status == "converged"
        assert result.total_force == pytest.approx(moved.model.params["P"], rel=1e-9)
        assert result.problem.model.params["a_over_R"] == a_over_R
        assert result.to_dict()["time"]["mesh_s"] == 0.0
    assert meshings() == 1 and assembled == []
    back = signorini.solve(with_load(problem, P=problem.model.params["P"]))
    assert back.solution.lam == pytest.approx(first.solution.lam, rel=1e-9, abs=1e-12)


def test_with_load_refuses_what_is_not_a_target_load():
    problem = signorini.build_problem("hertz-cylinder", params=SMALL)
    for bad in ({"E": 2.0}, {}, {"delta": 0.001}):
        with pytest.raises(InputError, match="with_load"):
            with_load(problem, **bad)
    with pytest.raises(InputError, match="a_over_R"):
        with_load(problem, a_over_R=-1.0)
    qp = signorini.ContactProblem.from_qp(np.eye(2), np.ones(2), np.eye(2), np.ones(2))
    with pytest.raises(InputError, match="build this problem again"):
        with_load(qp, P=1.0)
