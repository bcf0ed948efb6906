"""Hostile input files: a size is checked against what the file holds before anything of that
size is allocated, a matrix stored twice is refused naming both copies, and a file that is
not a regular file (a FIFO would wait forever) is refused wherever a file is read.
"""

import io
import os
import resource
import zipfile
from pathlib import Path

import numpy as np
import pytest

import signorini
from signorini.cli import main
from signorini.errors import InputError

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
#: the small QP of the plain format, the arrays each case starts from
SMALL = dict(f=np.array([1.0, 1.0]), d=np.array([0.25]))
COO_K = dict(K_row=np.array([0, 1]), K_col=np.array([0, 1]), K_data=np.array([2.0, 1.0]),
             K_shape=np.array([2, 2]))
#: a limit on this process's address space far below what the declared sizes would take
MEMORY_LIMIT = 4 << 30


@pytest.fixture
def little_memory():
    """The test runs with at most :data:`MEMORY_LIMIT` of address space: an allocation of the
    declared size would be a MemoryError, not a refusal."""
    before = resource.getrlimit(resource.RLIMIT_AS)
    limit = MEMORY_LIMIT if before[1] == resource.RLIM_INFINITY else min(MEMORY_LIMIT, before[1])
    resource.setrlimit(resource.RLIMIT_AS, (limit, before[1]))
    yield
    resource.setrlimit(resource.RLIMIT_AS, before)


def one_line(capsys, argv, code=2):
    assert main(argv) == code
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err, err
    return err


def npy_bytes(header_shape, data: np.ndarray) -> bytes:
    """An .npy member whose header declares ``header_shape`` but that stores ``data`` only."""
    buffer = io.BytesIO()
    np.lib.format.write_array_header_1_0(buffer, {"descr": data.dtype.str, "fortran_order": False,
                                                  "shape": header_shape})
    return buffer.getvalue() + data.tobytes()


# --- declared sizes ---------------------------------------------------------------------------

DECLARED = [
    ("huge_K_shape", {**SMALL, **COO_K, "K_shape": np.array([10**12, 10**12]),
                      "N": np.array([[1.0, 0.0]])}, ["K_shape declares 1000000000000", "f has length 2"]),
    ("huge_N_shape", {**SMALL, "K": np.eye(2), "N_row": np.array([0]), "N_col": np.array([0]),
                      "N_data": np.array([1.0]), "N_shape": np.array([10**12, 2])},
     ["N_shape declares 1000000000000 × 2", "d has length 1", "N must be 1 × 2"]),
]


@pytest.mark.parametrize("name, arrays, words", DECLARED, ids=[d[0] for d in DECLARED])
def test_a_declared_sparse_shape_is_held_to_the_stored_vectors(tmp_path, capsys, little_memory,
                                                                name, arrays, words):
    path = tmp_path / f"{name}.npz"
    np.savez(path, **arrays)
    err = one_line(capsys, ["solve", str(path)])
    for word in [name, *words]:
        assert word in err, (word, err)


def test_an_npy_header_declaring_more_than_its_member_holds_is_refused(tmp_path, capsys,
                                                                        little_memory):
    path = tmp_path / "bomb.npz"
    with zipfile.ZipFile(path, "w") as archive:
        for key, value in dict(K=np.eye(1), N=np.ones((1, 1)), d=np.ones(1)).items():
            buffer = io.BytesIO()
            np.save(buffer, value)
            archive.writestr(f"{key}.npy", buffer.getvalue())
        archive.writestr("f.npy", npy_bytes((10**10,), np.zeros(1)))
    err = one_line(capsys, ["solve", str(path)])
    assert "'f' declares shape (10000000000,)" in err and "numpy.savez" in err, err


def matrix_market(folder, K_header="2 2 2", f_header="2 1"):
    folder.mkdir()
    (folder / "K.mtx").write_text("%%MatrixMarket matrix coordinate real general\n"
                                  f"{K_header}\n1 1 2.0\n2 2 1.0\n")
    (folder / "f.mtx").write_text(f"%%MatrixMarket matrix array real general\n{f_header}\n1.0\n1.0\n")
    (folder / "N.mtx").write_text("%%MatrixMarket matrix coordinate real general\n1 2 1\n1 1 1.0\n")
    (folder / "d.mtx").write_text("%%MatrixMarket matrix array real general\n1 1\n0.25\n")
    return folder


def test_a_matrix_market_folder_as_written_solves(tmp_path, capsys):
    assert main(["solve", str(matrix_market(tmp_path / "qp"))]) == 0


@pytest.mark.parametrize("K_header, f_header, words", [
    ("300000000 300000000 1", "2 1", ["K.mtx declares 300000000 × 300000000", "f.mtx declares 2"]),
    ("2 2 2", "300000000 1", ["f.mtx' declares 300000000 entries", "bytes"]),
    ("2 2 100000000000", "2 1", ["K.mtx' declares 100000000000 entries", "bytes"]),
])
def test_matrix_market_headers_are_read_before_any_matrix(tmp_path, capsys, little_memory,
                                                          K_header, f_header, words):
    folder = matrix_market(tmp_path / "qp", K_header, f_header)
    err = one_line(capsys, ["solve", str(folder)])
    for word in words:
        assert word in err, (word, err)


@pytest.mark.parametrize("key", ["K", "N"])
def test_a_matrix_stored_both_dense_and_sparse_is_refused_naming_both(tmp_path, capsys, key):
    dense = {"K": np.diag([2.0, 1.0]), "N": np.array([[1.0, 0.0]])}
    sparse = {"K": COO_K, "N": dict(N_row=np.array([0]), N_col=np.array([0]),
                                    N_data=np.array([1.0]), N_shape=np.array([1, 2]))}
    path = tmp_path / "twice.npz"
    np.savez(path, **SMALL, **dense, **sparse[key])
    err = one_line(capsys, ["solve", str(path)])
    assert f"{key} is stored twice" in err and f"dense as '{key}'" in err, err
    assert f"{key}_data" in err and "keep one" in err, err


# --- files that are not regular files ---------------------------------------------------------

def fifo(path):
    os.mkfifo(path)
    return path


def test_a_fifo_is_refused_wherever_a_file_is_read(tmp_path, capsys):
    limits = fifo(tmp_path / "limits.toml")
    err = one_line(capsys, ["validate", "--limits", str(limits), "--out", str(tmp_path / "v")])
    assert "limits file" in err and "not a regular file" in err, err
    scene = fifo(tmp_path / "scene.toml")
    for argv in (["solve", str(scene)], ["converge", str(scene)], ["sweep", str(scene), "--load", "1:2:2"],
                 ["crosscheck", str(scene)], ["bench", "--scene", str(scene)]):
        err = one_line(capsys, [*argv, *(["--out", str(tmp_path / "o")] if argv[0] in
                                         ("converge", "sweep", "bench") else [])])
        assert "scene file" in err and "not a regular file" in err, (argv, err)
    problem = fifo(tmp_path / "problem.npz")
    for argv in (["solve", str(problem)], ["validate", "--problem", str(problem)],
                 ["bench", "--problem", str(problem), "--out", str(tmp_path / "b")]):
        err = one_line(capsys, argv)
        assert "problem file" in err and "not a regular file" in err, (argv, err)
    assert not (tmp_path / "v").exists() and not (tmp_path / "o").exists()


def test_a_fifo_among_a_scenes_or_problems_files_is_refused_by_the_api(tmp_path):
    mesh_scene = tmp_path / "block-mesh.toml"
    mesh_scene.write_text((EXAMPLES / "block-mesh.toml").read_text())
    fifo(tmp_path / "block.msh")
    with pytest.raises(InputError, match="mesh file .*block.msh.* is not a regular file"):
        signorini.solve(str(mesh_scene))
    folder = matrix_market(tmp_path / "qp")
    (folder / "f.mtx").unlink()
    fifo(folder / "f.mtx")
    with pytest.raises(InputError, match="f.mtx' is not a regular file"):
        signorini.solve(str(folder))
    with pytest.raises(InputError, match="limits file .* is not a regular file"):
        from signorini.studies.suite_checks import read_limits

        read_limits(str(fifo(tmp_path / "limits.toml")))
