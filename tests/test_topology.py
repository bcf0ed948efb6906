"""signorini.fem.topology finds the facets scikit-fem would, in its order, on every kind of mesh
the scenes build: if scikit-fem changes how it numbers facets, these tests say so."""

from __future__ import annotations

import numpy as np
import pytest
from skfem import MeshTet, MeshTri

from signorini.fem.topology import TOPOLOGY, facet_topology, moved, with_topology
from signorini.scenes.meshing import coarse_ball_octant, refine_simplices_to_size


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
