"""A user's problem read from a file: the package's own ``save``, plain ``.npz`` or Matrix Market.

Every command that takes a problem file reads it here (:func:`read_problem`),
so the three formats mean the same everywhere. The QP is

    minimise ½ uᵀK u − fᵀu   subject to   N u ≤ d

in the units it was written in; ``docs/problem-files.md`` documents the formats:

- a ``.npz`` that :meth:`ContactProblem.save` wrote (a scene's problem, with its mesh);
- a plain ``.npz`` written by NumPy alone: ``f``, ``d`` (vectors), ``K``, ``N`` each
  either a dense array or its sparse parts — COO ``K_row``, ``K_col``, ``K_data``
  or CSR ``K_data``, ``K_indices``, ``K_indptr``, with ``K_shape`` — and optionally
  ``weights`` (m,), ``contact_points`` (m, dim), ``force_multiplicity`` (a number);
- Matrix Market: a folder holding ``K.mtx``, ``f.mtx``, ``N.mtx``, ``d.mtx`` and
  optionally ``weights.mtx`` (``scipy.io.mmwrite`` writes them), given as the
  folder or as the path of its ``K.mtx``.

Bad input raises :class:`~signorini.errors.InputError` with one line naming the
file, the array and the fix.
"""

from __future__ import annotations

import math
import os
import zipfile
from pathlib import Path
from typing import Any

import numpy as np
import scipy.sparse as sp

from signorini.errors import InputError, docs_page
from signorini.files import check_input_file
from signorini.problem.contact import ContactProblem
from signorini.problem.saved import declared_sizes

__all__ = ["MATRIX_MARKET_NAMES", "PLAIN_KEYS", "is_problem_file", "problem_file_paths",
           "read_problem"]

#: the arrays of the plain format: what each is (for messages)
PLAIN_KEYS = {"K": "the stiffness, n × n symmetric positive definite",
              "f": "the load, n values", "N": "the contact rows, m × n",
              "d": "the initial gaps, m values"}
#: optional arrays of the plain format
OPTIONAL_KEYS = {"weights": "the lumped boundary weight of each candidate, m values",
                 "contact_points": "each candidate's coordinates, m × dim",
                 "force_multiplicity": "copies of the model in the whole body, a number"}
#: the parts of a sparse matrix in a plain file, after its name and an underscore
SPARSE_PARTS = ("row", "col", "data", "indices", "indptr", "shape")
#: the files of a Matrix Market problem, in its folder (``weights`` optional)
MATRIX_MARKET_NAMES = ("K", "f", "N", "d", "weights")
FORMATS = f"see {docs_page('problem-files')}"


def is_problem_file(name: Any) -> bool:
    """Whether ``name`` names a problem file (``.npz``, ``.mtx``, or a folder of ``.mtx`` files)."""
    if not isinstance(name, (str, os.PathLike)):
        return False
    text = os.fspath(name)
    return text.lower().endswith((".npz", ".mtx")) or (
        os.path.isdir(text) and os.path.isfile(os.path.join(text, "K.mtx")))


def problem_file_paths(name: str | os.PathLike) -> list[str]:
    """The files a problem file reads: itself, or a Matrix Market folder's ``.mtx`` files."""
    folder = _matrix_market_folder(name)
    if folder is None:
        return [os.fspath(name)]
    return [str(folder / f"{key}.mtx") for key in MATRIX_MARKET_NAMES
            if (folder / f"{key}.mtx").exists()]


def read_problem(name: str | os.PathLike) -> ContactProblem:
    """The problem stored at ``name`` in one of the module's formats (its docstring).

    A plain file's problem is named after the file (its stem); a saved one keeps its scene's name.
    """
    path = Path(name)
    if not path.exists():
        raise InputError(f"problem file {str(path)!r} does not exist: give the path of a .npz "
                         "file or of a folder of Matrix Market files (.mtx)")
    folder = _matrix_market_folder(path)
    try:
        if folder is not None:
            return _from_arrays(path, _matrix_market(folder), folder.name)
        if not path.is_file():
            raise InputError(f"problem file {str(path)!r} is not a regular file: give a .npz file")
        if path.suffix.lower() != ".npz":
            raise InputError(f"{str(path)!r} is not a problem file: give a .npz file or a folder "
                             f"of Matrix Market files ({FORMATS})")
        arrays = _npz(path)
        if "meta" in arrays:  # written by ContactProblem.save
            return ContactProblem.load(path)  # its reader names the field at fault
        return _from_arrays(path, arrays, path.stem)
    except InputError as exc:
        text = str(exc)
        if text.startswith("problem file"):
            raise
        hint = f" ({FORMATS})" if "shape" in text and FORMATS not in text else ""
        raise InputError(f"problem file {str(path)!r}: {text}{hint}") from None


# --- the formats --------------------------------------------------------------------------------


def _matrix_market_folder(name: str | os.PathLike) -> Path | None:
    path = Path(name)
    if path.is_dir():
        if not (path / "K.mtx").is_file():
            raise InputError(f"problem folder {str(path)!r} holds no K.mtx: write K.mtx, f.mtx, "
                             f"N.mtx and d.mtx into it ({FORMATS})")
        return path
    if path.suffix.lower() == ".mtx":
        if path.name != "K.mtx":
            raise InputError(f"problem file {str(path)!r}: a Matrix Market problem is a folder of "
                             f"K.mtx, f.mtx, N.mtx and d.mtx: give the folder or its K.mtx")
        return path.parent
    return None


def _npz(path: Path) -> dict[str, np.ndarray]:
    if not zipfile.is_zipfile(path):  # np.load would try it as a pickle
        raise InputError(f"problem file {str(path)!r} is not a NumPy .npz archive: write it with "
                         f"numpy.savez ({FORMATS})")
    try:
        with np.load(path, allow_pickle=False) as stored:
            declared = declared_sizes(str(path), stored.zip)
            sizes = {key: stored[key] for key in ("K_shape", "N_shape")  # a few numbers each
                     if key in stored.files and math.prod(declared.get(key, ())) <= 3}
            _check_declared_fit(declared, sizes)
            return {key: stored[key] for key in stored.files}
    except InputError:
        raise
    except (zipfile.BadZipFile, EOFError, OSError) as exc:
        raise InputError(f"problem file {str(path)!r} is not a NumPy .npz archive ({exc}): write "
                         f"it with numpy.savez ({FORMATS})") from None
    except ValueError as exc:  # an array of Python objects (pickled)
        raise InputError(f"problem file {str(path)!r} holds an array that is not numbers ({exc}): "
                         "store plain numeric arrays") from None


def _check_declared_fit(declared: dict[str, tuple[int, ...]], sizes: dict[str, np.ndarray]) -> None:
    """InputError when the shapes the headers declare (and ``K_shape``, ``N_shape``: a few
    numbers, read first) cannot make one problem: f n values and d m, K n × n and N m × n,
    their sparse parts no more entries than that, weights m values and contact points m rows.
    Checked before any array is read, for a compressed member may unpack to far more than the
    archive's size."""
    if "f" not in declared or "d" not in declared:
        return  # reading says which is missing
    n, m = math.prod(declared["f"]), math.prod(declared["d"])
    if len(declared.get("K", ())) == 2:  # a dense K sets n, as it does for ContactProblem
        k = declared["K"][0]
        if declared["K"] != (k, k) or n != k:
            raise InputError(f"f must have shape ({k},), got ({n},)" if declared["K"] == (k, k)
                             else f"K must be square, got shape {declared['K']}")
    if len(declared.get("N", ())) == 2 and declared["N"] != (m, n):
        raise InputError(f"N must have shape (m, {n}), got {declared['N']}")
    for key, expected in (("K", (n, n)), ("N", (m, n))):
        if f"{key}_shape" in sizes and np.asarray(sizes[f"{key}_shape"]).dtype.kind in "iu":
            _check_shape(key, tuple(int(v) for v in np.ravel(sizes[f"{key}_shape"])), expected)
    most = {"weights": m, "contact_points": 3 * m, "force_multiplicity": 1,
            **{f"{key}_{part}": count for key, count in (("K", n * n), ("N", m * n))
               for part in ("row", "col", "data", "indices")},
            "K_indptr": n + 1, "N_indptr": m + 1}
    for key, count in most.items():
        if key in declared and math.prod(declared[key]) > count:
            raise InputError(f"{key} declares {math.prod(declared[key]):,} entries, more than a "
                             f"problem of {n:,} unknowns (f) and {m:,} candidates (d) holds: "
                             "write it again with numpy.savez")


def _check_shape(key: str, shape: tuple[int, ...], expected: tuple[int, int]) -> None:
    """InputError when the declared ``{key}_shape`` is not ``expected`` (from f and d)."""
    if shape != expected:
        sizes = "f has length" if key == "K" else f"d has length {expected[0]} and f"
        raise InputError(f"{key}_shape declares {' × '.join(map(str, shape))}, but {sizes} "
                         f"{expected[1]}: {key} must be {expected[0]} × {expected[1]}; fix "
                         f"{key}_shape (or the vectors)")


def _matrix_market(folder: Path) -> dict[str, Any]:
    import scipy.io  # on use: scipy.io is slow to import, and only Matrix Market needs it

    files = {}
    for key in MATRIX_MARKET_NAMES:
        file = folder / f"{key}.mtx"
        if not file.exists() and key in PLAIN_KEYS:
            raise InputError(f"problem folder {str(folder)!r} holds no {key}.mtx "
                             f"({PLAIN_KEYS[key]}): write it with scipy.io.mmwrite ({FORMATS})")
        if file.exists():
            check_input_file(str(file), "problem file")
            files[key] = file
    _check_headers(files)  # the sizes they declare, before anything of that size is allocated
    arrays: dict[str, Any] = {}
    for key, file in files.items():
        try:
            arrays[key] = scipy.io.mmread(file)
        except (ValueError, OSError, IndexError, TypeError) as exc:
            raise InputError(f"problem file {str(file)!r} is not a Matrix Market file ({exc}): "
                             "write it with scipy.io.mmwrite") from None
    return arrays


#: the fewest bytes one stored entry takes: a value and a newline; two indices and a value
_ENTRY_BYTES = {"array": 2, "coordinate": 6}


def _check_headers(files: dict[str, Path]) -> None:
    """InputError when the Matrix Market headers declare sizes that disagree with each other
    (K n × n, f n, N m × n, d and weights m) or entries their file is too short to hold."""
    import scipy.io

    shapes = {}
    for key, file in files.items():
        try:
            rows, cols, entries, layout, field, _ = scipy.io.mminfo(file)
        except (ValueError, OSError, IndexError, TypeError) as exc:
            raise InputError(f"problem file {str(file)!r} has no Matrix Market header ({exc}): "
                             "write it with scipy.io.mmwrite") from None
        least = _ENTRY_BYTES.get(layout, 2) - (2 if field == "pattern" else 0)
        if entries * least > file.stat().st_size:
            raise InputError(f"problem file {str(file)!r} declares {entries} entries, more than "
                             f"its {file.stat().st_size} bytes can hold: write it again with "
                             "scipy.io.mmwrite")
        shapes[key] = (rows, cols)
    said = {key: " × ".join(map(str, shape)) for key, shape in shapes.items()}
    for key in set(shapes) - {"K", "N"}:
        if min(shapes[key]) != 1:
            raise InputError(f"{key}.mtx declares {said[key]}: store {key} as one column")
        shapes[key] = max(shapes[key])
    n, m = shapes["f"], shapes["d"]
    expected = {"K": (n, n), "N": (m, n), "f": n, "d": m, "weights": m}
    wrong = [key for key, shape in shapes.items() if shape != expected[key]]
    if wrong:
        raise InputError(f"{wrong[0]}.mtx declares {said[wrong[0]]}, but f.mtx declares {n} values "
                         f"and d.mtx {m}: K must be {n} × {n}, N {m} × {n}, weights {m} values")


def _sparse(arrays: dict[str, Any], key: str, expected: tuple[int, int]) -> Any:
    """Matrix ``key``: dense, or from its COO or CSR parts (``K_row``, ``K_col``, ``K_data``...).

    A declared ``{key}_shape`` must be ``expected`` (the sizes of f and d) before anything of
    that size is allocated.
    """
    parts = {part: arrays[f"{key}_{part}"] for part in SPARSE_PARTS if f"{key}_{part}" in arrays}
    if key in arrays and parts:
        raise InputError(f"{key} is stored twice, dense as {key!r} and sparse as "
                         f"{', '.join(f'{key}_{part}' for part in parts)}: keep one of them")
    if key in arrays:
        return arrays[key]
    if not parts:
        raise InputError(f"no {key!r} ({PLAIN_KEYS[key]}): store it dense as {key}, or sparse as "
                         f"{key}_row, {key}_col, {key}_data and {key}_shape ({FORMATS})")
    if "shape" not in parts or "data" not in parts:
        missing = "shape" if "shape" not in parts else "data"
        raise InputError(f"{key} is stored sparse without {key}_{missing}: store {key}_data "
                         f"and {key}_shape with its indices")
    for part in ("row", "col", "indices", "indptr", "shape"):
        values = np.asarray(parts.get(part, np.zeros(0, dtype=int)))
        whole = values.dtype.kind in "iu" or (values.dtype.kind == "f" and bool(
            np.all(np.isfinite(values)) and np.all(values == np.round(values))))
        if not whole:
            raise InputError(f"{key}_{part} must hold whole numbers (it counts or indexes), got "
                             f"a {values.dtype} array: store it as an integer array")
        if part in parts:
            parts[part] = values.astype(np.int64)
    shape = tuple(int(v) for v in np.ravel(parts["shape"]))
    _check_shape(key, shape, expected)
    try:
        if "row" in parts and "col" in parts:
            return sp.coo_matrix((parts["data"], (parts["row"], parts["col"])), shape=shape).tocsr()
        if "indices" in parts and "indptr" in parts:
            return sp.csr_matrix((parts["data"], parts["indices"], parts["indptr"]), shape=shape)
    except (ValueError, TypeError, IndexError) as exc:
        raise InputError(f"the sparse parts of {key} do not fit together ({exc}): check "
                         f"{key}_shape and the indices") from None
    raise InputError(f"{key} is stored sparse without its indices: give {key}_row and {key}_col "
                     f"(COO) or {key}_indices and {key}_indptr (CSR)")


def _vector(arrays: dict[str, Any], key: str, what: str) -> np.ndarray | None:
    if key not in arrays:
        return None
    value = arrays[key]
    value = value.toarray() if sp.issparse(value) else np.asarray(value)
    if value.ndim == 2 and 1 in value.shape:  # a Matrix Market column or row
        value = value.ravel()
    if value.ndim != 1 or value.dtype.kind not in "fiu":
        raise InputError(f"{key} ({what}) must be a vector of numbers, got a {value.dtype} array "
                         f"of shape {value.shape}: store {key} as a 1-D float array")
    return value.astype(float)


def _finite(key: str, values: np.ndarray) -> None:
    bad = np.flatnonzero(~np.isfinite(values))
    if bad.size:
        raise InputError(f"{key} is not finite at {bad.size} entries (the first at {int(bad[0])}: "
                         f"{values[bad[0]]}): replace NaN and inf by numbers")


def _from_arrays(path: Path, arrays: dict[str, Any], name: str) -> ContactProblem:
    known = set(PLAIN_KEYS) | set(OPTIONAL_KEYS) | {f"{key}_{part}" for key in ("K", "N")
                                                     for part in SPARSE_PARTS}
    stray = sorted(set(arrays) - known)
    if stray:
        raise InputError(f"{stray[0]!r} is not an array of the format (K, f, N, d, weights, "
                         f"contact_points, force_multiplicity): rename or drop it ({FORMATS})")
    vectors = {}
    for key, what in (("f", PLAIN_KEYS["f"]), ("d", PLAIN_KEYS["d"]),
                      ("weights", OPTIONAL_KEYS["weights"])):
        vectors[key] = _vector(arrays, key, what)
        if vectors[key] is None and key != "weights":
            raise InputError(f"no {key!r} ({what}): store it beside K and N ({FORMATS})")
    n, m = vectors["f"].size, vectors["d"].size  # the sizes the stored values give
    K, N = _sparse(arrays, "K", (n, n)), _sparse(arrays, "N", (m, n))
    for key, matrix in (("K", K), ("N", N)):
        data = matrix.data if sp.issparse(matrix) else np.asarray(matrix)
        if data.dtype.kind not in "fiu":
            raise InputError(f"{key} must hold numbers, got {data.dtype}: store a float array")
        _finite(key, np.asarray(data, dtype=float).ravel())
    for key, values in vectors.items():
        if values is not None:
            _finite(key, values)
    multiplicity = arrays.get("force_multiplicity", 1.0)
    if np.size(multiplicity) != 1 or np.asarray(multiplicity).dtype.kind not in "fiu":
        raise InputError(f"force_multiplicity must be one number, got {np.asarray(multiplicity).dtype} "
                         f"of shape {np.shape(multiplicity)}")
    return ContactProblem.from_qp(K, vectors["f"], N, vectors["d"], weights=vectors["weights"],
                                  contact_points=arrays.get("contact_points"),
                                  force_multiplicity=float(np.ravel(multiplicity)[0]), name=name)
