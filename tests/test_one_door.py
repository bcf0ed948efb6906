"""One door: a solve runs one pipeline, read top to bottom, traced with ``sys.setprofile``.

``signorini.solve`` checks the request once, matches a target load by load control, runs the
method and certifies its answer once. The package files a solve enters are counted, so that a
detour back through the layers shows up as a larger count (the bounds are what the pipeline
enters today: a regression guard, not the aim of 20 files for a scene and 8 for a QP of one's
own).
"""

from __future__ import annotations

import os
import sys

import numpy as np
import pytest

import signorini

ROOT = os.path.dirname(signorini.__file__)
#: package files a solve enters: a scene with a target load, and a QP given as arrays
SCENE_FILES = 34
QP_FILES = 16


def traced(step):
    """What ``step()`` returned, the package files it entered and its calls of check_request
    and of the KKT certificate."""
    files: set[str] = set()
    calls = {"check_request": 0, "certificate": 0}
    checking = os.path.join(ROOT, "solvers", "registry.py")
    certifying = os.path.join(ROOT, "certification", "kkt.py")

    def profile(frame, event, arg):
        if event != "call" or not frame.f_code.co_filename.startswith(ROOT):
            return
        where, name = frame.f_code.co_filename, frame.f_code.co_name
        files.add(where)
        if (where, name) == (checking, "check_request"):
            calls["check_request"] += 1
        elif (where, name) == (certifying, "certificate"):
            calls["certificate"] += 1

    sys.setprofile(profile)
    try:
        result = step()
    finally:
        sys.setprofile(None)
    return result, files, calls


def own_qp():
    return signorini.ContactProblem.from_qp(K=np.diag([2.0, 1.0]), f=np.ones(2),
                                            N=np.array([[1.0, 0.0]]), d=np.array([0.25]))


@pytest.mark.parametrize("make, bound", [(lambda: "hertz-cylinder", SCENE_FILES),
                                         (own_qp, QP_FILES)], ids=["scene", "from_qp"])
def test_one_solve_checks_once_certifies_once_and_enters_few_files(make, bound):
    signorini.solve(make(), "pdas")  # first imports and caches are not the pipeline's
    problem = make()
    result, files, calls = traced(lambda: signorini.solve(problem, "pdas"))
    assert result.converged, result.message
    assert calls == {"check_request": 1, "certificate": 1}
    assert len(files) <= bound, sorted(os.path.relpath(f, ROOT) for f in files)


def test_the_trace_counts_a_second_door():
    """The counts are not blind: two solves check twice and certify twice."""
    problem = own_qp()
    (first, second), _, calls = traced(lambda: (signorini.solve(problem, "pdas"),
                                                 signorini.solve(problem, "pdas")))
    assert first.converged and second.converged
    assert calls == {"check_request": 2, "certificate": 2}
