"""Figures with many series tell every series apart, and show the data they were given.

Issue 13 §4: in the validation report's accuracy-against-time figure `qp-osqp@default` and
`condensed` shared a colour (ten colours, one marker), so an exact method looked wrong.
"""

from __future__ import annotations

import numpy as np
from matplotlib.colors import to_rgba

from signorini.output import plots
from signorini.studies.atlas import figures

METHODS = [f"method-{i}" for i in range(19)]


def styles(lines) -> list[tuple[tuple[float, ...], str]]:
    return [(to_rgba(line.get_color()), line.get_marker()) for line in lines]


def test_the_first_110_series_differ_in_colour_and_marker():
    pairs = [plots.series_style(i) for i in range(110)]
    assert len(set(pairs)) == 110
    assert plots.series_style(0) != plots.series_style(10)


def test_accuracy_against_time_tells_19_runs_apart_and_fills_the_converged_ones():
    rows = [{"label": name, "status": "converged" if i % 2 else "inaccurate",
             "time_s": 0.01 * (i + 1), "kkt_worst": 10.0 ** -(i % 12)} for i, name in enumerate(METHODS)]
    ax = plots.kkt_against_time(rows)
    lines = ax.get_lines()
    assert [line.get_label() for line in lines] == [f"{r['label']} ({r['status']})" for r in rows]
    assert len(set(styles(lines))) == len(rows)
    for line, row in zip(lines, rows):
        assert line.get_xdata()[0] == row["time_s"] and line.get_ydata()[0] == row["kkt_worst"]
        assert (line.get_markerfacecolor() == "none") == (row["status"] != "converged")
    legend = ax.get_legend()
    assert [t.get_text() for t in legend.get_texts()] == [line.get_label() for line in lines]


def test_pressure_profile_tells_15_methods_apart():
    x = np.linspace(0.0, 1.0, 9)
    others = [(f"m{i}", np.sqrt(np.clip(1 - x ** 2, 0, None)) * (1 + 0.01 * i)) for i in range(15)]
    ax = plots.pressure_profile(x, np.sqrt(1 - x ** 2), a_ref=1.0, p0_ref=1.0, others=others)
    series = [line for line in ax.get_lines() if line.get_label() != "Hertz"]
    assert [line.get_label() for line in series] == ["numeric"] + [name for name, _ in others]
    assert len(set(styles(series))) == 16
    np.testing.assert_allclose(series[-1].get_ydata(), others[-1][1])


def test_atlas_series_tells_20_methods_apart():
    rows = [{"method": f"m{i}", "dofs": d, "time_s": 0.1 * (i + 1) * d / 100, "outcome": "right",
             "claim_correct": True} for i in range(20) for d in (100, 400)]
    ax = figures.atlas_series(rows, "dofs", "time_s")
    joined = [line for line in ax.get_lines() if line.get_linestyle() == "-"]
    assert [line.get_label() for line in joined] == [f"m{i}" for i in range(20)]
    markers = [line for line in ax.get_lines() if line.get_linestyle() == "None"]
    pairs = {(to_rgba(m.get_color()), m.get_marker()) for m in markers}
    assert len(pairs) == 20  # one colour-and-marker per method, both its points alike


def test_bench_speed_accuracy_gives_each_method_and_tolerance_its_own_style():
    rows = [{"method": f"m{i:02d}", "tolerance": tol, "time_s": 0.1 * (i + 1), "kkt_worst": 1e-6,
             "status": "converged"} for i in range(13) for tol in ("low", "high")]
    ax = plots.bench_speed_accuracy(rows)
    lines = ax.get_lines()
    assert len(lines) == 26 and len(set(styles(lines))) == 26
