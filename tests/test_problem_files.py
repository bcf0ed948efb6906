"""A user's problem as an input: save's own .npz, plain .npz and Matrix Market, in every command.

Each format, written by NumPy and SciPy alone, is read back to the same QP and
solved by ``solve`` and ``crosscheck`` to the answer of the problem it came
from; bad files are refused in one line naming the file and the fix (exit 2,
no traceback, nothing written).
"""

import json

import numpy as np
import pytest
import scipy.io
import scipy.sparse as sp

import signorini
from signorini.cli import main
from signorini.errors import InputError
from signorini.problem.files import is_problem_file, read_problem


@pytest.fixture(scope="module")
def block():
    """The block scene's QP at its load: the problem every format below stores."""
    return signorini.at_load(signorini.build_problem("block"))


def write_dense(problem, folder):
    path = folder / "dense.npz"
    np.savez(path, K=problem.K.toarray(), f=problem.f, N=problem.N.toarray(), d=problem.d,
             weights=problem.weights)
    return path


def write_coo(problem, folder):
    K, N = problem.K.tocoo(), problem.N.tocoo()
    path = folder / "coo.npz"
    np.savez(path, K_row=K.row, K_col=K.col, K_data=K.data, K_shape=K.shape,
             N_row=N.row, N_col=N.col, N_data=N.data, N_shape=N.shape, f=problem.f, d=problem.d)
    return path


def write_csr(problem, folder):
    K, N = problem.K.tocsr(), problem.N.tocsr()
    path = folder / "csr.npz"
    np.savez(path, K_data=K.data, K_indices=K.indices, K_indptr=K.indptr, K_shape=K.shape,
             N=N.toarray(), f=problem.f, d=problem.d, force_multiplicity=problem.force_multiplicity)
    return path


def write_matrix_market(problem, folder, name="market"):
    where = folder / name
    where.mkdir()
    scipy.io.mmwrite(where / "K.mtx", problem.K.tocoo(), symmetry="symmetric")
    scipy.io.mmwrite(where / "N.mtx", problem.N.tocoo())
    scipy.io.mmwrite(where / "f.mtx", problem.f[:, None])
    scipy.io.mmwrite(where / "d.mtx", problem.d[:, None])
    scipy.io.mmwrite(where / "weights.mtx", problem.weights[:, None])
    return where


def write_saved(problem, folder):
    path = folder / "saved.npz"
    problem.save(path)
    return path


WRITERS = [write_dense, write_coo, write_csr, write_matrix_market, write_saved]


@pytest.mark.parametrize("write", WRITERS, ids=[w.__name__[6:] for w in WRITERS])
def test_every_format_reads_back_the_same_qp(block, tmp_path, write):
    path = write(block, tmp_path)
    assert is_problem_file(str(path))
    read = read_problem(path)
    assert (read.n, read.m) == (block.n, block.m)
    # a plain file holds the QP in its own units (from_qp scales it: undo that); save's format
    # holds the scaled QP and its scales, which it reads back as they were
    K, f, _, d = read.qp()
    K0, f0, _, d0 = block.qp() if write is write_saved else (block.K, block.f, None, block.d)
    assert abs(K - K0).max() <= 1e-15 * abs(K0).max()
    assert abs(read.N - block.N).max() == 0
    np.testing.assert_allclose(f, f0, rtol=1e-15, atol=0)
    np.testing.assert_allclose(d, d0, rtol=1e-15, atol=0)


def test_a_matrix_market_problem_is_named_by_its_folder_or_its_k(block, tmp_path):
    folder = write_matrix_market(block, tmp_path)
    assert read_problem(folder / "K.mtx").n == read_problem(folder).n == block.n
    assert read_problem(folder).name == "market"
    read = read_problem(folder)
    np.testing.assert_allclose(read.weights * read.scales.weight, block.weights, rtol=1e-15)


@pytest.mark.parametrize("write", WRITERS, ids=[w.__name__[6:] for w in WRITERS])
def test_solve_gives_the_answer_of_the_problem_the_file_came_from(block, tmp_path, capsys, write):
    path = write(block, tmp_path)
    out = tmp_path / "result.json"
    assert main(["solve", str(path), "--method", "pdas", "--json", str(out)]) == 0
    record = json.loads(out.read_text())
    exact = signorini.solve(block, "pdas")
    force = np.array(record["contact"]["force"], dtype=float)
    scale = block.scales.force if write is write_saved else 1.0  # plain files: the QP's own units
    np.testing.assert_allclose(force, exact.solution.lam * scale, rtol=1e-9,
                               atol=1e-12 * np.abs(exact.solution.lam * scale).max())


def test_a_saved_scene_with_a_pending_load_is_matched_when_solved(tmp_path, capsys):
    path = tmp_path / "hertz.npz"
    problem = signorini.build_problem("hertz-cylinder")
    assert problem.model.pending
    problem.save(path)
    out = tmp_path / "r.json"
    assert main(["solve", str(path), "--json", str(out)]) == 0
    record = json.loads(out.read_text())
    assert record["status"] == "converged"
    direct = signorini.solve("hertz-cylinder")
    assert abs(record["total_force"] / direct.total_force - 1) < 1e-8


@pytest.mark.parametrize("scene", ["reverse-hertz", "hertz-cylinder"])
def test_a_saved_scene_keeps_its_load_resultant_and_its_predicted_contact(scene, tmp_path):
    """What load control reads is stored: the resultant's weights of a curved obstacle (the load
    matched is the resultant along the push, not Σλ) and the contact the scene predicts (load
    control starts from it): the saved problem is matched as the scene is, in as many steps."""
    problem = signorini.build_problem(scene)
    problem.save(tmp_path / "p.npz")
    saved = signorini.ContactProblem.load(tmp_path / "p.npz")
    for kept, given in ((saved.model.push.resultant, problem.model.push.resultant),
                        (saved.model.predicted_contact, problem.model.predicted_contact)):
        assert (kept is None) == (given is None) and (given is None or np.array_equal(kept, given))
    direct, again = signorini.solve(problem, "pdas"), signorini.solve(saved, "pdas")
    assert np.array_equal(direct.solution.lam, again.solution.lam)
    assert direct.solution.work["load_control"] == again.solution.work["load_control"]


@pytest.mark.parametrize("write", [write_coo, write_matrix_market, write_saved],
                         ids=["coo", "matrix_market", "saved"])
def test_crosscheck_takes_a_problem_file(block, tmp_path, capsys, write):
    path = write(block, tmp_path)
    out = tmp_path / "check.json"
    assert main(["crosscheck", str(path), "--method", "pdas", "--method", "qp-clarabel",
                 "--json", str(out)]) == 0
    record = json.loads(out.read_text())
    assert [pair["verdict"] for pair in record["pairs"]] == ["agree"]


def test_a_user_method_returning_u_and_lam_solves_a_problem_file(block, tmp_path, capsys,
                                                                  monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "mine.py").write_text(
        "from signorini.solvers.pdas import pdas\n\n"
        "def solve(problem, **options):\n    answer = pdas(problem)\n"
        "    return answer.u, answer.lam\n")
    path = write_coo(block, tmp_path)
    assert main(["solve", str(path), "--method", "mine.py:solve", "--json", "r.json"]) == 0
    assert json.loads((tmp_path / "r.json").read_text())["status"] == "converged"


# --- bad files --------------------------------------------------------------------------------

SMALL = dict(K=np.diag([2.0, 1.0]), f=np.array([1.0, 1.0]), N=np.array([[1.0, 0.0]]),
             d=np.array([0.25]))

#: (name, arrays or text, words the one line must hold)
BAD = [
    ("missing.npz", None, ["missing.npz", "does not exist"]),
    ("text.npz", "not an archive", ["text.npz", "not a NumPy .npz archive", "numpy.savez"]),
    ("no_d.npz", {k: v for k, v in SMALL.items() if k != "d"}, ["no_d.npz", "'d'", "gaps"]),
    ("no_K.npz", {k: v for k, v in SMALL.items() if k != "K"}, ["no_K.npz", "'K'", "K_row"]),
    ("typo.npz", {**SMALL, "gap": SMALL["d"]}, ["typo.npz", "'gap'", "rename or drop"]),
    ("short_f.npz", {**SMALL, "f": np.ones(3)}, ["short_f.npz", "f must have shape (2,)"]),
    ("wide_N.npz", {**SMALL, "N": np.ones((1, 3))}, ["wide_N.npz", "N must have shape"]),
    ("nan_f.npz", {**SMALL, "f": np.array([1.0, np.nan])}, ["nan_f.npz", "f is not finite",
                                                            "replace NaN"]),
    ("inf_K.npz", {**SMALL, "K": np.diag([np.inf, 1.0])}, ["inf_K.npz", "K is not finite"]),
    ("unsymmetric.npz", {**SMALL, "K": np.array([[2.0, 1.0], [0.0, 1.0]])},
     ["unsymmetric.npz", "K must be symmetric", "½(K + Kᵀ)"]),
    ("coo_no_shape.npz", {"K_row": [0, 1], "K_col": [0, 1], "K_data": [2.0, 1.0],
                          **{k: SMALL[k] for k in ("f", "N", "d")}},
     ["coo_no_shape.npz", "K_shape"]),
    ("text_d.npz", {**SMALL, "d": np.array(["a"])}, ["text_d.npz", "d (the initial gaps",
                                                     "1-D float array"]),
    ("zero_weight.npz", {**SMALL, "weights": np.array([0.0])}, ["zero_weight.npz", "weight 0"]),
]


def write_bad(folder, name, content):
    path = folder / name
    if isinstance(content, str):
        path.write_text(content)
    elif content is not None:
        np.savez(path, **content)
    return path


@pytest.mark.parametrize("name, content, words", BAD, ids=[b[0] for b in BAD])
@pytest.mark.parametrize("command", ["solve", "crosscheck"])
def test_a_bad_problem_file_is_refused_in_one_line(tmp_path, capsys, name, content, words, command):
    path = write_bad(tmp_path, name, content)
    out = tmp_path / "out.json"
    code = main([command, str(path), "--json", str(out)])
    err = capsys.readouterr().err
    assert code == 2, err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err, err
    for word in words:
        assert word in err, (word, err)
    assert not out.exists()


@pytest.mark.parametrize("name, content, words", BAD, ids=[b[0] for b in BAD])
def test_the_api_raises_the_same_input_error(tmp_path, name, content, words):
    path = write_bad(tmp_path, name, content)
    with pytest.raises(InputError) as info:
        signorini.solve(str(path))
    for word in words:
        assert word in str(info.value)


def test_a_matrix_market_folder_without_its_files_is_refused(tmp_path, capsys):
    folder = tmp_path / "market"
    folder.mkdir()
    scipy.io.mmwrite(folder / "K.mtx", sp.coo_matrix(SMALL["K"]))
    assert main(["solve", str(folder)]) == 2
    err = capsys.readouterr().err
    assert "f.mtx" in err and "market" in err and len(err.strip().splitlines()) == 1
    for key in ("N", "d"):
        scipy.io.mmwrite(folder / f"{key}.mtx", sp.coo_matrix(SMALL[key].reshape(1, -1)))
    (folder / "f.mtx").write_text("%%MatrixMarket nonsense\n")
    assert main(["solve", str(folder / "K.mtx")]) == 2
    err = capsys.readouterr().err
    assert "f.mtx" in err and "Matrix Market" in err
    assert main(["solve", str(folder / "other.mtx")]) == 2
    assert "give the folder or its K.mtx" in capsys.readouterr().err


@pytest.mark.parametrize("flags, word", [
    (["--set", "E=2"], "--set"), (["--raw-units"], "--raw-units"),
    (["--target-error", "1%"], "--target-error"), (["--vtk", "out.vtu"], "--vtk"),
])
def test_scene_options_on_a_problem_file_are_refused(tmp_path, capsys, monkeypatch, flags, word):
    monkeypatch.chdir(tmp_path)
    path = write_bad(tmp_path, "small.npz", SMALL)
    assert main(["solve", str(path), *flags]) == 2
    err = capsys.readouterr().err
    assert word in err and "small.npz" in err and "Traceback" not in err
    assert not (tmp_path / "out.vtu").exists()


def test_an_output_onto_the_problem_file_is_refused(tmp_path, capsys):
    path = write_bad(tmp_path, "small.npz", SMALL)
    before = path.read_bytes()
    assert main(["solve", str(path), "--json", str(path)]) == 2
    assert "problem file" in capsys.readouterr().err
    assert path.read_bytes() == before


def test_bench_takes_a_problem_file_as_one_size(block, tmp_path, capsys):
    import csv

    path = write_matrix_market(block, tmp_path)
    out = tmp_path / "bench"
    assert main(["bench", "--problem", str(path), "--method", "pdas", "--method", "uzawa",
                 "--tol", "mid", "--out", str(out)]) == 0
    with open(out / "bench.csv", newline="") as handle:
        rows = list(csv.DictReader(handle))
    assert {(r["scene"], r["size"], r["method"]) for r in rows} == {
        ("market", "file", "pdas"), ("market", "file", "uzawa")}
    assert all(int(r["dofs"]) == block.n and int(r["candidates"]) == block.m for r in rows)
    exact = next(r for r in rows if r["method"] == "pdas")
    assert exact["status"] == "converged" and float(exact["lam_rel"]) < 1e-8
    assert (out / "bench.md").is_file()


@pytest.mark.parametrize("flags", [["--sizes", "0,1"], ["--scene", "block"], ["--set", "E=2"],
                                   ["--peer", "getfem"]])
def test_bench_refuses_scene_options_with_a_problem_file(tmp_path, capsys, flags):
    path = write_bad(tmp_path, "small.npz", SMALL)
    assert main(["bench", "--problem", str(path), *flags, "--out", str(tmp_path / "b")]) == 2
    err = capsys.readouterr().err
    assert flags[0] in err and "Traceback" not in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "b").exists()


@pytest.mark.parametrize("argv", [["converge", "{path}", "--out", "{tmp}/c"],
                                  ["bench", "--scene", "{path}", "--out", "{tmp}/c"]])
def test_a_command_that_needs_a_scene_says_so_of_a_problem_file(tmp_path, capsys, argv):
    path = write_bad(tmp_path, "small.npz", SMALL)
    assert main([a.format(path=path, tmp=tmp_path) for a in argv]) == 2
    err = capsys.readouterr().err
    assert "is a problem file, and this needs a scene" in err and "small.npz" in err
    assert not (tmp_path / "c").exists()
