"""Hostile saved problems and time limits: every array and number of a file ContactProblem.save
wrote is checked against the rest before it is used (no C code reads an index out of range, no
array of a declared size is made), the refusal names the field and the fix, the file is left as
it was; a time limit beyond what the platform's clock can wait for still runs the solve.
"""

import copy
import io
import json
import zipfile
from pathlib import Path

import numpy as np
import pytest

import signorini
from signorini.cli import main
from signorini.errors import InputError
from signorini.scenes import build_problem


@pytest.fixture(scope="module")
def saved(tmp_path_factory):
    """The arrays and the meta record of a pending scene problem as save writes them."""
    path = tmp_path_factory.mktemp("saved") / "cylinder.npz"
    problem = build_problem("hertz-cylinder", params={"n_contact": 8})
    assert problem.model.pending and problem.model.predicted_contact is not None
    assert problem.model.watch is not None
    problem.save(path)
    with np.load(path) as z:
        arrays = {key: z[key] for key in z.files}
    return arrays, json.loads(bytes(arrays["meta"]).decode())


def changed(arrays, record, **changes):
    out = {**arrays, "meta": np.frombuffer(json.dumps(record).encode(), dtype=np.uint8)}
    for key, value in changes.items():
        if value is None:
            out.pop(key)
        else:
            out[key] = value(arrays[key]) if callable(value) else value
    return out


def meta_with(meta, record, key, value):
    meta = copy.deepcopy(meta)
    target = {"top": meta, "disc": meta["discretisation"],
              "push": meta["discretisation"]["push"], "watch": meta["discretisation"]["watch"]}
    target[record][key] = value
    return meta


#: (case, the arrays changed, the meta changed, what the refusal names)
ATTACKS = [
    ("index out of range", dict(K_indices=lambda v: v + 10**6), None, "K"),
    ("push resultant NaN", dict(push_resultant=np.array(np.nan)), None, "push_resultant"),
    ("push resultant short", dict(push_resultant=np.ones(3)), None, "push_resultant"),
    ("prediction short", dict(predicted_contact=lambda v: v[:3]), None, "predicted_contact"),
    ("prediction floats", dict(predicted_contact=lambda v: v.astype(float)), None,
     "predicted_contact"),
    ("watch columns", {}, ("watch", "columns", 10**12), "watch"),
    ("free dofs beyond the model", dict(free_dofs=lambda v: v + 10**9), None, "free_dofs"),
    ("mesh corners", dict(mesh_t=lambda v: v + 10**6), None, "mesh_t"),
    ("push of the wrong size", dict(push_f1=lambda v: v[:5]), None, "push_f1"),
    ("contact points short", dict(contact_points=lambda v: v[:2]), None, "contact_points"),
    ("a pickled array", dict(f=np.array([object()] * 3, dtype=object)), None, "allow_pickle"),
    ("a missing push", dict(push_d0=None), None, "push_d0"),
    ("an extra array", dict(extra=np.zeros(3)), None, "extra"),
    ("a material as text", {}, ("disc", "E", "steel"), "E"),
    ("a scale of zero", {}, ("top", "scales", {"length": 1, "displacement": 0, "force": 0,
                                               "weight": 1}), "scales"),
    ("a multiplicity as text", {}, ("top", "force_multiplicity", "two"), "force_multiplicity"),
    ("a target as text", {}, ("push", "target", "x"), "target"),
    ("params as a list", {}, ("disc", "params", [1]), "params"),
    ("nu of one half", {}, ("disc", "nu", 0.5), "nu"),
    ("E as true", {}, ("disc", "E", True), "E"),
    ("materials as text", {}, ("disc", "materials", ["ab"]), "materials"),
    ("a push of zero", {}, ("push", "scale", 0), "scale"),
    ("pending without a target", {}, ("push", "target", None), "target"),
    ("meta nested past recursion", dict(meta=np.frombuffer(b"[" * 10**5 + b"]" * 10**5,
                                                           dtype=np.uint8)), None, "meta"),
]


@pytest.mark.parametrize("case, arrays, meta, field", ATTACKS, ids=[a[0] for a in ATTACKS])
def test_a_hand_made_saved_problem_is_refused_naming_its_field(saved, tmp_path, case, arrays,
                                                                meta, field):
    stored, record = saved
    path = tmp_path / "attack.npz"
    np.savez(path, **changed(stored, meta_with(record, *meta) if meta else record, **arrays))
    before = path.read_bytes()
    with pytest.raises(InputError, match=field) as refused:
        signorini.ContactProblem.load(path)
    assert "attack.npz" in str(refused.value) and "again" in str(refused.value)
    assert path.read_bytes() == before


def test_a_declared_size_is_refused_before_the_api_allocates_it(saved, tmp_path):
    stored, _ = saved
    path = tmp_path / "huge.npz"
    with zipfile.ZipFile(path, "w") as archive:
        for key, value in stored.items():
            buffer = io.BytesIO()
            if key == "K_data":  # a header declaring 10^12 floats, eight of them stored
                np.lib.format.write_array_header_1_0(
                    buffer, {"descr": "<f8", "fortran_order": False, "shape": (10**12,)})
                buffer.write(np.zeros(8).tobytes())
            else:
                np.save(buffer, value)
            archive.writestr(f"{key}.npy", buffer.getvalue())
    with pytest.raises(InputError, match="K_data' declares shape"):
        signorini.ContactProblem.load(path)


@pytest.mark.parametrize("arrays", [dict(K_indices=lambda v: v + 10**6),
                                    dict(push_resultant=np.array(np.nan))],
                         ids=["index out of range", "resultant NaN"])
def test_signorini_solve_of_a_hand_made_saved_problem_says_one_line(saved, tmp_path, capsys,
                                                                     arrays):
    stored, record = saved
    path = tmp_path / "attack.npz"
    np.savez(path, **changed(stored, record, **arrays))
    assert main(["solve", str(path)]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err, err
    assert next(iter(arrays)) in err


def test_every_scene_kind_still_loads_as_saved(saved, tmp_path):
    stored, record = saved
    path = tmp_path / "same.npz"  # written by NumPy from what save wrote
    np.savez(path, **changed(stored, record))
    again = signorini.ContactProblem.load(path)
    assert again.model.pending and again.model.watch is not None
    qp = signorini.ContactProblem.from_qp(K=np.diag([2.0, 1.0]), f=np.ones(2),
                                          N=np.array([[1.0, 0.0]]), d=np.array([0.25]))
    qp.save(tmp_path / "qp.npz")
    assert signorini.ContactProblem.load(tmp_path / "qp.npz").K.toarray()[0, 0] == 2.0


def test_a_time_limit_past_the_platforms_clock_still_runs_the_solve(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    signorini.ContactProblem.from_qp(K=np.diag([2.0, 1.0]), f=np.ones(2),
                                     N=np.array([[1.0, 0.0]]), d=np.array([0.25])).save("qp.npz")
    assert main(["solve", "qp.npz", "--time-limit", "1e308"]) == 0
    assert "Traceback" not in capsys.readouterr().err


def test_the_certificate_refuses_a_duality_gap_flag_that_is_not_true_or_false():
    qp = signorini.ContactProblem.from_qp(K=np.diag([2.0, 1.0]), f=np.ones(2),
                                          N=np.array([[1.0, 0.0]]), d=np.array([0.25]))
    result = signorini.solve(qp, "pdas")
    with pytest.raises(InputError, match="duality_gap"):
        signorini.certificate(qp, result.solution, duality_gap="no")
    assert signorini.certificate(qp, result.solution, duality_gap=False).passed(1e-8)


#: a row with the columns of the benchmark and dofs that are no number
FOREIGN_ROW = (b"scene,size,dofs,candidates,method,ranks,tolerance,status,claimed_status,iterations,"
               b"build_s,solve_s,time_s,factor_s,ratio_to_factor,kkt_worst,lam_rel,misclassified,"
               b"p0_rel,a_rel,message\nhertz-cylinder,refine0,abc,58,pdas,1,high,converged,"
               b"converged,1,0.1,0.1,0.1,0.1,1,1e-10,0,0,0,0,\n")


@pytest.mark.parametrize("content, report_only", [
    (b"a,b\n1,2\n", True), (b"a,b\n1,2\n", False), (b"\xff\xfe\x00not text", True),
    (b"\xff\xfe\x00not text", False), (FOREIGN_ROW, True)],
    ids=["foreign columns, report", "foreign columns, runs", "not text, report", "not text, runs",
         "a row bench did not write"])
def test_a_benchmark_csv_bench_did_not_write_is_refused_and_kept(tmp_path, capsys, content,
                                                                 report_only):
    (tmp_path / "bench.csv").write_bytes(content)
    argv = ["bench", "--out", str(tmp_path), "--sizes", "0", "--method", "pdas"]
    assert main(argv + (["--report-only"] if report_only else [])) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "bench.csv" in err and "Traceback" not in err
    assert (tmp_path / "bench.csv").read_bytes() == content
    assert not (tmp_path / "bench.md").exists()


def test_a_load_far_beyond_hertz_is_refused_in_a_short_line():
    """A huge P names the a/R it gives in a few digits, not a 150-digit fixed-point number."""
    problem = build_problem("hertz-cylinder", {"n_contact": 8})
    with pytest.raises(InputError) as raised:
        signorini.with_load(problem, P=1e300)
    message = str(raised.value)
    assert "a/R = 1.08e+150 > 0.5" in message and len(message) < 200


def test_a_junit_file_may_go_into_the_report_folder_validate_creates(tmp_path, capsys):
    """``--junit`` inside the ``--out`` folder that does not exist yet: the command makes the
    folder, so the path is taken, and the JUnit file is written beside the report."""
    out = tmp_path / "new"
    argv = ["validate", "--out", str(out), "--junit", str(out / "checks.xml"), "--method", "pdas",
            "--case", "block"]
    assert main(argv) == 0, capsys.readouterr().err
    assert (out / "report.md").is_file() and "<testsuites" in (out / "checks.xml").read_text()
    assert main(["validate", "--out", str(tmp_path / "other"), "--junit",
                 str(tmp_path / "elsewhere" / "checks.xml"), "--method", "pdas", "--case",
                 "block"]) == 2  # a folder no output makes is still refused
    assert "does not exist" in capsys.readouterr().err
