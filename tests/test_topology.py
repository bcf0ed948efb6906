"""signorini.fem.topology finds the facets scikit-fem would, in its order, on every kind of mesh
the scenes build: if scikit-fem changes how it numbers facets, these tests say so."""

from __future__ import annotations

import numpy as np
import pytest
from skfem import MeshTet, MeshTri

from signorini.fem.topology import (TOPOLOGY, facet_topology, moved, sorted_columns,
                                    with_edges, with_topology)
from signorini.scenes.ball_octant import coarse_ball_octant
from signorini.scenes.meshing import refine_simplices_to_size


def graded_octant() -> MeshTet:
    """A tetrahedral mesh made as the 3D sphere's: longest-edge bisection towards a point."""
    return refine_simplices_to_size(coarse_ball_octant(),
                                    lambda x: 0.05 + 0.5 * np.linalg.norm(x, axis=0))


MESHES = {
    "ball": lambda: MeshTet.init_ball(2),
    "graded octant": graded_octant,
    "uniform tetrahedra": lambda: MeshTet().refined(3),
    "disc": lambda: MeshTri.init_circle(3),
    "adapted triangles": lambda: MeshTri.init_sqsymmetric().refined(2).refined(np.arange(5)),
}


@pytest.mark.parametrize("name", MESHES)
def test_the_facets_are_scikit_fems_in_its_order(name):
    mesh = MESHES[name]()
    mine = facet_topology(mesh.t, mesh.elem.refdom.facets, mesh.p.shape[1])
    theirs = (mesh.facets, mesh.t2f, mesh.f2t)  # scikit-fem computes its own here
    for ours, reference, attribute in zip(mine, theirs, TOPOLOGY):
        assert ours.shape == reference.shape, attribute
        assert np.array_equal(ours, reference), attribute


def test_a_mesh_given_its_facets_answers_as_scikit_fem_would():
    fresh, prepared = graded_octant(), with_topology(graded_octant())
    assert all(hasattr(prepared, name) for name in TOPOLOGY)
    assert np.array_equal(prepared.boundary_facets(), fresh.boundary_facets())
    assert np.array_equal(prepared.boundary_nodes(), fresh.boundary_nodes())


def test_a_moved_mesh_keeps_the_facets_and_takes_the_new_nodes():
    mesh = graded_octant()
    scaled = moved(mesh, 3.0 * mesh.p)
    assert np.allclose(scaled.p, 3.0 * mesh.p)
    assert np.array_equal(scaled.t, mesh.t)
    for name in TOPOLOGY:
        assert getattr(scaled, name) is getattr(mesh, name)


def test_too_many_nodes_to_pack_leaves_the_work_to_scikit_fem():
    t = np.array([[0], [1], [2], [3]])
    assert facet_topology(t, MeshTet().elem.refdom.facets, 2 ** 21 + 1) is None


@pytest.mark.parametrize("name", ["ball", "graded octant", "uniform tetrahedra"])
def test_the_edges_are_scikit_fems_and_so_is_its_uniform_refinement(name):
    theirs, mine = MESHES[name](), with_edges(MESHES[name]())
    assert hasattr(mine, "_edges") and not hasattr(theirs, "_edges")
    assert np.array_equal(mine.edges, theirs.edges) and mine.edges.dtype == theirs.edges.dtype
    assert np.array_equal(mine.t2e, theirs.t2e)
    finer, reference = mine.refined(), theirs.refined()
    assert np.array_equal(finer.p, reference.p) and np.array_equal(finer.t, reference.t)


def test_the_sorting_network_sorts_columns_and_counts_swaps():
    rng = np.random.default_rng(3)
    for rows in (2, 3, 4):
        keys = rng.integers(0, 5, size=(rows, 500))
        ordered, odd = sorted_columns(keys)
        assert np.array_equal(ordered, np.sort(keys, axis=0))
        distinct = np.all(np.diff(np.sort(keys, axis=0), axis=0) > 0, axis=0)
        sign = np.sign([np.linalg.det(np.eye(rows)[np.argsort(column)]) for column in keys.T])
        assert np.array_equal(odd[distinct], sign[distinct] < 0)


def test_snapping_refuses_a_move_that_turns_a_tetrahedron_inside_out():
    from signorini.fem.checks import signed_measures
    from signorini.scenes.ball_octant import on_ball_octant_surface, snap_to_sphere

    snap, centre = snap_to_sphere((0.0, 0.0, 1.0), 1.0), np.array([[0.0], [0.0], [1.0]])
    mesh = snap(graded_octant())
    assert np.allclose(snap(mesh).p, mesh.p, rtol=0.0, atol=1e-15)  # on the sphere: stays there
    surface = on_ball_octant_surface(mesh, (0.0, 0.0, 1.0))
    node = surface[np.argmin(np.abs(mesh.p[2, surface] - 0.3))]  # off the rims
    pulled = mesh.p.copy()
    pulled[:, node] = centre[:, 0] + 0.2 * (pulled[:, node] - centre[:, 0])  # deep inside
    inside_out = moved(mesh, pulled)
    touching = np.any(mesh.t == node, axis=0)
    volumes = signed_measures(mesh.p, mesh.t[:, touching])
    assert np.any(np.sign(signed_measures(pulled, mesh.t[:, touching])) != np.sign(volumes))
    with pytest.raises(RuntimeError, match="inverted"):
        snap(inside_out)
