"""``validate`` for CI: a user's problem and method, --tol, --opt, a limits file, JUnit XML, annotations.

The JUnit file is validated against the schema CI systems read (Jenkins'
xunit ``junit-10.xsd``, shipped in tests/data); GitHub Actions annotations are
``::error`` lines on stdout only under ``GITHUB_ACTIONS=true``.
"""

import json
import textwrap
import xml.etree.ElementTree as ET
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

import signorini
from signorini.cli import main
from signorini.output.ci import github_annotations, junit_xml
from signorini.studies.suite import LIMITS

SCHEMA = Path(__file__).parent / "data" / "junit-10.xsd"

METHODS = textwrap.dedent("""
    import numpy as np
    from signorini.solvers.pdas import pdas


    def right(problem, **options):
        answer = pdas(problem)
        answer.message = "options " + repr(sorted(options.items()))
        return answer


    def no_force(problem, **options):
        return pdas(problem).u, np.zeros(problem.m)


    def nudged(problem, **options):
        # λ 1e-5 off the exact one, u stationary for it: accepted at tol 1e-3, apart from pdas
        lam = pdas(problem).lam * (1 + 1e-5)
        return problem.displacement_for(lam), lam
""")


def schema():
    xmlschema = pytest.importorskip("xmlschema")
    return xmlschema.XMLSchema(str(SCHEMA))


@pytest.fixture
def inputs(tmp_path, monkeypatch):
    """A folder with the user's method file and the block's QP as a plain .npz (the cwd)."""
    monkeypatch.chdir(tmp_path)
    monkeypatch.delenv("GITHUB_ACTIONS", raising=False)
    (tmp_path / "mine.py").write_text(METHODS)
    problem = signorini.at_load(signorini.build_problem("block"))
    K = problem.K.tocoo()
    np.savez(tmp_path / "beam.npz", K_row=K.row, K_col=K.col, K_data=K.data, K_shape=K.shape,
             N=problem.N.toarray(), f=problem.f, d=problem.d)
    return tmp_path


def checks_of(folder):
    return json.loads((folder / "report.json").read_text())


def test_a_right_method_on_the_users_problem_passes_and_its_junit_is_valid(inputs, capsys):
    code = main(["validate", "--problem", "beam.npz", "--method", "mine.py:right",
                 "--opt", "scale=2", "--junit", "report.xml", "--out", "report"])
    out = capsys.readouterr().out
    assert code == 0, out
    assert "::error" not in out  # not under GitHub Actions
    schema().validate(str(inputs / "report.xml"))
    report = checks_of(inputs / "report")
    root = ET.parse(inputs / "report.xml").getroot()
    cases = root.findall("testsuite/testcase")
    assert len(cases) == len(report["checks"]) > 0
    assert root.get("failures") == "0" and not root.findall(".//failure")
    assert root.find("testsuite").get("file") == "beam.npz"
    runs = [r for r in report["runs"] if r["method"] == "mine.py:right"]
    assert runs and all("('scale', 2)" in r["message"] for r in runs)
    names = [c.get("name") for c in cases]
    assert "mine.py:right@1e-09 converged: λ agrees with pdas" in names
    assert "--opt scale=2" in report["command"] and "--problem beam.npz" in report["command"]


def test_a_wrong_method_fails_with_junit_failures_and_github_annotations(inputs, capsys,
                                                                         monkeypatch):
    monkeypatch.setenv("GITHUB_ACTIONS", "true")
    code = main(["validate", "--problem", "beam.npz", "--method", "mine.py:no_force",
                 "--junit", "report.xml", "--out", "report"])
    out = capsys.readouterr().out
    assert code == 1
    schema().validate(str(inputs / "report.xml"))
    failed = [c for c in checks_of(inputs / "report")["checks"] if not c["passed"]]
    annotations = [line for line in out.splitlines() if line.startswith("::error ")]
    assert len(annotations) == len(failed) > 0
    assert all(line.startswith("::error file=beam.npz,title=beam%3A ") for line in annotations)
    failing = [case.get("name") for case in ET.parse(inputs / "report.xml").getroot().iter("testcase")
               if case.find("failure") is not None]
    assert sorted(failing) == sorted(c["name"] for c in failed)
    assert "mine.py:no_force (asked for by name) converged" in failing


def test_tol_and_a_limits_file_decide_what_passes(inputs, capsys):
    (inputs / "loose.toml").write_text("[limits]\nlam_rel_vs_pdas = 1e-4\n")
    argv = ["validate", "--problem", "beam.npz", "--method", "mine.py:nudged", "--tol", "1e-3"]
    assert main([*argv, "--out", "strict"]) == 1  # λ 1e-5 apart: over the default 1e-6
    strict = checks_of(inputs / "strict")
    apart = [c for c in strict["checks"] if "λ agrees with pdas" in c["name"]]
    assert apart and not apart[0]["passed"] and 1e-6 < apart[0]["value"] < 1e-4
    assert main([*argv, "--limits", "loose.toml", "--out", "loose"]) == 0
    loose = checks_of(inputs / "loose")
    assert loose["limits"]["lam_rel_vs_pdas"] == 1e-4
    assert loose["limits"]["force_balance"] == LIMITS["force_balance"]
    assert all(run["tol"] == 1e-3 for run in loose["runs"] if run["method"] == "mine.py:nudged")


#: (extra argv, words the one line on stderr must hold)
BAD = [
    (["--limits", "missing.toml"], ["missing.toml", "does not exist"]),
    (["--limits", "bad.toml"], ["bad.toml", "TOML"]),
    (["--limits", "unknown.toml"], ["unknown.toml", "'lam_rel'", "lam_rel_vs_pdas"]),
    (["--limits", "negative.toml"], ["negative.toml", "force_balance", "positive number"]),
    (["--limits", "table.toml"], ["table.toml", "[limits]"]),
    (["--tol", "2"], ["--tol", "(0, 1)"]),
    (["--method", "pdas", "--opt", "step=1"], ["--opt 'step=1'", "METHOD:step=1"]),
    (["--opt", "uzawa:step_fraction=0.5"], ["uzawa", "not among the --method"]),
    (["--method", "pdas", "--opt", "pdas:no_such_option=1"], ["no_such_option"]),
    (["--problem", "missing.npz"], ["missing.npz", "does not exist"]),
    (["--problem", "bad.toml"], ["'bad.toml' is not a problem file", ".npz"]),
    (["--junit", "-"], ["--junit -", "file name"]),
    (["--junit", "beam.npz"], ["--junit", "problem file"]),
    (["--junit", "report"], ["--junit", "--out", "same file"]),
]


@pytest.mark.parametrize("argv, words", BAD, ids=[" ".join(b[0]) for b in BAD])
def test_bad_ci_input_is_refused_in_one_line_before_any_work(inputs, capsys, argv, words):
    (inputs / "bad.toml").write_text("[limits\n")
    (inputs / "unknown.toml").write_text("[limits]\nlam_rel = 1e-3\n")
    (inputs / "negative.toml").write_text("[limits]\nforce_balance = -1\n")
    (inputs / "table.toml").write_text("lam_rel_vs_pdas = 1e-3\n")
    before = sorted(p.name for p in inputs.iterdir())
    code = main(["validate", "--problem", "beam.npz", "--method", "mine.py:right",
                 *argv, "--out", "report"])
    err = capsys.readouterr().err
    assert code == 2, err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err, err
    for word in words:
        assert word in err, (word, err)
    assert sorted(p.name for p in inputs.iterdir()) == before  # nothing written


def fake_suite(detail):
    check = SimpleNamespace(case="my,case", name="λ: agrees", value=0.5, limit=1e-6,
                            passed=False, detail=detail)
    passed = SimpleNamespace(case="my,case", name="converged", value=True, limit=None,
                             passed=True, detail="")
    result = SimpleNamespace(case=SimpleNamespace(name="my,case", scene="x.npz"),
                             problem=SimpleNamespace(n=2, m=1),
                             runs=[{"time_s": 0.25}, {"time_s": float("nan")}])
    return SimpleNamespace(checks=[check, passed], results=[result], elapsed_s=1.5)


def test_annotations_escape_what_github_reads_as_syntax():
    suite = fake_suite("100% off\nsecond line")
    [line] = github_annotations(suite, {"my,case": "dir/a:b.npz"})
    assert "\n" not in line
    properties, _, message = line[len("::error "):].partition("::")
    assert properties == "file=dir/a%3Ab.npz,title=my%2Ccase%3A λ%3A agrees"
    assert "100%25 off%0Asecond line" in message and "0.5 is over the limit 1e-06" in message


def test_junit_holds_control_characters_and_counts_as_the_schema_wants(tmp_path):
    suite = fake_suite("bell \x07 and escape \x1b")
    path = tmp_path / "r.xml"
    path.write_text(junit_xml(suite, {"my,case": "x.npz"}), encoding="utf-8")
    schema().validate(str(path))
    root = ET.parse(path).getroot()
    assert (root.get("tests"), root.get("failures")) == ("2", "1")
    suite_element = root.find("testsuite")
    assert suite_element.get("time") == "0.250" and suite_element.get("file") == "x.npz"
    assert "\x07" not in root.find(".//failure").get("message")
