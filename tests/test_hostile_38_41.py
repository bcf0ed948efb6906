"""The doors of one door and of the slider, attacked as a hostile user would.

Bad input at every door (the slider's at_load, with_load and Model.at_push, a warm start,
problem files, --set and --opt, solve_adaptive's max_dofs, ContactProblem.load) is an
InputError or exit 2 with one line naming it, before anything of its size is allocated; a
broken sparse matrix is refused before SciPy's C code reads it.
"""

import numpy as np
import pytest
import scipy.sparse as sp

import signorini
from signorini import ContactProblem
from signorini.cli import main


def steel_qp():
    """Two dofs in SI units (K ~ 1e11 N/m, gaps ~ 0.1 mm): far from order one."""
    K = np.array([[2e11, -1e11], [-1e11, 2e11]])
    return ContactProblem.from_qp(K, np.array([1e8, 1e8]), np.array([[1.0, 0.0]]),
                                  np.array([2.5e-4]))


def pdas_answer(problem):
    answer = signorini.solve(problem, "pdas").solution
    return answer.u, answer.lam


@pytest.fixture(scope="module")
def cylinder():
    return signorini.build_problem("hertz-cylinder", params={"n_contact": 12, "grading": 0.4})


@pytest.mark.parametrize("call, words", [
    (lambda p: signorini.at_load("hertz-cylinder"), ["at_load", "ContactProblem", "build_problem"]),
    (lambda p: signorini.at_load(None), ["at_load", "ContactProblem"]),
    (lambda p: signorini.with_load(p, P=None), ["P=None", "number"]),
    (lambda p: p.model.at_push(float("nan")), ["scale=nan", "finite"]),
    (lambda p: p.model.at_push(float("inf")), ["scale=inf", "finite"]),
    (lambda p: p.model.at_push("1"), ["scale='1'", "finite"]),
    (lambda p: p.model.at_push(1.0, load=float("nan")), ["load=nan", "finite"]),
    (lambda p: p.pushed(float("nan")), ["scale=nan"]),
    (lambda p: steel_qp().model.at_push(1.0), ["push", "as it is"]),
    (lambda p: p.with_target(float("nan")), ["P=nan", "finite number > 0"]),
    (lambda p: p.with_target(-1.0), ["P=-1.0", "finite number > 0"]),
    (lambda p: p.with_target("1"), ["P='1'", "finite number > 0"]),
])
def test_the_sliders_doors_refuse_bad_input_naming_it(cylinder, call, words):
    with pytest.raises(signorini.InputError) as refused:
        call(cylinder)
    assert all(word in str(refused.value) for word in words), str(refused.value)


BROKEN_CSR = (np.array([2.0, 2.0]), np.array([0, 1]), np.array([0, 5, 2]))  # indptr decreases


@pytest.mark.parametrize("matrix", [sp.csr_matrix, sp.csc_matrix, sp.csr_array])
def test_a_compressed_matrix_with_broken_indices_is_refused_not_read_out_of_bounds(matrix):
    K = matrix(BROKEN_CSR, shape=(2, 2))  # SciPy builds it unchecked; its C code would crash
    with pytest.raises(signorini.InputError, match="K is not a valid .* matrix .indptr"):
        ContactProblem.from_qp(K, [1.0, 1.0], [[1.0, 0.0]], [0.25])


@pytest.mark.parametrize("arrays, words", [
    ({"K_data": BROKEN_CSR[0], "K_indices": BROKEN_CSR[1], "K_indptr": BROKEN_CSR[2]},
     ["K is not a valid CSR matrix"]),
    ({"K_row": np.array([0, 1.5]), "K_col": np.array([0, 1]), "K_data": np.array([2.0, 2.0])},
     ["K_row", "whole numbers"]),
    ({"K": np.eye(2), "force_multiplicity": np.array("two")}, ["force_multiplicity", "one number"]),
], ids=["decreasing indptr", "a fractional index", "a word for a number"])
def test_a_hostile_problem_file_is_one_line_exit_2(tmp_path, capsys, arrays, words):
    shape = {} if "K" in arrays else {"K_shape": np.array([2, 2])}
    np.savez(tmp_path / "qp.npz", f=np.ones(2), N=np.array([[1.0, 0.0]]), d=np.array([0.25]),
             **arrays, **shape)
    assert main(["solve", str(tmp_path / "qp.npz")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and all(word in err for word in words), err


def test_whole_numbers_stored_as_floats_still_index_a_file(tmp_path):
    np.savez(tmp_path / "qp.npz", K_row=np.array([0.0, 0, 1, 1]), K_col=np.array([0.0, 1, 0, 1]),
             K_data=np.array([2.0, -1, -1, 2]), K_shape=np.array([2.0, 2]), f=np.ones(2),
             N=np.array([[1.0, 0.0]]), d=np.array([0.25]))
    assert main(["solve", str(tmp_path / "qp.npz")]) == 0


def test_a_first_mesh_beyond_max_dofs_is_refused_before_it_is_solved(capsys):
    assert main(["solve", "hertz-cylinder", "--target-error", "1%", "--max-dofs", "100"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "max dofs 100" in err and "--max-dofs" in err


@pytest.fixture(scope="module")
def block_answer():
    return signorini.solve("block", "pdas")


@pytest.mark.parametrize("method", ["pdas", "nested", "auto"])
@pytest.mark.parametrize("field, spoil", [("lam", lambda v: v * np.nan), ("u", lambda v: v + np.inf)])
def test_a_non_finite_warm_start_is_refused_naming_it(block_answer, method, field, spoil):
    solution = block_answer.solution
    given = {"lam": solution.lam, "u": solution.u}
    given[field] = spoil(given[field])
    with pytest.raises(signorini.InputError, match=f"warm_start: its {field} is not finite"):
        signorini.solve(block_answer.problem, method, warm_start=signorini.WarmStart(**given))


def test_a_warm_start_given_as_lists_is_taken_as_arrays(block_answer):
    start = signorini.WarmStart(lam=list(block_answer.solution.lam))
    assert signorini.solve(block_answer.problem, "nested", warm_start=start).status == "converged"


def compressed_bomb(path, key, count, others):
    """An .npz whose compressed member ``key`` unpacks to ``count`` zeros (a few hundred kB on
    disk, a consistent header and zip entry), beside the small arrays ``others``."""
    import io
    import zipfile

    header = io.BytesIO()
    np.lib.format.write_array_header_1_0(header, {"descr": "<f8", "fortran_order": False,
                                                  "shape": (count,)})
    with zipfile.ZipFile(path, "w", compression=zipfile.ZIP_DEFLATED) as archive:
        with archive.open(f"{key}.npy", "w", force_zip64=True) as member:
            member.write(header.getvalue())
            for _ in range(count // 1_000_000):
                member.write(bytes(8_000_000))
        for name, value in others.items():
            buffer = io.BytesIO()
            np.save(buffer, value)
            archive.writestr(f"{name}.npy", buffer.getvalue())


@pytest.mark.parametrize("key, others, words", [
    ("f", {"K": np.eye(2), "N": np.array([[1.0, 0.0]]), "d": np.array([0.25])},
     ["f must have shape (2,), got (30000000,)"]),
    ("f", {"K_row": np.array([0, 1]), "K_col": np.array([0, 1]), "K_data": np.ones(2),
           "K_shape": np.array([2, 2]), "N_row": np.array([0]), "N_col": np.array([0]),
           "N_data": np.ones(1), "N_shape": np.array([1, 2]), "d": np.array([0.25])},
     ["K_shape declares 2 × 2", "f has length 30000000"]),
    ("K_data", {"K_row": np.array([0, 1]), "K_col": np.array([0, 1]), "K_shape": np.array([2, 2]),
                "f": np.ones(2), "N": np.array([[1.0, 0.0]]), "d": np.array([0.25])},
     ["K_data declares 30,000,000 entries", "2 unknowns"]),
], ids=["dense K", "sparse K", "sparse part"])
def test_a_compressed_member_is_held_to_the_others_before_it_is_read(tmp_path, capsys,
                                                                    monkeypatch, key, others, words):
    path = tmp_path / "bomb.npz"
    compressed_bomb(path, key, 30_000_000, others)
    read = []
    original = np.lib.npyio.NpzFile.__getitem__
    monkeypatch.setattr(np.lib.npyio.NpzFile, "__getitem__",
                        lambda self, name: read.append(name) or original(self, name))
    assert main(["solve", str(path)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and all(word in err for word in words), err
    assert key not in read


@pytest.mark.parametrize("argv, words", [
    (["--set", "nx=4", "--set", "nx=6"], ["--set nx is given twice (4 and 6)"]),
    (["--method", "pdas", "--opt", "c=1", "--opt", "c=2"], ["--opt c is given twice (1 and 2)"]),
], ids=["set", "opt"])
def test_a_setting_given_twice_with_two_values_is_refused(capsys, argv, words):
    assert main(["solve", "block", *argv]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and all(word in err for word in words), err


@pytest.mark.parametrize("call, words", [
    (lambda: signorini.solve(steel_qp(), "pdas", keep_factor="yes"), ["keep_factor='yes'"]),
    (lambda: signorini.solve_adaptive("block", 0.5, max_dofs=True), ["max dofs True", "whole"]),
    (lambda: signorini.solve_adaptive("block", 0.5, max_dofs=1e5), ["max dofs 100000.0", "whole"]),
    (lambda: signorini.with_load("hertz-cylinder", P=1.0), ["with_load", "ContactProblem"]),
    (lambda: ContactProblem.load("no-such-problem.npz"), ["no-such-problem.npz", "does not exist"]),
], ids=["keep_factor", "max_dofs bool", "max_dofs float", "with_load of a name", "load missing"])
def test_more_api_doors_refuse_bad_input_naming_it(call, words):
    with pytest.raises(signorini.InputError) as refused:
        call()
    assert all(word in str(refused.value) for word in words), str(refused.value)


def test_a_file_that_is_not_an_archive_is_refused_by_load(tmp_path):
    (tmp_path / "p.npz").write_bytes(b"not a zip")
    with pytest.raises(signorini.InputError, match="not an archive"):
        ContactProblem.load(tmp_path / "p.npz")
