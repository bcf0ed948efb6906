"""What every scene model is checked for before assembly: its mesh, its obstacle and its units.

A mesh (triangles in 2D, tetrahedra in 3D) is refused, with the first bad
element named by its index and its nodes, when

- a node has a non-finite coordinate, or an element names a node it does not have;
- an element is **degenerate**: its area (volume) is at most
  :data:`DEGENERATE` times its longest edge squared (cubed), which includes
  an element with a repeated node;
- two elements are the **same** (the same nodes in any order);
- a facet (an edge in 2D, a face in 3D) bounds **more than two** elements
  (the mesh is not a manifold there);
- two elements that share a facet lie on the **same side** of it: one of
  them is folded over the other (an inverted element among its neighbours).

Orientation: scikit-fem integrates every element with ``|det J|``, so the
order of an element's nodes (clockwise or not) is no convention of this
package and is accepted either way; what matters is that neighbours lie on
opposite sides of their shared facet, which the last check holds. Together
these catch duplicated, degenerate, inverted-in-place and folded elements.
They do not catch two parts of a mesh that overlap without sharing a facet
(two separate layers laid on top of each other): that needs a search of
every pair of nearby elements, which no scene here makes.

The obstacle must start outside the undeformed body: no contact candidate
may have a gap below ``-OUTSIDE · length_scale``, and at every candidate on
a contact facet the obstacle's normal (from the body towards the obstacle)
must not point into the body. The units must be representable: the force
unit ``E · U · L^k`` and the weight unit ``L^(k+1)`` of
:class:`~signorini.problem.contact.Scales`, and a target load, finite and normal.
"""

from __future__ import annotations

import sys
from itertools import combinations
from typing import Any

import numpy as np

from signorini.errors import InputError
from signorini.fem.topology import outward_normals, packed_keys, sort_order, sorted_columns

#: an element whose measure is at most this times its longest edge to the dimension is degenerate
DEGENERATE = 1e-12
#: the range of a length (and of a mesh's coordinates): squares and cubes stay representable
LENGTH_RANGE = (1e-100, 1e100)
#: a candidate's gap below minus this times the length scale: the obstacle starts inside the body
OUTSIDE = 1e-8
#: a candidate whose obstacle normal has at most this component along the body's outward
#: normal faces away from the obstacle
FACING = -1e-6
NAMES = {2: ("triangle", "area", "edge"), 3: ("tetrahedron", "volume", "face")}
PLURAL = {"triangle": "triangles", "tetrahedron": "tetrahedra"}


def _nodes(t: np.ndarray, element: int) -> str:
    return ", ".join(str(int(n)) for n in t[:, element])


def signed_measures(p: np.ndarray, t: np.ndarray) -> np.ndarray:
    """``det[p₁ − p₀, …, p_d − p₀]`` of each simplex (d! times its signed area or volume)."""
    rows = np.ascontiguousarray(p.T)  # gathering rows is several times faster than columns
    origin = np.take(rows, t[0], axis=0)  # np.take: several times faster than rows[t[0]]
    return _determinants([np.take(rows, t[i], axis=0) - origin for i in range(1, t.shape[0])])


def _determinants(edges: list[np.ndarray]) -> np.ndarray:
    """``det[e₁, …, e_d]`` of each simplex from its edge vectors (d of them, (elements, d))."""
    if len(edges) == 2:
        return edges[0][:, 0] * edges[1][:, 1] - edges[0][:, 1] * edges[1][:, 0]
    return np.einsum("ij,ij->i", edges[0], np.cross(edges[1], edges[2]))


def check_mesh(p: np.ndarray, t: np.ndarray, what: str = "the scene's mesh",
               facet_ids: np.ndarray | None = None) -> None:
    """InputError naming the first bad element of the simplex mesh ``(p, t)`` (see the module).

    ``facet_ids`` (corners, elements), when known: the index of the facet opposite each node of
    each element among the mesh's facets in lexicographic order of their sorted nodes
    (:func:`opposite_facets`); the facets are then grouped by it instead of by a sort.
    """
    p, t = np.asarray(p, dtype=float), np.asarray(t)
    dim = p.shape[0]
    kind, measure, facet = NAMES.get(dim, ("element", "measure", "facet"))
    if dim not in NAMES or t.shape[0] != dim + 1:
        raise InputError(f"{what} must be made of {dim + 1}-node simplices in 2D or 3D, got "
                         f"{t.shape[0]}-node elements in {dim}D")
    bad = ~np.all(np.isfinite(p), axis=0)
    if np.any(bad):
        raise InputError(f"{what}: node {int(np.argmax(bad))} has a non-finite coordinate: "
                         "give every node finite coordinates")
    largest = float(np.max(np.abs(p), initial=0.0))
    if largest > LENGTH_RANGE[1]:
        raise InputError(f"{what}: its coordinates reach {largest:g}, beyond {LENGTH_RANGE[1]:g} "
                         "(areas and volumes must be representable in double precision): choose a "
                         "length unit nearer the body's size")
    if t.size and (t.min() < 0 or t.max() >= p.shape[1]):
        element = int(np.argmax(np.any((t < 0) | (t >= p.shape[1]), axis=0)))
        raise InputError(f"{what}: {kind} {element} (nodes {_nodes(t, element)}) names a node the "
                         f"mesh does not have (it has {p.shape[1]})")
    with np.errstate(over="ignore", invalid="ignore"):  # an overflow is a degenerate element
        rows = np.ascontiguousarray(p.T)
        corners = [np.take(rows, t[i], axis=0) for i in range(dim + 1)]
        spokes = [corner - corners[0] for corner in corners[1:]]  # the edges from corner 0
        longest = np.zeros(t.shape[1])  # the longest edge squared, one edge at a time
        for i, j in combinations(range(dim + 1), 2):
            edge = spokes[j - 1] if i == 0 else corners[j] - corners[i]
            np.maximum(longest, np.einsum("ij,ij->i", edge, edge), out=longest)
        longest = np.sqrt(longest)
        volume = _determinants(spokes)  # signed_measures
        degenerate = ~(np.abs(volume) > DEGENERATE * longest ** dim)
    if np.any(degenerate):
        element = int(np.argmax(degenerate))
        raise InputError(f"{what}: {kind} {element} (nodes {_nodes(t, element)}) has zero {measure} "
                         f"(its nodes lie on one {'line' if dim == 2 else 'plane'}): remove it or "
                         "move its nodes apart")
    _check_facets(t, np.sign(volume), p.shape[1], what, kind, facet, facet_ids)


def _first_equal_neighbours(keys: np.ndarray, count: int,
                            ids: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The order sorting the columns of ``keys`` (node indices below ``count``) and where a
    sorted column equals the next: by their ``ids`` when given (their ranks in that order),
    one int64 per column where they fit, else a lexsort."""
    if ids is not None:
        order = sort_order(ids, int(ids.max(initial=0)) + 1)
        ordered = np.take(ids, order)
        return order, ordered[1:] == ordered[:-1]
    packed = packed_keys(keys, count)
    if packed is None:
        order = np.lexsort(keys[::-1])
        ordered = keys[:, order]
        return order, np.all(ordered[:, 1:] == ordered[:, :-1], axis=0)
    order = np.argsort(packed)
    ordered = packed[order]
    return order, ordered[1:] == ordered[:-1]


def opposite_facets(mesh: Any) -> np.ndarray | None:
    """The ``facet_ids`` of :func:`check_mesh` of a simplex mesh whose facets scikit-fem (or
    :func:`~signorini.fem.topology.with_topology`) has found: its ``t2f``, row j the facet
    opposite node j; None when they are not found yet."""
    if not hasattr(mesh, "_t2f") or mesh.t.shape[0] != mesh.p.shape[0] + 1:
        return None
    local = [set(f) for f in mesh.elem.refdom.facets]
    return mesh.t2f[[next(k for k, f in enumerate(local) if j not in f)
                     for j in range(mesh.t.shape[0])]]


def _facets_sound(t: np.ndarray, orientation: np.ndarray, facet_ids: np.ndarray) -> bool:
    """Whether every facet bounds at most two elements, lying on opposite sides of it: two sums
    over the facets (``facet_ids``, as in :func:`check_mesh`), no sort.

    The side element e lies on of its facet opposite node j (the sign of the permutation from
    e's node order to the facet's nodes sorted, then node j; see :func:`_check_facets`) is
    e's orientation, times the sign of sorting e's nodes, times ``(−1)^(d − r)``, r the rank
    of node j among e's d + 1 nodes: sides sum to zero on a facet between two elements on
    opposite sides. Two elements the same lie on the same side of the facets they share.
    """
    corners = t.shape[0]
    _, odd = sorted_columns(t)
    sign = np.where(odd, -orientation, orientation)
    ids = facet_ids.ravel()
    count = np.bincount(ids)
    if count.max(initial=0) > 2:
        return False
    ranks = [sum((t[k] < t[j]).astype(np.int8) for k in range(corners) if k != j)
             for j in range(corners)]
    side = np.concatenate([np.where((corners - 1 - rank) % 2 == 1, -sign, sign)
                           for rank in ranks])
    return not np.any(np.bincount(ids, weights=side, minlength=count.size)[count == 2])


def _check_facets(t: np.ndarray, orientation: np.ndarray, count: int, what: str, kind: str,
                  facet: str, facet_ids: np.ndarray | None = None) -> None:
    """No two elements the same, at most two elements on a facet, and two on either side of it.

    Two elements are the same when they share a facet and the node opposite it: the sort of
    the facets that finds the shared ones finds them too, next to each other or one apart where
    at most three elements share a facet (more than that is refused anyway).

    The side of a facet an element lies on is the orientation of the simplex (the facet's
    nodes sorted, then the element's node opposite it): the element's own orientation
    (``orientation``, the sign of its measure) times the sign of the permutation from its
    node order to that one, so no coordinate is read again. With ``facet_ids`` the facets are
    grouped by them and only the parity of that permutation is found, not the sorted nodes.
    """
    if facet_ids is not None and _facets_sound(t, orientation, facet_ids):
        return  # nothing to name: the search below runs only to say what is wrong
    corners = t.shape[0]
    local = [[i for i in range(corners) if i != j] for j in range(corners)]
    rows = np.hstack([t[f] for f in local])  # (dim, corners · elements)
    if facet_ids is None:
        nodes, odd = sorted_columns(rows)
    else:  # only the sort's parity: that of the number of pairs out of order (distinct nodes)
        nodes = None
        odd = np.logical_xor.reduce([rows[i] > rows[j]
                                     for i, j in combinations(range(rows.shape[0]), 2)])
    # moving node j to the end passes the corners - 1 - j nodes after it
    moved = np.repeat([(corners - 1 - j) % 2 == 1 for j in range(corners)], t.shape[1])
    element = np.tile(np.arange(t.shape[1]), corners)
    side = np.where(odd ^ moved, -1.0, 1.0) * orientation[element]
    order, same = _first_equal_neighbours(
        nodes, count, None if facet_ids is None else facet_ids.ravel())
    if same.size == 0:
        return
    shared = same[1:] & same[:-1]  # three in a row
    opposite = t.ravel()[order]  # the node each facet leaves out: t[j] for local facet j
    duplicate = [np.nonzero(same & (opposite[1:] == opposite[:-1]))[0],
                 np.nonzero(shared & (opposite[2:] == opposite[:-2]))[0]]
    pairs = [(int(element[order[i]]), int(element[order[i + gap]]))
             for gap, found in enumerate(duplicate, start=1) for i in found[:1]]
    if pairs:
        first, second = min(tuple(sorted(pair)) for pair in pairs)
        raise InputError(f"{what}: {PLURAL[kind]} {first} and {second} are the same {kind} (nodes "
                         f"{_nodes(t, first)}): remove one of them")
    if np.any(shared):
        k = int(np.argmax(shared))
        owners = sorted(int(element[order[i]]) for i in range(k, k + 3))
        shared_nodes = ", ".join(map(str, np.sort(rows[:, order[k]])))
        raise InputError(f"{what}: the {facet} (nodes {shared_nodes}) "
                         f"bounds {PLURAL[kind]} {', '.join(map(str, owners))}, more than two: the mesh "
                         "overlaps itself there; remesh it")
    pairs = np.nonzero(same)[0]
    first, second = order[pairs], order[pairs + 1]
    folded = side[first] == side[second]
    if np.any(folded):
        k = int(np.argmax(folded))
        a, b = sorted((int(element[first[k]]), int(element[second[k]])))
        shared_nodes = ", ".join(map(str, np.sort(rows[:, first[k]])))
        raise InputError(f"{what}: {PLURAL[kind]} {a} and {b} overlap: they lie on the same side of "
                         f"their shared {facet} (nodes {shared_nodes}), so "
                         "the mesh is folded there (an inverted element); remesh it or move its nodes")


def check_obstacle_outside(model: Any) -> None:
    """InputError when the obstacle starts inside the undeformed body (see the module)."""
    nodes = np.asarray(model.contact_nodes)
    if nodes.size == 0:
        return
    points = model.mesh.p[:, nodes].T
    normals, gaps = model.obstacle.normals_and_gaps(points)
    normals, gaps = np.asarray(normals, dtype=float), np.asarray(gaps, dtype=float)
    if not np.all(np.isfinite(gaps)):
        i = int(np.argmax(~np.isfinite(gaps)))
        raise InputError(f"the obstacle gives contact candidate {i} (node {nodes[i]}) the gap "
                         f"{gaps[i]:g}: give an obstacle with a finite distance to the body")
    inside = gaps < -OUTSIDE * model.length_scale
    if np.any(inside):
        i = int(np.argmin(gaps))
        raise InputError(f"the obstacle starts inside the body: contact candidate {i} (node "
                         f"{nodes[i]}, at {_at(points[i])}) is {-gaps[i]:g} inside it; move the "
                         "obstacle out of the undeformed body (every initial gap must be >= 0)")
    facets = np.asarray(model.contact_facets)
    if facets.size == 0:
        return
    outward = np.zeros_like(model.mesh.p.T)
    facet_normals = outward_normals(model.mesh, facets).T
    for row in model.mesh.facets[:, facets]:
        np.add.at(outward, row, facet_normals)
    along = np.einsum("ij,ij->i", normals, outward[nodes])
    away = along < FACING * np.linalg.norm(outward[nodes], axis=1)
    if np.any(away):
        i = int(np.argmax(away))
        raise InputError(f"the obstacle lies on the body's side of contact candidate {i} (node "
                         f"{nodes[i]}, at {_at(points[i])}): its normal there points into the body, "
                         "so the obstacle starts inside it (or the candidates face away from it); "
                         "move the obstacle outside the undeformed body, facing the candidates")


def _at(point: np.ndarray) -> str:
    return "(" + ", ".join(f"{c:g}" for c in point) + ")"


def _normal(value: float) -> bool:
    return bool(np.isfinite(value) and abs(value) >= sys.float_info.min)


def check_units(model: Any) -> None:
    """InputError when the model's units or load are not representable (see the module)."""
    k = 1 if (model.axisymmetric or model.mesh.p.shape[0] == 3) else 0
    L, E = float(model.length_scale), float(model.E)
    U = max((abs(float(v)) for _, nodes, v in model.dirichlet if len(nodes)), default=0.0) or L
    with np.errstate(over="ignore", under="ignore"):  # what is not representable is refused below
        units = {"length scale L": L, "modulus E": E, "displacement unit U": U,
                 "force unit E·U·L^k": E * U * np.float64(L) ** k,
                 "weight unit L^(k+1)": np.float64(L) ** (k + 1)}
    if model.target_load is not None:
        units["target load"] = float(model.target_load)
    for name, value in units.items():
        if not _normal(value):
            given = ", ".join(f"{key}={v:g}" for key, v in model.params.items()
                              if isinstance(v, float))
            raise InputError(f"the scene's {name} = {value:g} is not representable in double "
                             f"precision (from {given or 'its parameters'}): choose units in "
                             "which E, the lengths and the load are nearer 1 (e.g. MPa and mm)")


def check_model(model: Any) -> None:
    """Every check of this module on a :class:`~signorini.fem.model.SceneModel`."""
    check_mesh(model.mesh.p, model.mesh.t, facet_ids=opposite_facets(model.mesh))
    check_units(model)
    check_obstacle_outside(model)


__all__ = ["signed_measures", "check_mesh", "opposite_facets", "check_obstacle_outside",
           "check_units", "check_model", "LENGTH_RANGE"]
