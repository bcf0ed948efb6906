"""The catalogue of bad input (issue 13 §2): one row per case, over the command line and the API.

Each command-line row pins the exit code, a one-line message on stderr that
names the input at fault, no traceback and no file touched in the working
folder (every output flag points into it). Each API row pins an InputError
whose message names the argument. Commands run in process through
:func:`signorini.cli.main`; nothing here solves a problem (every case is
refused before the work), except where a row says so.
"""

import numpy as np
import pytest
import scipy.sparse as sp

import signorini
from signorini import ContactProblem
from signorini.cli import main
from signorini.errors import InputError
from signorini.scenes.block import force_controlled_problem

LOAD = "0.001:0.002:3"
SCENE_TOML = """[mesh]
file = "{mesh}"
[material]
E = 1.0
nu = 0.3
[[dirichlet]]
boundary = {{y = 1.0}}
component = "y"
value = -0.01
[contact]
boundary = {{y = 0.0}}
[obstacle]
type = "flat"
height = 0.0
[load]
boundary = {{y = 1.0}}
component = "y"
"""

#: (argv, exit code, words the one line must contain); {inputs} is the folder of input files
CLI = [
    # the command line itself
    (["frobnicate"], 2, ["invalid choice", "frobnicate"]),
    (["solve"], 2, ["scene"]),
    (["solve", "block", "--bogus"], 2, ["unrecognized arguments", "--bogus"]),
    (["methods", "--all"], 2, ["--all"]),
    # scenes and their parameters
    (["solve", "nowhere"], 2, ["unknown scene", "'nowhere'"]),
    (["solve", "block", "--set", "E=-1"], 2, ["E=", "> 0"]),
    (["solve", "block", "--set", "nu=0.5"], 2, ["nu=", "(-1, 0.5)"]),
    (["solve", "block", "--set", "nu=abc"], 2, ["nu=", "float"]),
    (["solve", "block", "--set", "W=inf"], 2, ["W=", "finite"]),
    (["solve", "block", "--set", "nx=2.5"], 2, ["nx=", "int"]),
    (["solve", "block", "--set", "colour=red"], 2, ["no parameter 'colour'"]),
    (["solve", "block", "--set", "novalue"], 2, ["--set", "key=value"]),
    (["solve", "block", "--set", "touching=1"], 2, ["touching=", "[0, 1)"]),
    (["solve", "hertz-cylinder", "--set", "refine=9"], 2, ["refine=", "0..6"]),
    (["solve", "hertz-sphere-3d", "--set", "refine=4"], 2, ["refine=", "0..3"]),
    (["solve", "hertz-cylinder", "--set", "n_contact=2"], 2, ["n_contact=", ">= 4"]),
    (["solve", "hertz-cylinder", "--set", "mesher=magic"], 2, ["mesher=", "relaxed"]),
    (["solve", "hertz-cylinder", "--set", "loading=gravity"], 2, ["loading=", "traction"]),
    # size before allocation
    (["solve", "hertz-cylinder", "--set", "refine=6"], 2, ["refine=6", "dofs", "GB",
                                                         "SIGNORINI_MAX_MEMORY_GB"]),
    (["solve", "hertz-sphere-3d", "--set", "refine=3", "--set", "n_contact=20"], 2,
     ["refine=3", "dofs", "GB"]),
    (["solve", "block", "--set", "nx=100000", "--set", "ny=100000"], 2, ["nx=100000", "dofs"]),
    (["solve", "punch", "--set", "n_contact=10000000"], 2, ["n_contact=1e+07", "dofs"]),
    (["solve", "hertz-sphere-3d", "--set", "grading=0.01"], 2, ["grading=0.01", "tetrahedra"]),
    # methods and their options
    (["solve", "block", "--method", "simplex"], 2, ["unknown method", "'simplex'", "pdas"]),
    (["solve", "block", "--method", "pdas", "--opt", "c=abc"], 2, ["c='abc'", "positive"]),
    (["solve", "block", "--method", "pdas", "--opt", "c=0"], 2, ["c=0", "positive"]),
    (["solve", "block", "--method", "pdas", "--opt", "bogus=1"], 2, ["'bogus'", "accepted"]),
    (["solve", "block", "--method", "pdas", "--opt", "callback=foo"], 2, ["callback='foo'"]),
    (["solve", "block", "--method", "pdas", "--opt", "backend=magic"], 2, ["backend='magic'"]),
    (["solve", "block", "--method", "pdas", "--opt", "lam0=1"], 2, ["lam0=1", "Python API"]),
    (["solve", "block", "--method", "uzawa", "--opt", "rho=-1"], 2, ["rho=-1", "positive"]),
    (["solve", "block", "--method", "uzawa", "--opt", "rho=inf"], 2, ["rho=inf"]),
    (["solve", "block", "--method", "uzawa", "--opt", "step_fraction=nan"], 2, ["step_fraction=nan"]),
    (["solve", "block", "--method", "uzawa", "--opt", "operator=magic"], 2, ["operator='magic'"]),
    (["solve", "block", "--method", "uzawa", "--opt", "divergence_factor=-1"], 2,
     ["divergence_factor=-1"]),
    (["solve", "block", "--method", "uzawa", "--opt", "max_iter=0"], 2, ["max_iter", "positive"]),
    (["solve", "block", "--method", "uzawa", "--opt", "max_iter=2.5"], 2, ["max_iter", "2.5"]),
    (["solve", "block", "--method", "uzawa-nesterov", "--opt", "acceleration=heavy"], 2,
     ["acceleration='heavy'"]),
    (["solve", "block", "--method", "condensed", "--opt", "block=abc"], 2, ["block='abc'"]),
    (["solve", "block", "--method", "condensed", "--opt", "max_candidates=-3"], 2,
     ["max_candidates=-3"]),
    (["solve", "block", "--method", "nested", "--opt", "neighbours=abc"], 2, ["neighbours='abc'"]),
    (["solve", "block", "--method", "nested", "--opt", "analytic=maybe"], 2, ["analytic='maybe'"]),
    (["solve", "block", "--method", "qp-osqp", "--opt", "time_limit=-1"], 2,
     ["time_limit=-1", "positive"]),
    (["solve", "block", "--method", "qp-osqp", "--opt", "eps_abs=abc"], 2, ["eps_abs='abc'"]),
    (["solve", "block", "--method", "qp-osqp", "--opt", "rho=abc"], 2, ["rho='abc'"]),
    (["solve", "block", "--method", "qp-osqp", "--opt", "polish=3"], 2, ["polish=3"]),
    (["solve", "block", "--method", "qp-osqp", "--opt", "form=primel"], 2, ["form='primel'"]),
    (["solve", "block", "--method", "qp-osqp", "--opt", "max_dense_dofs=-1"], 2,
     ["max_dense_dofs=-1"]),
    (["solve", "block", "--method", "qp-clarabel", "--opt", "time_limit=-5"], 2, ["time_limit=-5"]),
    (["solve", "block", "--method", "qp-highs", "--opt", "time_limit=-1"], 2, ["time_limit=-1"]),
    (["solve", "block", "--method", "qp-scs", "--opt", "max_iters=abc"], 2, ["max_iters='abc'"]),
    (["solve", "block", "--method", "qp-daqp", "--opt", "iter_limit=-2"], 2, ["iter_limit=-2"]),
    (["solve", "block", "--method", "qp-gurobi", "--opt", "TimeLimit=-1"], 2, ["TimeLimit=-1"]),
    (["solve", "block", "--method", "petsc-vi", "--opt", "ksp=cg"], 2, ["ksp='cg'"]),
    (["solve", "block", "--method", "cvxpy", "--opt", "polish=sometimes"], 2, ["polish='sometimes'"]),
    (["solve", "block", "--opt", "novalue"], 2, ["--opt", "key=value"]),
    # tolerances and limits
    (["solve", "block", "--tol", "nan"], 2, ["--tol", "(0, 1)"]),
    (["solve", "block", "--tol", "1"], 2, ["--tol", "(0, 1)"]),
    (["solve", "block", "--tol", "tight"], 2, ["--tol", "'tight'"]),
    (["solve", "block", "--tol", "1e-20"], 2, ["--tol", "double precision"]),
    (["solve", "block", "--time-limit", "0"], 2, ["--time-limit", "positive"]),
    (["solve", "block", "--time-limit", "soon"], 2, ["--time-limit", "'soon'"]),
    (["solve", "hertz-cylinder", "--time-limit", "5", "--target-error", "0.01"], 2,
     ["--time-limit", "--target-error"]),
    (["solve", "block", "--max-dofs", "1000"], 2, ["max_dofs", "target_error"]),
    # user methods
    (["solve", "block", "--method", "nofile.py:solve"], 2, ["nofile.py"]),
    (["solve", "block", "--method", "os:no_such_function"], 2, ["'os'", "no_such_function"]),
    (["solve", "block", "--method", "{inputs}/syntax.py:solve"], 2, ["syntax.py", "syntax error"]),
    (["solve", "block", "--method", "{inputs}/exits.py:solve"], 2, ["exits.py", "sys.exit(3)"]),
    (["solve", "block", "--method", "{inputs}/raises.py:solve"], 2, ["raises.py", "NameError"]),
    (["solve", "block", "--method", "no_such_module_anywhere:solve"], 2,
     ["no_such_module_anywhere"]),
    # scene files and meshes
    (["solve", "missing.toml"], 2, ["missing.toml"]),
    (["solve", "{inputs}/notmesh.toml"], 2, ["notmesh.msh", "cannot be read"]),
    (["solve", "{inputs}/empty.toml"], 2, ["empty.msh", "cannot be read"]),
    (["solve", "{inputs}/nofile.toml"], 2, ["nofile.msh", "does not exist"]),
    (["solve", "{inputs}/weird.toml"], 2, ["weird.xyz", "cannot be read"]),
    (["solve", "{inputs}/lines.toml"], 2, ["lines.msh", "no triangles"]),
    (["solve", "{inputs}/nocontact.toml"], 2, ["contact", "y = 5.0"]),
    (["solve", "{inputs}/broken.toml"], 2, ["broken.toml"]),
    # outputs
    (["solve", "block", "--json", "{inputs}/nodir/r.json"], 2, ["--json", "does not exist"]),
    (["solve", "block", "--json", "{inputs}"], 2, ["--json", "directory"]),
    (["solve", "block", "--json", "x" * 300 + ".json"], 2, ["--json", "bytes long"]),
    (["solve", "block", "--vtk", "out.txt"], 2, ["--vtk", ".vtu"]),
    (["solve", "block", "--vtk", "{inputs}/nodir/r.vtu"], 2, ["--vtk", "does not exist"]),
    (["solve", "block", "--json", "r.json", "--vtk", "{inputs}/nodir/r.vtu"], 2, ["--vtk"]),
    # converge
    (["converge", "block"], 2, ["'block'", "refine"]),
    (["converge", "hertz-cylinder", "--method", "nope"], 2, ["unknown method", "'nope'"]),
    (["converge", "hertz-cylinder", "--levels", "1", "--fit-from", "5"], 2, ["--fit-from 5"]),
    (["converge", "hertz-cylinder", "--levels", "2", "--fit-from", "-1"], 2, ["--fit-from -1"]),
    (["converge", "hertz-cylinder", "--levels", "7"], 2, ["--levels 7", "0..6"]),
    (["converge", "hertz-sphere-3d", "--levels", "4"], 2, ["--levels 4", "refine=4"]),
    (["converge", "hertz-cylinder", "--set", "refine=1"], 2, ["--levels", "refine"]),
    (["converge", "hertz-cylinder", "--uniform-levels", "9"], 2, ["--uniform-levels 9"]),
    # sweep
    (["sweep", "hertz-cylinder", "--load", "1:2"], 2, ["--load", "P1:P2:n"]),
    (["sweep", "hertz-cylinder", "--load", "0.004:0.001:3"], 2, ["--load", "P1 ≤ P2"]),
    (["sweep", "hertz-cylinder", "--load", "0.001:0.002:0"], 2, ["--load", "n ≥ 1"]),
    (["sweep", "hertz-cylinder", "--load", "0.001:1e400:3"], 2, ["--load"]),
    (["sweep", "hertz-cylinder", "--load", "0.001:0.002:1000000000"], 2, ["--load", "at most 1000"]),
    (["sweep", "nowhere", "--load", LOAD], 2, ["unknown scene"]),
    (["sweep", "hertz-cylinder", "--load", LOAD, "--set", "refine=6"], 2, ["refine=6", "dofs"]),
    # bench
    (["bench", "--method", "nope"], 2, ["unknown method", "'nope'"]),
    (["bench", "--sizes", "a,b"], 2, ["--sizes"]),
    (["bench", "--sizes", "7", "--method", "pdas"], 2, ["--sizes", "level 7"]),
    (["bench", "--sizes", "-1", "--method", "pdas"], 2, ["--sizes", "level -1", "0..6"]),
    (["bench", "--tol", "tight"], 2, ["--tol", "'tight'"]),
    (["bench", "--time-limit", "-1"], 2, ["--time-limit"]),
    (["bench", "--ranks", "0"], 2, ["--ranks"]),
    (["bench", "--sizes", "6", "--method", "pdas", "--scene", "hertz-cylinder"], 2, ["dofs", "GB"]),
    # validate and stability
    (["validate", "--time-limit", "nan"], 2, ["--time-limit"]),
    (["validate", "--method", "nope"], 2, ["unknown method", "'nope'"]),
    (["validate", "--case", "nowhere"], 2, ["nowhere"]),
    (["stability", "--axis", "9"], 2, ["--axis", "'9'"]),
    (["stability", "--time-limit", "-3"], 2, ["--time-limit", "positive"]),
]


@pytest.fixture(scope="module")
def inputs(tmp_path_factory):
    """Input files the rows refer to, in a folder of their own (not the working folder)."""
    folder = tmp_path_factory.mktemp("inputs")
    (folder / "syntax.py").write_text("def solve(problem, **options)\n    return None\n")
    (folder / "exits.py").write_text("import sys\nsys.exit(3)\n")
    (folder / "raises.py").write_text("x = undefined_name\n")
    (folder / "notmesh.msh").write_text("hello\n")
    (folder / "empty.msh").write_text("")
    (folder / "weird.xyz").write_text("x")
    (folder / "lines.msh").write_text(
        "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n2\n1 0 0 0\n2 1 0 0\n$EndNodes\n"
        "$Elements\n1\n1 1 2 0 1 1 2\n$EndElements\n")
    for name, mesh in (("notmesh", "notmesh.msh"), ("empty", "empty.msh"),
                       ("nofile", "nofile.msh"), ("weird", "weird.xyz"), ("lines", "lines.msh")):
        (folder / f"{name}.toml").write_text(SCENE_TOML.format(mesh=mesh))
    meshio = pytest.importorskip("meshio", reason="scene files read meshes with meshio")
    from skfem import MeshTri

    square = MeshTri.init_tensor([0.0, 0.5, 1.0], [0.0, 0.5, 1.0])
    meshio.write(folder / "square.msh", meshio.Mesh(square.p.T, [("triangle", square.t.T)]),
                 file_format="gmsh22", binary=False)
    (folder / "nocontact.toml").write_text(
        SCENE_TOML.format(mesh="square.msh").replace("boundary = {y = 0.0}", "boundary = {y = 5.0}"))
    (folder / "broken.toml").write_text("[mesh\nfile = 3\n")
    return folder


def files_under(path):
    return sorted(p for p in path.rglob("*"))


@pytest.mark.parametrize("argv, code, words", CLI, ids=[" ".join(c[0])[:60] for c in CLI])
def test_the_command_line_refuses_bad_input(capsys, tmp_path, monkeypatch, inputs, argv, code, words):
    monkeypatch.chdir(tmp_path)  # default output folders would land here
    monkeypatch.setenv("SIGNORINI_MAX_MEMORY_GB", "19")  # the refusals of this 24 GB machine
    argv = [a.replace("{inputs}", str(inputs)) for a in argv]
    out_flag = {"converge": ["--out", "out"], "sweep": ["--out", "out"], "bench": ["--out", "out"],
                "validate": ["--out", "out"], "stability": ["--out", "out"]}.get(argv[0], [])
    before = files_under(inputs)
    got = main([*argv, *out_flag])
    out, err = capsys.readouterr()
    assert got == code, (got, err)
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("signorini: error:"), err
    assert "Traceback" not in err + out
    for word in words:
        assert word in lines[0], (word, lines[0])
    assert files_under(tmp_path) == []  # nothing written, no folder made
    assert files_under(inputs) == before


def _problem():
    return signorini.build_problem("block")


def _solution():
    return signorini.solve(_problem()).solution


K3, F3, N3, D1 = sp.eye(3, format="csr"), np.ones(3), np.ones((1, 3)), np.ones(1)

#: (what the call does, the call, words its InputError must contain)
API = [
    ("build_problem with a number for the scene", lambda: signorini.build_problem(3), ["scene", "int"]),
    ("build_problem with None", lambda: signorini.build_problem(None), ["scene", "NoneType"]),
    ("build_problem unknown scene", lambda: signorini.build_problem("nowhere"), ["'nowhere'"]),
    ("build_problem bad parameter", lambda: signorini.build_problem("block", params={"nx": "a"}), ["nx="]),
    ("build_problem unknown parameter", lambda: signorini.build_problem("block", params={"colour": 1}),
     ["'colour'"]),
    ("build_problem too big", lambda: signorini.build_problem("hertz-cylinder", params={"refine": 6}),
     ["dofs", "GB"]),
    ("build_problem params a number", lambda: signorini.build_problem("block", 4),
     ["params", "int", "params={"]),
    ("build_problem params keyed by number", lambda: signorini.build_problem("block", {1: 2.0}),
     ["params", "1", "strings"]),
    ("force-controlled block params a list",
     lambda: force_controlled_problem(0.01, ["nx", 4]), ["params", "list"]),
    ("solve method a number", lambda: signorini.solve(_problem(), 3), ["method", "int"]),
    ("solve unknown method", lambda: signorini.solve(_problem(), "simplex"), ["'simplex'"]),
    ("solve a list", lambda: signorini.solve([1, 2]), ["problem", "list"]),
    ("solve params a list", lambda: signorini.solve("block", params=[1]), ["params", "list"]),
    ("solve params with a problem", lambda: signorini.solve(_problem(), params={"E": 1}),
     ["params="]),
    ("solve tol a string", lambda: signorini.solve("block", tol="a"), ["tol", "'a'"]),
    ("solve tol negative", lambda: signorini.solve("block", tol=-1e-9), ["tol"]),
    ("solve tol too small", lambda: signorini.solve("block", tol=1e-17), ["tol", "double"]),
    ("solve max_iter zero", lambda: signorini.solve("block", max_iter=0), ["max_iter"]),
    ("solve max_iter a string", lambda: signorini.solve("block", max_iter="9"), ["max_iter"]),
    ("solve unknown option", lambda: signorini.solve("block", bad_option=1), ["'bad_option'"]),
    ("solve option of the wrong kind", lambda: signorini.solve("block", "pdas", c="abc"),
     ["c='abc'"]),
    ("solve option a bool for a number", lambda: signorini.solve("block", "pdas", c=True),
     ["c=True"]),
    ("solve lam0 of the wrong length", lambda: signorini.solve("block", "pdas", lam0=[1.0]),
     ["lam0", "17"]),
    ("solve lam0 text", lambda: signorini.solve("block", "uzawa", lam0="abc"), ["lam0='abc'"]),
    ("solve callback not callable", lambda: signorini.solve("block", "uzawa", callback=3),
     ["callback=3"]),
    ("solve max_dofs without target", lambda: signorini.solve("block", max_dofs=10), ["max_dofs"]),
    ("solve target_error on a problem", lambda: signorini.solve(_problem(), target_error=0.01),
     ["target_error", "solve_adaptive"]),
    ("solve_adaptive on a problem", lambda: signorini.solve_adaptive(_problem(), 0.01),
     ["by name"]),
    ("certificate of a string", lambda: signorini.certificate(_problem(), "x"),
     ["solution", "str"]),
    ("certificate for a string", lambda: signorini.certificate("x", _solution()),
     ["problem", "str"]),
    ("certificate of None", lambda: signorini.certificate(_problem(), None), ["NoneType"]),
    ("certificate of a Result", lambda: signorini.certificate(_problem(), signorini.solve("block")),
     ["result.solution"]),
    ("certificate against a pending target load",
     lambda: signorini.certificate(signorini.build_problem("hertz-cylinder"),
                                   signorini.solve("hertz-cylinder").solution),
     ["target load", "result.problem", "at_load"]),
    ("certificate of another problem's answer",
     lambda: signorini.certificate(signorini.build_problem("block", params={"nx": 8}), _solution()),
     ["solution.u", "entries"]),
    ("from_qp K text", lambda: ContactProblem.from_qp("K", F3, N3, D1), ["K", "str"]),
    ("from_qp K not square", lambda: ContactProblem.from_qp(sp.eye(3, 4), F3, N3, D1), ["K", "square"]),
    ("from_qp f too short", lambda: ContactProblem.from_qp(K3, np.ones(2), N3, D1), ["f", "(3,)"]),
    ("from_qp f a matrix", lambda: ContactProblem.from_qp(K3, np.ones((3, 1)), N3, D1), ["f", "1D"]),
    ("from_qp f text", lambda: ContactProblem.from_qp(K3, ["a", "b", "c"], N3, D1), ["f"]),
    ("from_qp f not finite", lambda: ContactProblem.from_qp(K3, np.array([1, np.nan, 1]), N3, D1),
     ["f", "non-finite"]),
    ("from_qp N columns", lambda: ContactProblem.from_qp(K3, F3, np.ones((1, 2)), D1), ["N", "(m, 3)"]),
    ("from_qp N text", lambda: ContactProblem.from_qp(K3, F3, "N", D1), ["N", "str"]),
    ("from_qp d length", lambda: ContactProblem.from_qp(K3, F3, N3, np.ones(2)), ["d", "(1,)"]),
    ("from_qp no candidates", lambda: ContactProblem.from_qp(K3, F3, np.ones((0, 3)), np.ones(0)),
     ["no contact candidates"]),
    ("from_qp K not finite",
     lambda: ContactProblem.from_qp(sp.diags([1.0, np.inf, 1.0]), F3, N3, D1), ["non-finite"]),
]


@pytest.mark.parametrize("call, words", [(c, w) for _, c, w in API], ids=[a[0] for a in API])
def test_the_api_refuses_bad_input_naming_the_argument(call, words):
    with pytest.raises(InputError) as info:
        call()
    message = str(info.value)
    assert "\n" not in message
    for word in words:
        assert word in message, (word, message)


def test_the_catalogue_has_at_least_100_cases():
    assert len(CLI) + len(API) >= 100
