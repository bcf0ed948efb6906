"""Bad input across the command line: one line naming the parameter and the fix, exit code 2.

Collected here: the flags of ``stability``, ``bench`` and ``sweep``, method
options and tolerances of ``solve``, the block's ``touching``, scene files
whose contact set is empty, and unwritable outputs. Each case also checks
that nothing was written. (Scene parameters, scene and method names and
unknown options are covered by tests/test_cli.py and tests/test_scenes_input.py.)
"""

import subprocess
import sys

import pytest

from signorini.cli import main


def run(capsys, argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def files_under(path):
    return sorted(p for p in path.rglob("*") if p.is_file())


def assert_one_line_exit_2(code, err, words):
    assert code == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("signorini: error:"), err
    assert "Traceback" not in err
    for word in words:
        assert word in lines[0], (word, lines[0])


LOAD = "0.001:0.002:3"

CASES = [
    # signorini stability
    (["stability", "--axis", "9"], ["--axis", "'9'", "uzawa-step"]),
    (["stability", "--axis", "speed"], ["--axis", "'speed'", "ill-posed"]),
    (["stability", "--axis", "1", "--axis", "0"], ["--axis", "'0'"]),
    (["stability", "--time-limit", "0"], ["--time-limit", "positive"]),
    (["stability", "--time-limit", "-3"], ["--time-limit", "positive"]),
    (["stability", "--time-limit", "nan"], ["--time-limit", "positive"]),
    (["stability", "--time-limit", "inf"], ["--time-limit", "positive"]),
    (["stability", "--time-limit", "ten"], ["--time-limit", "e.g."]),
    (["stability", "--quick", "--fast"], ["unrecognized arguments", "--fast"]),
    # signorini bench
    (["bench", "--sizes", "a,b"], ["--sizes", "e.g."]),
    (["bench", "--sizes", "7", "--method", "pdas"], ["--sizes '7'", "0..6"]),
    (["bench", "--tol", "tight"], ["--tol", "'tight'", "high"]),
    (["bench", "--method", "simplex"], ["unknown method", "pdas"]),
    (["bench", "--scene", "nowhere"], ["unknown scene"]),
    (["bench", "--set", "nu=0.7", "--method", "pdas"], ["nu=", "(-1, 0.5)"]),
    (["bench", "--time-limit", "abc"], ["--time-limit", "abc"]),
    # signorini sweep
    (["sweep", "hertz-cylinder", "--load", "1:2"], ["--load", "P1:P2:n"]),
    (["sweep", "hertz-cylinder", "--load", "a:b:3"], ["--load", "P1:P2:n"]),
    (["sweep", "hertz-cylinder", "--load", "0.001:0.002:0"], ["--load", "n ≥ 1"]),
    (["sweep", "hertz-cylinder", "--load", "nan:0.002:3"], ["--load"]),
    (["sweep", "hertz-cylinder", "--load", "0.004:0.001:3"], ["--load", "P1 ≤ P2"]),
    (["sweep", "hertz-cylinder"], ["--load", "required"]),
    (["sweep", "nowhere", "--load", LOAD], ["unknown scene"]),
    (["sweep", "hertz-cylinder", "--load", LOAD, "--set", "n_contact=2"], ["n_contact=", ">= 4"]),
    # signorini solve: tolerances, method options, non-finite values
    (["solve", "block", "--tol", "nan"], ["--tol", "(0, 1)"]),
    (["solve", "block", "--tol", "inf"], ["--tol", "(0, 1)"]),
    (["solve", "block", "--tol", "1"], ["--tol", "(0, 1)"]),
    (["solve", "block", "--method", "uzawa", "--opt", "step_fraction=nan"], ["step_fraction=nan"]),
    (["solve", "block", "--method", "uzawa", "--opt", "rho=-1"], ["rho=-1", "positive"]),
    (["solve", "block", "--method", "uzawa", "--opt", "rho=inf"], ["rho=inf", "positive"]),
    (["solve", "block", "--method", "uzawa", "--opt", "max_iter=0"], ["max_iter", "positive integer"]),
    (["solve", "block", "--method", "uzawa", "--opt", "max_iter=2.5"], ["max_iter", "2.5"]),
    (["solve", "block", "--method", "uzawa", "--opt", "operator=magic"], ["operator='magic'"]),
    (["solve", "block", "--method", "pdas", "--opt", "c=0"], ["c=0", "positive"]),
    (["solve", "block", "--method", "qp-osqp", "--opt", "max_dense_dofs=-1"], ["max_dense_dofs"]),
    (["solve", "block", "--opt", "novalue"], ["--opt", "key=value"]),
    (["solve", "block", "--method", "nofile.py:solve"], ["nofile.py", "path/to/file.py:function"]),
    (["solve", "block", "--method", "os:no_such_function"], ["'os'", "no_such_function"]),
    (["solve", "hertz-cylinder", "--method", "qp-daqp", "--opt", "form=primal"],
     ["qp-daqp", "max_dense_dofs"]),
    (["solve", "block", "--set", "W=inf"], ["W=", "finite"]),
    (["solve", "block", "--set", "delta=-inf"], ["delta="]),
    # the block's degenerate variant
    (["solve", "block", "--set", "touching=1"], ["touching=", "[0, 1)"]),
    (["solve", "block", "--set", "touching=-0.1"], ["touching=", "[0, 1)"]),
    (["solve", "block", "--set", "touching=nan"], ["touching=", "finite"]),
    (["solve", "block", "--set", "touching=half"], ["touching=", "float"]),
    # scene files
    (["solve", "missing.toml"], ["missing.toml"]),
]


@pytest.mark.parametrize("argv, words", CASES, ids=[" ".join(c[0]) for c in CASES])
def test_bad_flag_is_one_line_exit_2_and_writes_nothing(capsys, tmp_path, monkeypatch, argv, words):
    monkeypatch.chdir(tmp_path)  # default output directories would land here
    out_flags = {"stability": ["--out", str(tmp_path / "out")],
                 "bench": ["--out", str(tmp_path / "out")],
                 "sweep": ["--out", str(tmp_path / "out")],
                 "solve": ["--json", str(tmp_path / "result.json")]}[argv[0]]
    code, out, err = run(capsys, [*argv, *out_flags])
    assert_one_line_exit_2(code, err, words)
    assert files_under(tmp_path) == []


def test_a_mesh_scene_without_contact_candidates_is_refused(capsys, tmp_path):
    meshio = pytest.importorskip("meshio")
    from skfem import MeshTri

    mesh = MeshTri.init_tensor([0.0, 0.5, 1.0], [0.0, 0.5, 1.0])
    meshio.write(tmp_path / "square.msh", meshio.Mesh(mesh.p.T, [("triangle", mesh.t.T)]),
                 file_format="gmsh22", binary=False)
    capsys.readouterr()  # meshio's own warnings while writing the file
    scene = tmp_path / "square.toml"
    scene.write_text('[mesh]\nfile = "square.msh"\n[material]\nE = 1.0\nnu = 0.3\n'
                     '[[dirichlet]]\nboundary = {y = 1.0}\ncomponent = "y"\nvalue = -0.01\n'
                     '[contact]\nboundary = {y = 5.0}\n[obstacle]\ntype = "flat"\nheight = 0.0\n'
                     '[load]\nboundary = {y = 1.0}\ncomponent = "y"\n')
    code, out, err = run(capsys, ["solve", str(scene), "--json", str(tmp_path / "r.json")])
    assert_one_line_exit_2(code, err, ["contact", "boundary", "y = 5.0"])
    assert not (tmp_path / "r.json").exists()


@pytest.mark.parametrize("command", [
    ["stability", "--quick", "--axis", "1", "--out"],
    ["sweep", "hertz-cylinder", "--load", LOAD, "--out"],
    ["bench", "--sizes", "0", "--method", "pdas", "--out"],
    ["validate", "--case", "block", "--method", "pdas", "--out"],
])
def test_an_output_directory_under_a_file_is_refused_before_any_work(capsys, tmp_path, command):
    blocker = tmp_path / "file"
    blocker.write_text("not a directory")
    code, out, err = run(capsys, [*command, str(blocker / "report")])
    assert_one_line_exit_2(code, err, ["--out", "writable"])
    assert files_under(tmp_path) == [blocker]


def test_a_bad_stability_flag_leaves_an_earlier_report_alone(capsys, tmp_path):
    report = tmp_path / "stability.md"
    report.write_text("an earlier atlas\n")
    code, _, err = run(capsys, ["stability", "--axis", "nine", "--out", str(tmp_path)])
    assert code == 2 and report.read_text() == "an earlier atlas\n"


def test_a_stability_run_writes_whole_files_only(capsys, tmp_path):
    code, out, _ = run(capsys, ["stability", "--quick", "--axis", "8", "--in-process",
                                "--out", str(tmp_path)])
    assert code == 0
    names = {p.name for p in files_under(tmp_path)}
    assert names == {"stability.md", "runs.csv", "runs.json", "axis8-ill-posed.png"}
    assert not any(name.startswith(".") for name in names)  # no temporary file left behind


@pytest.mark.parametrize("value", ["0", "nan"])
def test_bench_time_limit_must_be_positive(capsys, tmp_path, value):
    code, out, err = run(capsys, ["bench", "--sizes", "0", "--method", "pdas", "--tol", "high",
                                  "--time-limit", value, "--out", str(tmp_path / "out")])
    assert_one_line_exit_2(code, err, ["--time-limit"])


def test_json_onto_a_directory_is_one_line(capsys, tmp_path):
    code, out, err = run(capsys, ["solve", "block", "--set", "nx=2", "--set", "ny=2",
                                  "--json", str(tmp_path)])
    assert_one_line_exit_2(code, err, ["--json", str(tmp_path)])


@pytest.mark.slow
def test_the_installed_command_gives_no_traceback_for_a_bad_stability_flag(tmp_path):
    proc = subprocess.run([sys.executable, "-m", "signorini.cli", "stability", "--time-limit", "-1",
                           "--out", str(tmp_path / "out")], capture_output=True, text=True)
    assert proc.returncode == 2
    assert "Traceback" not in proc.stderr and "--time-limit" in proc.stderr
    assert not (tmp_path / "out").exists()


def test_result_files_are_readable_by_others(tmp_path):
    import os
    import stat

    from signorini.files import atomic_write_text

    target = tmp_path / "result.json"
    old = os.umask(0o022)
    try:
        atomic_write_text(target, "{}")
    finally:
        os.umask(old)
    assert stat.S_IMODE(target.stat().st_mode) == 0o644
