"""``signorini export qpbenchmark``: a test set qpbenchmark runs as it is, with certified answers,
written byte for byte the same twice."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import scipy.sparse as sp

import signorini
from signorini.cli import main
from signorini.studies import qpbench
from signorini.studies.qpbench_run import ACCURACY, judge

#: two small problems: a weakly active edge and a wide contact zone
TINY = ["EDGEBLOCK", "EDGEWIDE"]


@pytest.fixture(scope="module")
def exported(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("qpbench") / "set"
    assert main(["-q", "export", "qpbenchmark", str(folder), *(f"--only={n}" for n in TINY)]) == 0
    return folder


def load(path: Path) -> dict[str, np.ndarray]:
    with np.load(path) as data:
        return {key: data[key] for key in data.files}


def csc(data: dict, key: str) -> sp.csc_matrix:
    return sp.csc_matrix((data[f"{key}_data"], data[f"{key}_indices"], data[f"{key}_indptr"]),
                         shape=tuple(data[f"{key}_shape"]))


def test_layout_follows_qpbenchmarks_test_sets(exported):
    assert sorted(p.name for p in (exported / "data").iterdir()) == sorted(f"{n}.npz" for n in TINY)
    for name in ("signorini_contact.py", "signorini_contact_dense.py", "README.md"):
        assert (exported / name).is_file()
    assert (exported / "results").is_dir()
    readme = (exported / "README.md").read_text()
    assert all(f"``{n}``" in readme for n in TINY) and "MIT" in readme


def test_every_stored_answer_passes_the_certificate(exported):
    for path in sorted((exported / "data").glob("*.npz")):
        data = load(path)
        P, G = csc(data, "P"), csc(data, "G")
        assert abs(P - P.T).max() == 0  # qpsolvers' P: symmetric
        qp = signorini.ContactProblem.from_qp(P, -data["q"], G, data["h"])
        cert = signorini.certificate(qp, u=data["x_ref"], force=data["z_ref"])
        assert cert.passed(1e-10), (path.name, cert.worst())
        stored = dict(zip(data["certificate_names"].tolist(), data["certificate_values"].tolist()))
        assert max(v for v in stored.values() if v == v) <= 1e-10
        assert np.all(data["z_ref"] >= 0) and np.count_nonzero(data["z_ref"]) > 0


def test_the_qp_is_the_scenes_own_in_its_units(exported):
    """P = K, q = −f, G = N, h = d of the problem at its load, not rescaled."""
    result = signorini.solve("block", "pdas", params={"touching": 0.5, "nx": 16, "ny": 16})
    K, f, N, d = result.problem.qp()
    data = load(exported / "data" / "EDGEBLOCK.npz")
    assert abs(csc(data, "P") - K).max() <= 1e-12 * abs(K).max()
    assert np.array_equal(data["q"], -f) and np.array_equal(data["h"], d)
    assert abs(csc(data, "G") - N).max() == 0


def test_exporting_twice_gives_identical_bytes(exported, tmp_path):
    qpbench.export(str(tmp_path), only=TINY)
    first = sorted(p.relative_to(exported) for p in exported.rglob("*") if p.is_file()
                   and p.parent.name != "results")
    second = sorted(p.relative_to(tmp_path) for p in tmp_path.rglob("*") if p.is_file())
    assert first == second
    for rel in first:
        assert (exported / rel).read_bytes() == (tmp_path / rel).read_bytes(), rel


def test_qpbenchmark_runs_the_test_set_as_it_is(exported, tmp_path):
    pytest.importorskip("qpbenchmark", reason="the test set is run by qpbenchmark: "
                        "pip install qpbenchmark (the test extra)")
    pytest.importorskip("osqp", reason="the run uses OSQP: pip install osqp")
    folder = tmp_path / "set"
    qpbench.export(str(folder), only=TINY)
    # qpbenchmark asks for the report's author on stdin when --author is not given
    proc = subprocess.run([sys.executable, str(folder / "signorini_contact.py"), "run",
                           "--solver", "osqp"], input="pytest\n", capture_output=True,
                          text=True, timeout=600, cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr[-2000:]
    report = (folder / "results" / "signorini_contact.md").read_text()
    assert "Signorini contact test set" in report and "osqp" in report
    rows = (folder / "results" / "qpbenchmark_results.csv").read_text().splitlines()
    assert sorted({row.split(",")[0] for row in rows[1:]}) == sorted(TINY)
    assert len(rows) - 1 == len(TINY) * 4  # qpbenchmark's four settings


def test_a_run_is_judged_by_the_certified_answer(exported):
    qpsolvers = pytest.importorskip("qpsolvers", reason="the judged run reads qpsolvers' Solution")
    qpbenchmark = pytest.importorskip("qpbenchmark", reason="pip install qpbenchmark")
    data = load(exported / "data" / "EDGEWIDE.npz")
    P, G, q, h = csc(data, "P"), csc(data, "G"), data["q"], data["h"]
    qp = signorini.ContactProblem.from_qp(P, -q, G, h)
    reference = (data["x_ref"], data["z_ref"], {})
    tolerance = qpbenchmark.Tolerance(primal=1.0, dual=1.0, gap=1.0, runtime=10.0)

    def judged(z):
        solution = qpsolvers.Solution(qpsolvers.Problem(P, q, G, h))
        solution.found, solution.x, solution.z = True, data["x_ref"].copy(), z
        return judge(qp, solution, reference, tolerance, "default", 0.0, "given", "EDGEWIDE")

    exact = judged(data["z_ref"].copy())
    assert exact.close and exact.valid and exact.certificate <= 1e-10
    off = judged(data["z_ref"] * (1 + 10 * ACCURACY["default"]))  # 1 % off every force
    assert not off.close and off.z_error == pytest.approx(10 * ACCURACY["default"])
    assert off.valid  # qpbenchmark's absolute residuals cannot see it: the forces are small


def test_entries_in_a_fixed_order_with_a_place_for_two_bodies():
    names = [e.name for e in qpbench.entries()]
    assert len(names) == len(set(names)) and names == [e.name for e in qpbench.entries()]
    assert {"HERTZCYL0", "HERTZSPH2", "NU04999", "UNITSSI", "UNITSMM", "EDGEPUNCH"} <= set(names)
    assert "SPH3D" not in names and "SPH3D" in {e.name for e in qpbench.entries(three_d=True)}
    scenes = {e.scene for e in qpbench.FAMILIES["two-bodies"](0)}
    assert scenes == {"hertz-two-cylinders", "two-block-patch"}
    known = signorini.scene_families()
    assert all((e.scene in known) == (e.name in names) for e in qpbench.FAMILIES["two-bodies"](0))


def test_bad_input_exits_2_and_writes_nothing(tmp_path, capsys):
    folder = tmp_path / "set"
    assert main(["export", "qpbenchmark", str(folder), "--only", "NOPE"]) == 2
    assert main(["export", "qpbenchmark", str(folder), "--refine", "-1"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 2 and "--only NOPE" in err[0] and "--refine" in err[1]
    assert not folder.exists()


def test_a_second_export_into_the_folder_leaves_only_its_own_problems(tmp_path):
    qpbench.export(str(tmp_path), only=TINY)
    qpbench.export(str(tmp_path), only=TINY[:1])
    assert sorted(p.name for p in (tmp_path / "data").iterdir()) == [f"{TINY[0]}.npz"]


def test_the_committed_run_covers_every_solver_and_the_page_reads_it():
    """docs/qpbench.md's tables are what tools/qpbench.py renders from docs/qpbench/runs.json,
    which has every solver installed when it ran, each at default and high accuracy, and
    judges "close" by the accuracy the runner defines."""
    import importlib.util
    import json

    root = Path(__file__).resolve().parents[1]
    spec = importlib.util.spec_from_file_location("qpbench_tool", root / "tools" / "qpbench.py")
    tool = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(tool)
    from readme import current  # tools/readme.py, put on the path by the tool

    record = json.loads(tool.OUT.read_text())
    text = tool.DOC.read_text(encoding="utf-8")
    for name, body in tool.blocks(record).items():
        assert current(text, name) == body, f"docs/qpbench.md block {name!r}: run tools/qpbench.py --doc"
    runs = record["runs"] + record["dense_runs"]
    assert set(record["available"]) == {r["solver"] for r in runs}
    assert {r["settings"] for r in runs} == {"default", "high_accuracy"}
    for r in runs:
        assert r["close"] == (r["found"] and max(r["x_error"], r["z_error"]) <= ACCURACY[r["settings"]])
    for name in ("signorini_contact.md", "signorini_contact_dense.md"):
        assert (tool.OUT.parent / name).is_file()
