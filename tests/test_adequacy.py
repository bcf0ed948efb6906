"""An exact answer to an inadequate model is not `converged` (signorini.certification.adequacy)."""

from __future__ import annotations

import contextlib
import io
import json

import numpy as np
import pytest

import signorini
from signorini.certification.adequacy import adequacy, warnings
from signorini.cli import main
from signorini.problem.contact import Watch

SMALL = {"n_contact": 16, "grading": 0.3}


def test_a_push_beyond_the_candidates_is_model_inadequate():
    result = signorini.solve("hertz-cylinder", params={"delta": 0.02, **SMALL})
    assert result.status == "model_inadequate" and result.claimed_status == "converged"
    assert "raise the scene parameter candidates (now 2" in result.message
    record = result.to_dict()
    assert record["adequacy"]["penetrating_nodes"] > 0 and record["adequacy"]["penetration"] > 0
    assert record["adequacy"]["edge_active"] > 0
    # the same QP answer is exact: the certificate alone would have passed it
    assert max(result.certificate.as_dict().values()) < 1e-9


def test_a_saved_problem_keeps_its_watch_and_is_judged_inadequate_from_its_file(tmp_path):
    """The boundary beyond the candidates is stored with the problem: solved from its file, an
    outgrown contact is model_inadequate there too, by the command line as by the API."""
    problem = signorini.build_problem("hertz-cylinder", params={"delta": 0.02, **SMALL})
    problem.save(tmp_path / "p.npz")
    saved = signorini.ContactProblem.load(tmp_path / "p.npz")
    assert saved.model.watch is not None
    np.testing.assert_array_equal(saved.model.watch.rows.toarray(), problem.model.watch.rows.toarray())
    assert signorini.solve(saved).status == "model_inadequate"
    with contextlib.redirect_stdout(io.StringIO()) as out:
        code = main(["solve", str(tmp_path / "p.npz"), "--json", str(tmp_path / "r.json")])
    assert code == 1 and "model_inadequate" in out.getvalue()


def test_two_bodies_whose_contact_reaches_the_slave_faces_end_are_model_inadequate():
    """A push that brings every slave candidate into contact, the last one where the slave's
    boundary goes on facing the other cylinder: the zone may go on beyond the face, so the exact
    answer of the QP is model_inadequate; the default load stays converged, and the patch test's
    face, which ends at the blocks' sides, has no such candidate."""
    pushed = signorini.solve("hertz-two-cylinders", params={"delta": 0.02, "n_contact": 8})
    assert pushed.status == "model_inadequate" and pushed.claimed_status == "converged"
    assert "raise the scene parameter candidates" in pushed.message
    assert max(pushed.certificate.as_dict().values()) < 1e-9  # the QP's answer is exact
    default = signorini.solve("hertz-two-cylinders", params={"n_contact": 8})
    assert default.converged and default.problem.model.watch.edge.size == 1
    assert signorini.solve("two-block-patch").problem.model.watch.edge.size == 0


def test_more_candidates_make_the_same_push_adequate():
    result = signorini.solve("hertz-cylinder", params={"delta": 0.02, "candidates": 4.0, **SMALL})
    assert result.converged, result.message
    found = result.to_dict()["adequacy"]
    assert found == {"penetration": 0.0, "relative_penetration": 0.0, "penetrating_nodes": 0,
                     "edge_active": 0}


@pytest.mark.parametrize("scene", ["hertz-cylinder", "hertz-sphere", "hertz-sphere-3d", "block",
                                   "punch", "reverse-hertz"])
@pytest.mark.slow
def test_the_default_scenes_are_adequate_and_watched(scene):
    result = signorini.solve(scene)
    assert result.converged, result.message
    assert result.problem.model.watch is not None
    assert result.to_dict()["adequacy"]["edge_active"] == 0


def test_the_cli_exits_1_on_an_inadequate_model(tmp_path):
    path = tmp_path / "r.json"
    with contextlib.redirect_stdout(io.StringIO()) as out:
        code = main(["solve", "hertz-cylinder", "--set", "delta=0.02", "--set", "n_contact=16",
                     "--json", str(path)])
    assert code == 1 and "model_inadequate" in out.getvalue()
    assert json.loads(path.read_text())["status"] == "model_inadequate"


def test_a_watched_node_through_the_obstacle_is_found():
    problem = signorini.build_problem("hertz-cylinder", params=SMALL)
    solution = signorini.solve(problem).solution
    watch = problem.model.watch
    assert adequacy(problem, solution, 1e-9).penetrating_nodes == 0
    # move the first watched node's gap below zero: the check must see it
    gaps = watch.gap(problem, solution.u)
    moved = watch.gaps.copy()
    moved[0] -= gaps[0] + 1e-3
    shifted = Watch(watch.rows, moved, watch.edge, watch.candidate_gaps, watch.remedy)
    problem.model.watch = shifted
    found = adequacy(problem, solution, 1e-9)
    assert found.penetrating_nodes == 1 and found.inadequate(1e-9)
    assert found.penetration == pytest.approx(1e-3 * problem.scales.displacement)


def test_warnings_keep_the_status():
    result = signorini.solve("hertz-cylinder", params={"nu": 0.49, "volumetric": "element", **SMALL})
    assert result.converged and "P1 triangles lock" in result.message
    assert "volumetric=nodal" in result.message  # the remedy
    # by default (auto) ν = 0.49 averages the volumetric strain at the nodes: nothing locks
    result = signorini.solve("hertz-cylinder", params={"nu": 0.49, **SMALL})
    assert result.converged and "lock" not in result.message
    problem = signorini.build_problem("hertz-cylinder", params=SMALL)
    watch = problem.model.watch
    push = np.max(np.abs(problem.model.prescribed))
    problem.model.watch = Watch(watch.rows, watch.gaps, watch.edge, watch.candidate_gaps - 2 * push,
                          watch.remedy)
    assert any("inside the body" in w for w in warnings(problem))
