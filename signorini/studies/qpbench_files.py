"""The files of the qpbenchmark test set: each problem's .npz, the test-set scripts, the README.

The scripts need numpy, scipy and qpbenchmark only (not signorini): a QP solver's author
runs them as qpbenchmark's own test sets are run, ``python signorini_contact.py run``.
"""

from __future__ import annotations

import io
import os
import string
import zipfile
from importlib import resources

import numpy as np

from signorini.files import atomic_write_bytes, atomic_write_text

__all__ = ["TEMPLATES", "readme", "write_npz", "write_test_set"]

#: one fixed time stamp for every member of every .npz (the ZIP format's earliest)
ZIP_DATE = (1980, 1, 1, 0, 0, 0)


def write_npz(path: str, arrays: dict[str, np.ndarray]) -> None:
    """``arrays`` into an uncompressed .npz that ``np.load`` reads, its bytes a function of the
    arrays alone: members in the given order, each with the same fixed time stamp."""
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w", compression=zipfile.ZIP_STORED) as archive:
        for key, value in arrays.items():
            info = zipfile.ZipInfo(f"{key}.npy", date_time=ZIP_DATE)
            info.external_attr = 0o644 << 16
            with archive.open(info, "w", force_zip64=True) as member:
                np.lib.format.write_array(member, np.asarray(value), allow_pickle=False)
    atomic_write_bytes(path, buffer.getvalue())


#: the test set's files, each written from the template of the same name in qpbench_templates/
TEMPLATES = ("signorini_contact.py", "signorini_contact_dense.py", "README.md")


def _template(name: str) -> string.Template:
    return string.Template((resources.files(__package__) / "qpbench_templates" / f"{name}.in")
                           .read_text(encoding="utf-8"))


def _row(ref) -> str:
    cert = ref.certificate
    worst = ref.worst()[1]
    active = int(np.count_nonzero(ref.z > 0))
    return (f"| ``{ref.entry.name}`` | {ref.entry.what} | {ref.P.shape[0]} | {ref.G.shape[0]} | "
            f"{active} | {worst:.1e} | {cert['force_error']:.1e} |")


def readme(refs, dense_max: int) -> str:
    """The test set's README: what it is, how to run it, its problems, its licence."""
    dense = [r.entry.name for r in refs if r.P.shape[0] <= dense_max]
    table = "\n".join(_row(r) for r in refs)
    return _template("README.md").substitute(
        dense_max=dense_max, table=table,
        dense=", ".join(f"``{n}``" for n in dense) or "none at this size")


def write_test_set(directory: str, refs, dense_max: int) -> None:
    """The scripts and the README of the test set made of ``refs``."""
    for name in TEMPLATES:
        text = readme(refs, dense_max) if name == "README.md" else \
            _template(name).substitute(dense_max=dense_max)
        atomic_write_text(os.path.join(directory, name), text)
