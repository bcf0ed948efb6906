"""Short reprs: a result, its solution, certificate and derivatives print as a line or a few,
whatever the size of their arrays (status, sizes, key numbers)."""

from __future__ import annotations

import numpy as np
import pytest

import signorini
from signorini.reprs import brief


@pytest.fixture(scope="module")
def result():
    found = signorini.solve("hertz-cylinder", "pdas")
    assert found.converged and found.problem.n > 1000
    return found


def test_a_result_is_one_line_with_its_status_and_sizes(result):
    text = repr(result)
    assert "\n" not in text and len(text) <= 160, text
    for word in ("'pdas'", "converged", f"{result.problem.n} dofs", f"{result.problem.m} candidates"):
        assert word in text, text


def test_records_of_arrays_show_shapes_not_values(result):
    derivative = signorini.derivative(result, "pressure", "E")
    records = [result.solution, result.certificate, derivative, result.jvp(), result.vjp()]
    for record in records:
        text = repr(record)
        assert len(text) <= 500 and text.count("\n") <= 2, (type(record).__name__, len(text))
    assert f"u=<float64 array {result.problem.n}>" in repr(result.solution)
    assert f"derivative=<float64 array {result.problem.m}>" in repr(derivative)


@pytest.mark.parametrize("value, shown", [(np.zeros((3, 2)), "<float64 array 3×2>"),
                                          (1.23456789, "1.235"), ("x" * 200, "…"),
                                          ({"a": 1, "b": 2}, "{a, b}"), (list(range(9)), "<9 items>")])
def test_brief_shows_a_value_in_a_few_characters(value, shown):
    assert shown in brief(value) and len(brief(value)) <= 90
