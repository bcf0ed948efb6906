"""The explorer's HTML pieces: a figure as an image, numbers and a certificate as tables.

Every number is in an element with an ``id`` (``<prefix>-<name>``), written with
:data:`NUMBER_FORMAT`, so that a browser test can read it back and compare it with the
library's answer.
"""

from __future__ import annotations

import base64
import html
import io

from matplotlib.figure import Figure

from signorini.api import Result
from signorini.output.lessons import RaceRow

__all__ = ["NUMBER_FORMAT", "certificate_table", "figure_image", "number", "numbers_table", "race_table"]

#: how a number is written in the page
NUMBER_FORMAT = ".6g"


def number(value: object) -> str:
    """A number as the page writes it (text as it is)."""
    return format(value, NUMBER_FORMAT) if isinstance(value, (int, float)) else str(value)


def figure_image(fig: Figure, element_id: str, alt: str) -> str:
    """``fig`` as an inline PNG ``<img>`` with ``id=element_id``."""
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=80)
    data = base64.b64encode(buffer.getvalue()).decode("ascii")
    return (f'<img id="{element_id}" alt="{html.escape(alt)}" '
            f'src="data:image/png;base64,{data}" style="max-width:100%;height:auto">')


def numbers_table(prefix: str, rows: dict[str, tuple[str, object]]) -> str:
    """A two-column table: ``{name: (label, value)}``, each value in ``<td id=prefix-name>``."""
    body = "".join(f'<tr><th style="text-align:left">{html.escape(label)}</th>'
                   f'<td id="{prefix}-{name}" style="padding-left:1em">'
                   f"{html.escape(number(value))}</td></tr>"
                   for name, (label, value) in rows.items())
    return f'<table class="numbers" style="width:auto">{body}</table>'


def certificate_table(prefix: str, result: Result) -> str:
    """The status and every KKT residual of ``result``'s certificate."""
    rows = {"status": ("status (certificate)", result.status),
            "iterations": ("iterations", result.iterations)}
    rows.update({f"kkt-{name}": (name, value)
                 for name, value in result.certificate.residuals().items()})
    return numbers_table(prefix, rows)


def race_table(rows: list[RaceRow]) -> str:
    """One row per method: status, iterations, wall time and the worst KKT residual
    (``race-<method>-status``, ``race-<method>-iterations``)."""
    body = "".join(f'<tr id="race-{row.method}"><td>{row.method}</td>'
                   f'<td id="race-{row.method}-status">{row.status}</td>'
                   f'<td id="race-{row.method}-iterations">{row.iterations}</td>'
                   f"<td>{row.seconds:.3f}</td><td>{row.worst[0]} {row.worst[1]:.1e}</td></tr>"
                   for row in rows)
    return ('<table id="race-table"><tr><th>method</th><th>status</th><th>iterations</th>'
            f"<th>time [s]</th><th>worst KKT residual</th></tr>{body}</table>")
