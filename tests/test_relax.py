"""The relaxation's Delaunay steps: qhull only where the nodes are co-circular, Triangle after."""

import numpy as np
import pytest

import signorini.scenes.relax as relax_module
from signorini.scenes.meshing import graded_quarter_disc, graded_unit_disc


def _triangle_set(t: np.ndarray) -> set[tuple[int, ...]]:
    return set(map(tuple, np.sort(t, axis=0).T.tolist()))


@pytest.mark.parametrize("n_contact, grading", [(10, 0.15), (40, 0.15)])
def test_the_mesh_is_the_one_qhull_alone_gives(monkeypatch, n_contact, grading):
    calls = []
    delaunay = relax_module._delaunay

    def counted(p, general_position):
        calls.append(general_position)
        return delaunay(p, general_position)

    monkeypatch.setattr(relax_module, "_delaunay", counted)
    graded_unit_disc.cache_clear()  # meshed here, not kept from an earlier test
    mixed = graded_quarter_disc(1.0, 0.05, n_contact, grading).mesh
    assert calls.count(False) == 1 and calls.count(True) >= 2  # qhull once, then Triangle

    monkeypatch.setattr(relax_module, "_delaunay", lambda p, general_position: delaunay(p, False))
    graded_unit_disc.cache_clear()
    qhull = graded_quarter_disc(1.0, 0.05, n_contact, grading).mesh
    assert np.array_equal(mixed.p, qhull.p)
    assert _triangle_set(mixed.t) == _triangle_set(qhull.t)


def test_triangle_and_qhull_pick_different_diagonals_on_a_bisection_mesh():
    """Why the first step stays with qhull: on a square grid every cell has two Delaunay diagonals."""
    x, y = np.meshgrid(np.arange(4.0), np.arange(4.0))
    p = np.vstack([x.ravel(), y.ravel()])
    qhull, triangle = relax_module._delaunay(p, False), relax_module._delaunay(p, True)
    assert len(qhull) == len(triangle) == 18
    assert _triangle_set(qhull.T) != _triangle_set(triangle.T)
