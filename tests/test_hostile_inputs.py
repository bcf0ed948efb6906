"""Hostile input: extreme values, bad meshes and odd arrays, each refused in one line before any work.

The same conventions as tests/test_catalogue.py: each command-line row pins
exit code 2, one line on stderr naming the input at fault, no traceback and
nothing written; each API row pins an InputError naming the argument. Beyond
refusals: a timed-out validation is a failed row (exit 1), and the analytic
comparisons give the same errors in any units in which the solve works.
"""

import json
import warnings

import numpy as np
import pytest
import scipy.sparse as sp

import signorini
from signorini import ContactProblem
from signorini.cli import main
from signorini.errors import InputError
from signorini.fem.checks import check_mesh
from signorini.references.catalogue import reference_metrics
from test_catalogue import SCENE_TOML  # the mesh scene of the catalogue, on a flat

DIGITS_400 = "1" + "0" * 399
FLAT = 'type = "flat"\nheight = 0.0'

#: (argv, words the one line must contain); {inputs} is the folder of input files
CLI = [
    # mesh parameters whose mesh no double (or no mesher) can hold
    *[(["solve", scene, "--set", "grading=1e-300"], ["grading='1e-300'", "[1e-06, 2]"])
      for scene in ("hertz-cylinder", "hertz-sphere", "hertz-sphere-3d", "punch", "reverse-hertz")],
    # a mesh the relaxed mesher folds: named with the way out
    (["solve", "hertz-cylinder", "--set", "grading=1e-4", "--set", "n_contact=10", "--set",
      "mesher=relaxed"],
     ["grading=1e-4", "[1e-06, 2]", "mesher=bisection"]),
    (["solve", "hertz-cylinder", "--set", "a_over_R=1e-300"], ["a_over_R=", "[0.0001, 0.5]"]),
    (["solve", "hertz-sphere", "--set", "a_over_R=0"], ["a_over_R=", "[0.0001, 0.5]"]),
    (["solve", "block", "--set", f"nx={DIGITS_400}"], ["nx=", "400 characters", "at most 40"]),
    (["solve", "hertz-cylinder", "--set", f"n_contact={DIGITS_400}"], ["n_contact=", "at most 40"]),
    (["solve", "hertz-cylinder", "--set", "n_contact=" + "9" * 30], ["n_contact=", "2^53"]),
    (["solve", "block", "--set", "ny=-" + "9" * 30], ["ny=", "2^53"]),
    (["solve", "punch", "--set", "size=1e300"], ["size='1e300'", "[2, 10000]"]),
    (["solve", "reverse-hertz", "--set", "size=1e300"], ["size='1e300'", "[4, 10000]"]),
    # lengths: their squares and cubes must be representable
    *[(["solve", scene, "--set", f"R={value}"], [f"R='{value}'", "length unit"])
      for scene in ("hertz-cylinder", "hertz-sphere", "hertz-sphere-3d", "reverse-hertz")
      for value in ("1e300", "1e-300")],
    (["solve", "punch", "--set", "a=1e300"], ["a='1e300'", "length unit"]),
    *[(["solve", "block", "--set", f"{name}={value}"], [f"{name}='{value}'", "length unit"])
      for name in ("W", "H") for value in ("1e300", "1e-300")],
    (["solve", "block", "--set", "W=1e-90", "--set", "H=1e90"], ["triangle", "zero area"]),
    # loads and moduli: subnormal, or a load no double can hold
    (["solve", "block", "--set", "E=1e-310"], ["E='1e-310'", "double precision"]),
    (["solve", "block", "--set", "delta=4e-320"], ["delta='4e-320'", "double precision"]),
    (["solve", "hertz-sphere", "--set", "E=1e300", "--set", "R=1e100"], ["P = inf", "nearer 1"]),
    (["solve", "hertz-cylinder", "--set", "E=1e-300", "--set", "P=1e300"], ["P=1e+300", "lower P"]),
    (["solve", "reverse-hertz", "--set", "P=1e-300"], ["P=1e-300", "raise P"]),
    (["solve", "hertz-cylinder", "--set", "P=1e-300"], ["P=1e-300", "raise P"]),
    *[(["solve", scene, "--set", "delta=1e-300"], ["delta=1e-300", "raise delta"])
      for scene in ("hertz-sphere", "hertz-cylinder", "reverse-hertz")],
    (["solve", "block", "--set", "E=1e308", "--set", "delta=100"], ["force unit", "nearer 1"]),
    # scene files: TOML, meshes, obstacles
    (["solve", "{inputs}/nested.toml"], ["nested.toml", "nested too deeply"]),
    (["solve", "{inputs}/duplicate.toml"], ["duplicate.msh", "triangles 0 and 8 are the same", "remove one"]),
    (["solve", "{inputs}/degenerate.toml"], ["degenerate.msh", "triangle 8", "zero area"]),
    (["solve", "{inputs}/folded.toml"], ["folded.msh", "overlap", "folded"]),
    (["solve", "{inputs}/fan.toml"], ["fan.msh", "bounds triangles", "more than two"]),
    (["solve", "{inputs}/inside.toml"], ["inside.toml", "[obstacle]", "inside", "move the obstacle"]),
    (["solve", "{inputs}/overlapping.toml"], ["overlapping.toml", "inside the body", "gap"]),
    (["solve", "{inputs}/tiny.toml"], ["tiny.toml", "length_scale", "length unit"]),
    (["solve", "{inputs}/square.toml", "--set", "E=1e-320"], ["square.toml", "modulus E", "nearer 1"]),
    # bench: nothing to run is no run
    (["bench", "--sizes", ""], ["--sizes ''"]),
    (["bench", "--sizes", "0,0"], ["--sizes '0,0'", "twice"]),
    (["bench", "--repeat", "-1"], ["--repeat -1", "at least 1"]),
    (["bench", "--default-only-from", "-1"], ["--default-only-from -1", ">= 0"]),
]


def _write_mesh(folder, name, points, triangles):
    meshio = pytest.importorskip("meshio", reason="scene files read meshes with meshio")
    meshio.write(folder / name, meshio.Mesh(np.asarray(points, float), [("triangle", np.asarray(triangles))]),
                 file_format="gmsh22", binary=False)


@pytest.fixture(scope="module")
def inputs(tmp_path_factory):
    """Scene files with hostile meshes and obstacles, in a folder of their own."""
    from skfem import MeshTri

    folder = tmp_path_factory.mktemp("hostile")
    square = MeshTri.init_tensor([0.0, 0.5, 1.0], [0.0, 0.5, 1.0])  # 9 nodes, 8 triangles
    p, t = square.p.T, square.t.T
    _write_mesh(folder, "square.msh", p, t)
    _write_mesh(folder, "duplicate.msh", p, np.vstack([t, t[:1]]))
    on_bottom = [i for i in range(len(p)) if p[i, 1] == 0.0]
    _write_mesh(folder, "degenerate.msh", p, np.vstack([t, [on_bottom]]))
    moved = p.copy()
    centre = int(np.argmin(np.hypot(p[:, 0] - 0.5, p[:, 1] - 0.5)))
    moved[centre] = [1.4, 0.5]  # the centre node pulled through the right side: folded triangles
    _write_mesh(folder, "folded.msh", moved, t)
    extra = np.vstack([p, [[0.5, -0.5]], [[0.5, 1.5]]])  # two more triangles on one bottom edge
    edge = [i for i in range(len(p)) if p[i, 1] == 0.0][:2]
    _write_mesh(folder, "fan.msh", extra, np.vstack([t, [[edge[0], edge[1], 9]], [[edge[0], edge[1], 10]]]))
    for name, mesh, obstacle in (
            ("square", "square.msh", FLAT), ("duplicate", "duplicate.msh", FLAT),
            ("degenerate", "degenerate.msh", FLAT), ("folded", "folded.msh", FLAT),
            ("fan", "fan.msh", FLAT),
            ("inside", "square.msh", 'type = "circle"\ncentre = [0.5, 0.5]\nradius = 0.2'),
            ("overlapping", "square.msh", 'type = "flat"\nheight = 0.1')):
        (folder / f"{name}.toml").write_text(SCENE_TOML.format(mesh=mesh).replace(FLAT, obstacle))
    (folder / "tiny.toml").write_text(SCENE_TOML.format(mesh="square.msh")
                                      .replace("[material]", "length_scale = 1e-300\n[material]"))
    (folder / "nested.toml").write_text("x = " + "[" * 20_000 + "]" * 20_000 + "\n")
    return folder


def files_under(path):
    return sorted(p for p in path.rglob("*"))


@pytest.mark.parametrize("argv, words", CLI, ids=[" ".join(c[0])[:60] for c in CLI])
def test_hostile_command_lines_are_refused_in_one_line(capsys, tmp_path, monkeypatch, inputs, argv, words):
    monkeypatch.chdir(tmp_path)  # default output folders would land here
    monkeypatch.setenv("SIGNORINI_MAX_MEMORY_GB", "19")
    argv = [a.replace("{inputs}", str(inputs)) for a in argv]
    before = files_under(inputs)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no NumPy warning before the refusal
        got = main(argv)
    out, err = capsys.readouterr()
    assert got == 2, (got, err)
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("signorini: error:"), err
    assert "Traceback" not in err + out
    assert "coarser" not in lines[0] or "grading" in argv[-1]  # no advice about the mesh for units
    for word in words:
        assert word in lines[0], (word, lines[0])
    assert files_under(tmp_path) == []
    assert files_under(inputs) == before


K3, F3, N3, D1 = sp.eye(4, format="csr"), np.ones(4), np.array([[0.6, 0.8, 0.0, 0.0]]), np.ones(1)

#: (what the call does, the call, words its InputError must contain)
API = [
    ("from_qp complex K", lambda: ContactProblem.from_qp(K3 * (1 + 1j), F3, N3, D1), ["K", "complex"]),
    ("from_qp complex f", lambda: ContactProblem.from_qp(K3, F3 * 1j, N3, D1), ["f", "complex"]),
    ("from_qp complex N", lambda: ContactProblem.from_qp(K3, F3, N3 + 0j, D1), ["N", "complex"]),
    ("from_qp complex sparse N",
     lambda: ContactProblem.from_qp(K3, F3, sp.csr_matrix(N3 * (1 + 1j)), D1), ["N", "complex"]),
    ("from_qp complex d", lambda: ContactProblem.from_qp(K3, F3, N3, D1 * 1j), ["d", "complex"]),
    ("from_qp None in N", lambda: ContactProblem.from_qp(K3, F3, [[0.6, None, 0, 0]], D1),
     ["N", "None", "(0, 1)"]),
    ("from_qp None in f", lambda: ContactProblem.from_qp(K3, [1.0, None, 1.0, 1.0], N3, D1),
     ["f", "None", "entry 1"]),
    ("from_qp None in weights",
     lambda: ContactProblem.from_qp(K3, F3, N3, D1, weights=[None]), ["weights", "None"]),
    ("from_qp multiplicity text",
     lambda: ContactProblem.from_qp(K3, F3, N3, D1, force_multiplicity="two"), ["force_multiplicity='two'"]),
    ("from_qp multiplicity nan",
     lambda: ContactProblem.from_qp(K3, F3, N3, D1, force_multiplicity=float("nan")),
     ["force_multiplicity=nan", "> 0"]),
    ("from_qp multiplicity negative",
     lambda: ContactProblem.from_qp(K3, F3, N3, D1, force_multiplicity=-2.0), ["force_multiplicity=-2.0"]),
    ("from_qp multiplicity a bool",
     lambda: ContactProblem.from_qp(K3, F3, N3, D1, force_multiplicity=True), ["force_multiplicity=True"]),
    ("from_qp contact points text",
     lambda: ContactProblem.from_qp(K3, F3, N3, D1, contact_points="here"), ["contact_points", "str"]),
    ("from_qp contact points 3 columns in 2D",
     lambda: ContactProblem.from_qp(K3, F3, N3, D1, contact_points=np.zeros((1, 3))),
     ["contact_points", "3 columns", "2D"]),
    ("from_qp contact points per candidate",
     lambda: ContactProblem.from_qp(K3, F3, N3, D1, contact_points=np.zeros((2, 2))),
     ["contact_points", "(1, 2)"]),
    ("from_qp complex contact points",
     lambda: ContactProblem.from_qp(K3, F3, N3, D1, contact_points=np.zeros((1, 2)) * 1j),
     ["contact_points", "complex"]),
    ("build_problem nondimensionalise text",
     lambda: signorini.build_problem("block", nondimensionalise="no"), ["nondimensionalise='no'"]),
    ("build_problem nondimensionalise a number",
     lambda: signorini.build_problem("block", nondimensionalise=0), ["nondimensionalise=0"]),
    ("build_problem a subnormal modulus",
     lambda: signorini.build_problem("block", params={"E": 1e-320}), ["E="]),
    ("build_problem a length beyond range",
     lambda: signorini.build_problem("block", params={"W": 1e101}), ["W="]),
    ("build_problem a huge count",
     lambda: signorini.build_problem("block", params={"nx": 10 ** 20}), ["nx=", "2^53"]),
]


@pytest.mark.parametrize("call, words", [(c, w) for _, c, w in API], ids=[a[0] for a in API])
def test_hostile_api_calls_raise_input_error_naming_the_argument(call, words):
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no ComplexWarning: complex values are refused, not cast
        with pytest.raises(InputError) as info:
            call()
    message = str(info.value)
    assert "\n" not in message
    for word in words:
        assert word in message, (word, message)


# --- meshes: every check names the element and its nodes ------------------------------------

SQUARE_P = np.array([[0.0, 1.0, 1.0, 0.0], [0.0, 0.0, 1.0, 1.0]])
SQUARE_T = np.array([[0, 1, 2], [0, 2, 3]]).T


BAD_MESHES = [
    (SQUARE_P, np.hstack([SQUARE_T, [[2], [0], [1]]]), ["triangles 0 and 2 are the same", "nodes 0, 1, 2"]),
    (np.hstack([SQUARE_P, [[0.5], [0.0]]]), np.hstack([SQUARE_T, [[0], [4], [1]]]),
     ["triangle 2 (nodes 0, 4, 1)", "zero area"]),
    (SQUARE_P, np.hstack([SQUARE_T, [[0], [0], [1]]]), ["triangle 2", "zero area"]),
    (np.array([[0.0, 1.0, 1.0, 0.5], [0.0, 0.0, 1.0, 0.2]]), np.array([[0, 1, 2], [1, 2, 3]]).T,
     ["triangles 0 and 1 overlap", "nodes 1, 2", "folded"]),  # node 3 on node 0's side of edge 1-2
    (np.hstack([SQUARE_P, [[0.5], [-1.0]]]), np.hstack([SQUARE_T, [[0], [1], [4]], [[1], [0], [4]]]),
     ["same"]),
    (np.hstack([SQUARE_P, [[0.5], [-1.0]], [[0.5], [2.0]]]),
     np.hstack([SQUARE_T, [[0], [1], [4]], [[0], [2], [5]]]), ["edge (nodes 0, 2) bounds triangles 0, 1, 3", "more than two"]),
    (np.array([[0.0, 1.0, np.nan], [0.0, 0.0, 1.0]]), np.array([[0, 1, 2]]).T, ["node 2", "non-finite"]),
    (SQUARE_P, np.array([[0, 1, 7]]).T, ["triangle 0", "node the mesh does not have"]),
]


@pytest.mark.parametrize("p, t, words", BAD_MESHES)
def test_a_bad_mesh_is_refused_naming_the_element(p, t, words):
    with pytest.raises(InputError) as info:
        check_mesh(p, t, "the test mesh")
    for word in words:
        assert word in str(info.value), (word, str(info.value))


@pytest.mark.parametrize("p, t", [(p, t) for p, t, _ in BAD_MESHES
                                  if np.isfinite(p).all() and t.max() < p.shape[1]]
                         + [(SQUARE_P, SQUARE_T)])
def test_the_mesh_checks_given_the_facets_found_say_what_they_say_sorting_them(p, t):
    from skfem import MeshTri

    from signorini.fem.checks import opposite_facets
    from signorini.fem.topology import with_topology

    mesh = with_topology(MeshTri(p, t))
    said = []
    for facet_ids in (None, opposite_facets(mesh)):
        try:
            check_mesh(mesh.p, mesh.t, "the test mesh", facet_ids=facet_ids)
            said.append(None)
        except InputError as error:
            said.append(str(error))
    assert opposite_facets(mesh) is not None and said[0] == said[1]


def test_a_folded_tetrahedral_mesh_is_named_alike_given_its_facets_or_not():
    from skfem import MeshTet

    from signorini.fem.checks import opposite_facets
    from signorini.fem.topology import with_topology

    mesh = MeshTet().refined(2)
    inner = np.setdiff1d(np.arange(mesh.p.shape[1]), mesh.boundary_nodes())[0]
    p = mesh.p.copy()
    p[:, inner] += [0.3, 0.2, 0.1]  # pushed through its neighbours' facets
    folded = with_topology(MeshTet(p, mesh.t, sort_t=False))
    said = []
    for facet_ids in (None, opposite_facets(folded)):
        with pytest.raises(InputError, match="overlap") as info:
            check_mesh(p, mesh.t, "the test mesh", facet_ids=facet_ids)
        said.append(str(info.value))
    assert said[0] == said[1]


@pytest.mark.parametrize("dim", [2, 3])
def test_a_sound_mesh_given_its_facets_is_accepted_without_sorting_them(dim, monkeypatch):
    """Given the facets found, a sound mesh (its elements' nodes in any order, so of either
    orientation) is passed by two sums over its facets; the sort that names a fault never runs."""
    from skfem import MeshTet, MeshTri

    from signorini.fem import checks
    from signorini.fem.topology import with_topology

    mesh = (MeshTri if dim == 2 else MeshTet)().refined(3 if dim == 2 else 2)
    rng = np.random.default_rng(1)
    t = np.take_along_axis(mesh.t, np.argsort(rng.random(mesh.t.shape), axis=0), axis=0)
    shuffled = with_topology(type(mesh)(mesh.p, t, sort_t=False))
    monkeypatch.setattr(checks, "_first_equal_neighbours", lambda *a: pytest.fail("sorted"))
    check_mesh(mesh.p, t, facet_ids=checks.opposite_facets(shuffled))
    inner = np.setdiff1d(np.arange(mesh.p.shape[1]), mesh.boundary_nodes())[0]
    p = mesh.p.copy()
    p[:, inner] += 0.3  # pushed through its neighbours' facets: two elements on one side
    volume = checks.signed_measures(p, t)
    assert not checks._facets_sound(t, np.sign(volume), checks.opposite_facets(shuffled))


def test_a_mesh_of_either_orientation_is_accepted():
    check_mesh(SQUARE_P, SQUARE_T)
    check_mesh(SQUARE_P, SQUARE_T[[0, 2, 1]])  # both clockwise
    check_mesh(SQUARE_P, np.array([[0, 1, 2], [0, 3, 2]]).T)  # one of each: integrated with |det J|


def test_a_tetrahedral_mesh_with_a_flat_element_is_refused():
    from skfem import MeshTet

    mesh = MeshTet()
    check_mesh(mesh.p, mesh.t)
    base = np.nonzero(mesh.p[2] == 0.0)[0][:3]
    p = np.hstack([mesh.p, mesh.p[:, base].mean(axis=1, keepdims=True)])  # in their plane z = 0
    flat = np.append(base, p.shape[1] - 1)[:, None]
    with pytest.raises(InputError, match=f"tetrahedron {mesh.t.shape[1]} .* zero volume"):
        check_mesh(p, np.hstack([mesh.t, flat]))
    with pytest.raises(InputError, match="tetrahedra 0 and .* are the same"):
        check_mesh(mesh.p, np.hstack([mesh.t, mesh.t[::-1, :1]]))


# --- failed runs and unit-free comparisons --------------------------------------------------


def test_a_timed_out_validation_is_a_failed_row_not_a_traceback(capsys, tmp_path):
    got = main(["validate", "--case", "hertz-cylinder", "--method", "uzawa", "--time-limit", "0.5",
                "--out", str(tmp_path / "out")])
    out, err = capsys.readouterr()
    assert got == 1, err
    assert "Traceback" not in out + err
    report = json.loads((tmp_path / "out" / "report.json").read_text())
    timed_out = [r for r in report["runs"] if r["method"] == "uzawa"]
    assert not report["passed"] and timed_out and timed_out[0]["status"] == "timeout"
    assert timed_out[0]["kkt_worst"] is None  # unmeasured, written as null


@pytest.fixture(scope="module")
def unit_modulus_metrics():
    return {scene: reference_metrics(r.problem, r.solution) for scene in ("hertz-cylinder", "hertz-sphere-3d")
            for r in [signorini.solve(scene)]}


@pytest.mark.parametrize("scene, params", [
    ("hertz-cylinder", {"E": 1e300}),
    ("hertz-cylinder", {"E": 1e-300}),
    ("hertz-sphere-3d", {"E": 1e300}),
    ("hertz-sphere-3d", {"E": 1e-300}),
])
def test_hertz_comparisons_are_the_same_in_any_representable_units(unit_modulus_metrics, scene, params):
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no overflow on the way
        result = signorini.solve(scene, params=params)
        metrics = reference_metrics(result.problem, result.solution)
    expected = unit_modulus_metrics[scene]
    for key in ("a_rel", "p0_rel", "pressure_l2_rel"):
        assert np.isfinite(metrics[key]), (key, metrics)
        assert metrics[key] == pytest.approx(expected[key], rel=1e-6, abs=1e-12), key


def test_a_sphere_in_extreme_units_solves_and_compares():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        result = signorini.solve("hertz-sphere", params={"E": 1e250, "R": 1e-100})
        record = result.to_dict()
    assert result.solution.status == "converged"
    assert record["hertz"]["a_rel"] < 0.01 and record["hertz"]["p0_rel"] < 0.01


@pytest.mark.parametrize("dim", [2, 3])
def test_a_duplicated_interior_element_is_named_whatever_its_node_order(dim):
    """Every facet of an interior element is shared three ways once it is duplicated (found by
    a sort of the facets, or from the facets found for the mesh)."""
    from skfem import MeshTet, MeshTri

    from signorini.fem.checks import opposite_facets
    from signorini.fem.topology import with_topology

    mesh = (MeshTri if dim == 2 else MeshTet)().refined(2)
    interior = np.nonzero(np.all(mesh.f2t >= 0, axis=0))[0]
    counts = np.bincount(mesh.t2f.ravel(), minlength=mesh.facets.shape[1])
    inner = [e for e in range(mesh.t.shape[1]) if np.isin(mesh.t2f[:, e], interior).all()]
    assert inner and counts.max() <= 2
    element = inner[len(inner) // 2]
    for order in ([1, 0, *range(2, dim + 1)], list(range(dim + 1))[::-1]):
        t = np.hstack([mesh.t, mesh.t[order, element:element + 1]])
        kind = "triangles" if dim == 2 else "tetrahedra"
        for facet_ids in (None, opposite_facets(with_topology(type(mesh)(mesh.p, t, sort_t=False)))):
            with pytest.raises(InputError,
                               match=f"{kind} {element} and {mesh.t.shape[1]} are the same"):
                check_mesh(mesh.p, t, facet_ids=facet_ids)
