"""The files of the qpbenchmark test set: each problem's .npz, the test-set scripts, the README.

The scripts need numpy, scipy and qpbenchmark only (not signorini): a QP solver's author
runs them as qpbenchmark's own test sets are run, ``python signorini_contact.py run``.
"""

from __future__ import annotations

import io
import os
import zipfile

import numpy as np

from signorini.files import atomic_write_text

__all__ = ["DENSE_SCRIPT", "SCRIPT", "readme", "write_npz", "write_test_set"]

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
    tmp = f"{path}.part"
    with open(tmp, "wb") as out:
        out.write(buffer.getvalue())
    os.replace(tmp, path)


SCRIPT = '''#!/usr/bin/env python3
# -*- coding: utf-8 -*-
#
# SPDX-License-Identifier: MIT

"""Signorini contact test set: frictionless contact QPs with certified answers."""

import os
from typing import Dict, Iterator, Tuple

import numpy as np
import qpbenchmark
import scipy.sparse as spa
from qpbenchmark.benchmark import main
from qpbenchmark.problem import Problem


def load_csc(data, key: str) -> spa.csc_matrix:
    """Read a CSC matrix stored as its data, indices, indptr and shape."""
    return spa.csc_matrix(
        (data[f"{key}_data"], data[f"{key}_indices"], data[f"{key}_indptr"]),
        shape=tuple(data[f"{key}_shape"]),
    )


class SignoriniContact(qpbenchmark.TestSet):
    """Frictionless (Signorini) contact of linearly elastic bodies, one QP each.

    Each problem is min 1/2 x^T P x + q^T x subject to G x <= h, with P the
    stiffness K (sparse, symmetric positive definite), q = -f the load, G the
    normal-gap rows N (one per contact candidate node) and h = d the initial
    gaps, in the units of the scene it comes from (not rescaled). The optimal
    z is the vector of nodal contact forces.
    """

    data_dir: str

    @property
    def description(self) -> str:
        """Description of the test set."""
        return (
            "Frictionless contact QPs from finite elements (the signorini "
            "package): sparse SPD stiffness, contact at the edge of the zone, "
            "nearly incompressible bodies, SI and mm-MPa units unscaled. "
            "Each problem ships its certified answer (data/*.npz: x_ref, z_ref)."
        )

    @property
    def title(self) -> str:
        """Test set title."""
        return "Signorini contact test set"

    @property
    def sparse_only(self) -> bool:
        """This test set is sparse."""
        return True

    def define_tolerances(self) -> None:
        """qpbenchmark's tolerance levels, with a time limit for FEM sizes."""
        super().define_tolerances(runtime=60.0)

    def define_solver_settings(self) -> None:
        """qpbenchmark's settings, with what contact QPs need on top.

        The stiffness of a fine mesh is ill-conditioned (its condition
        number grows as 1/h^2, and as 1/(1 - 2 nu) near incompressibility),
        so first-order solvers (OSQP, SCS) get more iterations at the
        accuracy levels, and OSQP polishes its answer on the active set it
        found (solution polishing), as contact wants exact active sets.
        """
        super().define_solver_settings()
        for name in ("high_accuracy", "mid_accuracy"):
            settings = self.solver_settings[name]
            settings.set_param("osqp", "max_iter", 100000)
            settings.set_param("osqp", "polishing", True)
            settings.set_param("scs", "max_iters", 100000)

    def __init__(self):
        """Initialize test set."""
        super().__init__()
        current_dir = os.path.dirname(os.path.abspath(__file__))
        self.data_dir = os.path.join(current_dir, "data")

    def problem_names(self) -> Tuple[str, ...]:
        """Names of the problems, in a fixed order."""
        return tuple(
            sorted(
                fname[:-4]
                for fname in os.listdir(self.data_dir)
                if fname.endswith(".npz")
            )
        )

    def load(self, name: str) -> Problem:
        """Load one problem by name."""
        with np.load(os.path.join(self.data_dir, f"{name}.npz")) as data:
            return Problem(
                load_csc(data, "P"),
                data["q"],
                load_csc(data, "G"),
                data["h"],
                None,
                None,
                None,
                None,
                name=name,
            )

    def reference(self, name: str) -> Tuple[np.ndarray, np.ndarray, Dict]:
        """Certified answer (x, z) of a problem and its certificate.

        The certificate's residuals are relative (see README.md): a
        solver's answer can be judged by its distance to (x, z) as well as
        by its residuals.
        """
        with np.load(os.path.join(self.data_dir, f"{name}.npz")) as data:
            certificate = dict(
                zip(
                    data["certificate_names"].tolist(),
                    data["certificate_values"].tolist(),
                )
            )
            return data["x_ref"], data["z_ref"], certificate

    def __iter__(self) -> Iterator[Problem]:
        """Iterate over test set problems."""
        for name in self.problem_names():
            yield self.load(name)


if __name__ == "__main__":
    test_set_path = os.path.abspath(__file__)
    test_set_dir = os.path.dirname(test_set_path)
    main(
        test_set_path=test_set_path,
        results_path=f"{test_set_dir}/results/qpbenchmark_results.csv",
    )
'''

DENSE_SCRIPT = '''#!/usr/bin/env python3
# -*- coding: utf-8 -*-
#
# SPDX-License-Identifier: MIT

"""Dense subset of the Signorini contact test set."""

import os
from typing import Iterator

from qpbenchmark.benchmark import main
from qpbenchmark.problem import Problem

from signorini_contact import SignoriniContact

#: problems with at most this many unknowns are in the dense subset
DENSE_MAX_DOFS = {dense_max}


class SignoriniContactDense(SignoriniContact):
    """Subset of problems small enough for dense solvers."""

    @property
    def title(self) -> str:
        """Test set title."""
        return "Signorini contact dense subset"

    @property
    def sparse_only(self) -> bool:
        """This test set is open to sparse and dense matrices."""
        return False

    def __iter__(self) -> Iterator[Problem]:
        """Iterate on test set problems."""
        for problem in super().__iter__():
            if problem.P.shape[0] <= DENSE_MAX_DOFS:
                yield problem.to_dense()


if __name__ == "__main__":
    test_set_path = os.path.abspath(__file__)
    test_set_dir = os.path.dirname(test_set_path)
    main(
        test_set_path=test_set_path,
        results_path=f"{{test_set_dir}}/results/qpbenchmark_results_dense.csv",
    )
'''


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
    return f"""# Signorini contact test set for QP solvers

Frictionless (Signorini) contact QPs in a format suitable for
[qpbenchmark](https://github.com/qpsolvers/qpbenchmark), written by
`signorini export qpbenchmark`. Each problem is one finite-element contact QP

    minimize    1/2 x^T P x + q^T x
    subject to  G x <= h

with P the stiffness K (sparse, symmetric positive definite), q = -f the load, G the
normal-gap rows N (one per contact candidate node) and h = d the initial gaps, in the units
of the scene it comes from. The optimal z (qpsolvers' multiplier of G x <= h) is the vector
of nodal contact forces.

Every problem ships its reference answer: `data/NAME.npz` holds the QP (P and G as CSC
arrays `P_data`, `P_indices`, `P_indptr`, `P_shape`, ...; `q`, `h`) and `x_ref`, `z_ref`:
the primal-dual active-set (semismooth Newton) method's answer on exactly these arrays,
judged by the KKT certificate whose relative residuals are stored beside it
(`certificate_names`, `certificate_values`): primal feasibility, stationarity against the
contact forces, dual sign, complementarity, the natural (min-map) residual, the duality gap,
and the forward error of z and x (one Newton step on the active set). A solver's result can
thus be judged by its distance to the certified answer, not by its residuals alone:
`SignoriniContact().reference(name)` returns `(x_ref, z_ref, certificate)`.

## Installation

```console
pip install qpbenchmark
```

## Usage

Run the test set as follows:

```console
python signorini_contact.py run
python signorini_contact.py run --solver osqp --author your-name
```

The outcome, written to the `results/` directory, is qpbenchmark's standardized report
(`results/signorini_contact.md`) and its results (`results/qpbenchmark_results.csv`).
qpbenchmark asks for the report's author (a GitHub user name) unless `--author` is given.

## Settings

qpbenchmark's four settings and tolerances (default, low, mid and high accuracy), a time limit
of 60 s, and for contact: OSQP and SCS get 100000 iterations and OSQP polishes its answer at
mid and high accuracy. qpbenchmark's tolerances are absolute, and these problems are not
rescaled: in SI units (``UNITSSI``) a residual of 1 is small against forces of 10⁶ N/m, in
the dimensionless scenes (E = 1) it is larger than every force. That is deliberate: it is the
QP a user hands a solver. Judge by the stored answer as well.

## Dense subset

A *dense* subset holds the problems with at most {dense_max} unknowns
({", ".join(f"``{n}``" for n in dense) or "none at this size"}):

```console
python signorini_contact_dense.py run
```

## Problems

Sizes: n unknowns, m contact candidates; "active" counts the nodes with a positive reference
force; "certified" is the worst relative residual of the reference answer and "z error" its
estimated forward error.

| Problem name | Details | n | m | active | certified | z error |
|--------------|---------|---|---|--------|-----------|---------|
{table}

The families: ``HERTZCYL*`` and ``HERTZSPH*`` (the Hertz cylinder and sphere at three mesh
sizes), ``NU*`` (nearly incompressible: ν = 0.45, 0.499, 0.4999), ``UNITS*`` (SI and mm–MPa,
unscaled), ``EDGE*`` (weakly active constraints: gap 0 and force 0), ``SPH3D`` (3D, when
exported with `--3d`) and ``TWOBODY*`` (two elastic bodies, when the package has the scenes).

## License

MIT.
"""


def write_test_set(directory: str, refs, dense_max: int) -> None:
    """The scripts and the README of the test set made of ``refs``."""
    files = {"signorini_contact.py": SCRIPT,
             "signorini_contact_dense.py": DENSE_SCRIPT.format(dense_max=dense_max),
             "README.md": readme(refs, dense_max)}
    for name, text in files.items():
        atomic_write_text(os.path.join(directory, name), text)
