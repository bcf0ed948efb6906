"""Help and messages that say what to do: every command's help has a description, examples
and exit codes and points to the docs site (a wheel has no docs/ folder); one spelling per
option across commands; a message names the option or variable the user gave."""

import re
import shutil
from pathlib import Path

import numpy as np
import pytest

from signorini.cli import main
from signorini.cli.app import build_parser
from signorini.errors import DOCS_SITE

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
COMMANDS = sorted(build_parser()._subparsers._group_actions[0].choices)


def help_of(capsys, *argv):
    with pytest.raises(SystemExit) as done:
        main([*argv, "--help"])
    assert done.value.code == 0
    return capsys.readouterr().out


def test_there_are_commands_to_read():
    assert {"solve", "validate", "bench", "crosscheck", "converge", "methods"} <= set(COMMANDS)


@pytest.mark.parametrize("command", COMMANDS)
def test_every_commands_help_has_a_description_examples_and_exit_codes(capsys, command):
    text = help_of(capsys, command)
    usage, _, rest = text.partition("\n\n")
    description = rest.split("\n\n")[0]
    assert len(description.split()) >= 8 and not description.startswith(("positional", "options")), text
    examples = text.split("examples:\n")[1].split("\n\n")[0].splitlines()
    assert 2 <= len(examples) <= 3 and all(f"signorini {command}" in e or "signorini " in e
                                           for e in examples), examples
    codes = re.findall(r"^  (\d+) ", text.split("exit codes:\n")[1], re.M)
    assert {"0", "2", "130"} <= set(codes), text
    assert DOCS_SITE in text and "docs/" not in text.replace(DOCS_SITE, ""), text


def test_the_top_level_help_points_to_the_commands_help_and_the_site(capsys):
    text = help_of(capsys)
    assert "COMMAND --help" in text and DOCS_SITE in text


@pytest.mark.parametrize("command", ["solve", "crosscheck", "validate", "bench"])
def test_one_name_per_option_across_commands(capsys, command):
    text = help_of(capsys, command)
    assert "--tol" in text and "--tolerance" not in text
    if command != "bench":
        assert "--opt [METHOD:]KEY=VALUE" in text, text


@pytest.mark.parametrize("argv", [["--opt", "pdas:max_iter=3"], ["--opt", "max_iter=3"]])
def test_solve_takes_either_form_of_opt(capsys, argv):
    assert main(["solve", "block", "--set", "nx=4", "--set", "ny=4", "--method", "pdas", *argv]) in (0, 1)
    out = capsys.readouterr()
    assert "pdas" in out.out and "error" not in out.err


def test_an_option_for_another_method_is_refused_naming_it(capsys):
    assert main(["solve", "block", "--method", "pdas", "--opt", "uzawa:rho=1"]) == 2
    err = capsys.readouterr().err
    assert "'uzawa'" in err and "--method" in err, err


@pytest.mark.parametrize("argv, words", [
    (["bench", "--sizes", "-1"], ["--sizes '-1'", "level -1", "0..6"]),
    (["bench", "--scene", "block", "--sizes", "0"], ["--scene block", "refine"]),
    (["bench", "--tol", "tight"], ["--tol 'tight'", "mid,high"]),
    (["converge", str(EXAMPLES / "block-mesh.toml")], ["block-mesh.toml", "converge cannot refine"]),
])
def test_a_message_names_the_option_given(capsys, tmp_path, argv, words):
    assert main([*argv, "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "refine=" not in err, err
    for word in words:
        assert word in err, (word, err)


def test_a_bad_factorisation_variable_is_named_with_its_choices(capsys, monkeypatch):
    monkeypatch.setenv("SIGNORINI_FACTOR", "magic")
    assert main(["solve", "block", "--set", "nx=4", "--set", "ny=4", "--method", "pdas"]) == 2
    err = capsys.readouterr().err
    for word in ("SIGNORINI_FACTOR='magic'", "factorisation backend", "superlu"):
        assert word in err, (word, err)


@pytest.mark.slow
def test_converge_takes_a_scene_file_that_names_its_family(capsys, tmp_path):
    scene = tmp_path / "cylinder.toml"
    shutil.copy(EXAMPLES / "hertz-cylinder.toml", scene)
    assert main(["converge", str(scene), "--levels", "1", "--method", "pdas", "--set", "n_contact=10",
                 "--out", str(tmp_path / "c")]) == 0
    assert (tmp_path / "c" / "convergence-hertz-cylinder.md").is_file()


def test_the_summary_of_a_qp_without_an_applied_load_leaves_it_out(capsys, tmp_path):
    path = tmp_path / "qp.npz"
    np.savez(path, K=np.diag([2.0, 1.0]), f=np.ones(2), N=np.array([[1.0, 0.0]]), d=np.array([0.25]))
    assert main(["solve", str(path)]) == 0
    out = capsys.readouterr().out
    assert "total force" in out and "applied" not in out and "nan" not in out, out
    assert main(["solve", "block", "--set", "nx=4", "--set", "ny=4"]) == 0
    assert "(applied " in capsys.readouterr().out
