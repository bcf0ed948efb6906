"""Records as text. Short reprs: a result, its solution, certificate and derivatives print as
a line or a few, whatever the size of their arrays (status, sizes, key numbers); a missing number
is a dash; tables in Markdown, plain text and CSV."""

from __future__ import annotations

import numpy as np
import pytest

import signorini
from signorini.reprs import brief, csv_text, markdown_table, number, plain_table


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


@pytest.mark.parametrize("value, shown", [(None, "–"), (float("nan"), "–"), (float("inf"), "–"),
                                          (1.5e-3, "1.5e-03"), (7, "7.0e+00")])
def test_a_missing_number_is_a_dash(value, shown):
    assert number(value) == shown


def test_a_markdown_table_aligns_its_columns_and_escapes_a_bar():
    lines = markdown_table(["name", "value"], "lr", [["a|b", 1.5], ["c", "–"]])
    assert lines == ["| name | value |", "|---|---:|", "| a\\|b | 1.5 |", "| c | – |"]


def test_a_plain_table_pads_each_column_to_its_widest_cell():
    assert plain_table(["a", "bb"], [["ccc", "d"]]) == ["a    bb", "ccc  d"]


def test_csv_text_writes_the_columns_named_in_their_order():
    text = csv_text([{"b": 2, "a": "x, y", "c": 3}], ["a", "b"])
    assert text == 'a,b\n"x, y",2\n'
