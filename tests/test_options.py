"""Method options typed up front: every option declared with a kind, a bad value refused before any work.

Issue 13 §2: a string where a number belongs, a negative time limit or an
unknown option is an InputError naming the option (exit 2 in the CLI),
raised before the problem is factorised — not a solver's ``failed``.
"""

import numpy as np
import pytest

import signorini
from signorini.cli import main
from signorini.errors import InputError
from signorini.numerics.factor import Work, counting
from signorini.solvers import condensed, cvxpy_, nested, pdas, petsc_, qp, uzawa
from signorini.solvers.options import KINDS, Option
from signorini.solvers.registry import get_method

#: the backend modules whose methods declare every option's kind
TYPED_BACKENDS = (nested, pdas, condensed, uzawa, qp, cvxpy_, petsc_)
TYPED_METHODS = [m.name for backend in TYPED_BACKENDS for m in backend.METHODS]


@pytest.mark.parametrize("name", TYPED_METHODS)
def test_every_option_of_a_method_has_a_declared_kind(name):
    method = get_method(name)
    assert method.options, name
    assert set(method.typed_options) == set(method.options), name
    for option in method.typed_options.values():
        assert option.kind in KINDS
        if option.kind == "any":  # only MOSEK's parameter dict goes through unchecked
            assert (name, option.name) == ("qp-mosek", "mosek")


def _first_numeric(method):
    for option in method.typed_options.values():
        if option.name != "max_iter" and option.kind in ("positive", "fraction", "count", "positive_count", "nonnegative"):
            return option
    return None


NUMERIC = [(name, _first_numeric(get_method(name)).name) for name in TYPED_METHODS
           if _first_numeric(get_method(name)) is not None]


@pytest.mark.parametrize("name, option", NUMERIC, ids=[f"{n}-{o}" for n, o in NUMERIC])
def test_a_string_for_a_number_is_refused_before_any_work(name, option):
    problem = signorini.build_problem("block")
    with counting() as work, pytest.raises(InputError, match=f"option {option}='abc' must be"):
        signorini.solve(problem, name, **{option: "abc"})
    assert work == Work()  # nothing factorised, nothing solved


@pytest.mark.parametrize("name", [m for m in TYPED_METHODS if m.startswith("qp-")])
def test_a_negative_time_limit_is_refused_for_every_qp_backend_that_has_one(name):
    limits = [o for o in get_method(name).typed_options if o.lower().startswith("time")]
    for option in limits:
        with pytest.raises(InputError, match=f"{option}=-1.0 must be a positive number"):
            signorini.solve("block", name, **{option: -1.0})


@pytest.mark.parametrize("kind, good, converted, bad", [
    ("positive", 2, 2.0, [0, -1.0, float("nan"), float("inf"), "1", True, None]),
    ("nonnegative", 0, 0.0, [-1e-300, "0"]),
    ("fraction", 1, 1.0, [0, 1.5]),
    ("number", -3, -3.0, [float("nan"), "x"]),
    ("integer", -2.0, -2, [0.5, "1"]),
    ("count", 0, 0, [-1, 2.5, "3"]),
    ("positive_count", np.int64(5), 5, [0, 1.1]),
    ("bool", 1, True, [2, "true", 0.0]),
    ("text", "cholmod", "cholmod", [3, None]),
    ("callable", print, print, ["print"]),
])
def test_each_kind_converts_good_values_and_refuses_bad_ones(kind, good, converted, bad):
    option = Option("x", kind, default=1 if kind not in ("text", "callable") else "a")
    if kind == "callable":
        option = Option("x", kind, default=print)
    assert option.check("m", good) == converted
    for value in bad:
        with pytest.raises(InputError, match="option x="):
            option.check("m", value)


def test_a_vector_option_is_checked_for_kind_then_length():
    with pytest.raises(InputError, match="lam0='abc' must be an array"):
        signorini.solve("block", "uzawa", lam0="abc")
    with pytest.raises(InputError, match="lam0 has 2 entries, the problem 17 contact candidates"):
        signorini.solve("block", "uzawa", lam0=[1.0, 2.0])
    with pytest.raises(InputError, match="lam0=.* must be an array of finite floats"):
        signorini.solve("block", "pdas", lam0=[np.nan] * 17)


@pytest.mark.parametrize("argv, words", [
    (["--method", "pdas", "--opt", "c=abc"], ["c='abc'", "positive number", "e.g. c=1"]),
    (["--method", "pdas", "--opt", "callback=print"], ["callback='print'", "Python API only"]),
    (["--method", "qp-osqp", "--opt", "time_limit=-1"], ["time_limit=-1", "e.g. time_limit=60"]),
    (["--method", "qp-osqp", "--opt", "eps_abs=tight"], ["eps_abs='tight'", "positive number"]),
    (["--method", "qp-scs", "--opt", "max_iters=2.5"], ["max_iters=2.5", "integer ≥ 0"]),
    (["--method", "qp-clarabel", "--opt", "time_limit=-5"], ["time_limit=-5"]),
    (["--method", "qp-osqp", "--opt", "polishing=maybe"], ["polishing='maybe'", "true or false"]),
    (["--method", "condensed", "--opt", "block=0"], ["block=0", "integer ≥ 1"]),
    (["--method", "nested", "--opt", "zone=all"], ["zone='all'", "Zone"]),
    (["--method", "uzawa", "--opt", "operator=dense"], ["operator='dense'", "delassus"]),
    (["--method", "petsc-vi", "--opt", "ksp=cg"], ["ksp='cg'", "mumps, gamg"]),
    (["--method", "pdas", "--opt", "nonsense=1"], ["'nonsense'", "accepted options", "lam0"]),
])
def test_the_cli_refuses_a_bad_option_in_one_line_before_building_the_scene(capsys, monkeypatch,
                                                                            argv, words):
    import signorini.scenes

    def no_build(*args, **kwargs):  # the option is checked before the scene would be built
        raise AssertionError("the scene was built before the options were checked")

    monkeypatch.setattr(signorini.scenes, "build_problem", no_build)
    code = main(["solve", "block", *argv])
    err = capsys.readouterr().err
    assert code == 2 and len(err.strip().splitlines()) == 1 and "Traceback" not in err, err
    for word in words:
        assert word in err, (word, err)


def test_cli_values_are_read_as_their_declared_kind(capsys):
    # 'none' is acceleration's own choice, not Python's None; 1 is a bool for a switch
    assert main(["solve", "block", "--method", "uzawa-nesterov", "--opt", "acceleration=none"]) == 0
    assert "(delassus operator)" in capsys.readouterr().out
    method = get_method("qp-osqp")
    assert method.parse_options({"polishing": "1", "max_iter": "40", "rho": "0.5"}) == {
        "polishing": True, "max_iter": 40, "rho": 0.5}
    assert get_method("pdas").parse_options({"backend": "none"}) == {"backend": None}
