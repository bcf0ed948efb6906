"""Records as text: short reprs, numbers that may be missing, and tables.

``__repr__ = short_repr`` in a dataclass's body gives ``Name(field=value, …)`` with
numbers to four digits, arrays as their shape and kind, long text cut, mappings as their
keys and any other object as its type: a :class:`~signorini.api.Result` whose arrays hold
10⁵ numbers still reads in one glance.
"""

from __future__ import annotations

import csv
import dataclasses
import io
import math
from typing import Any, Iterable, Mapping, Sequence

import numpy as np

#: text longer than this is cut (with …)
TEXT = 80


def brief(value: Any) -> str:
    """One value in a few characters (see the module's note)."""
    if isinstance(value, (bool, np.bool_, int, np.integer)) or value is None:
        return repr(value)
    if isinstance(value, (float, np.floating)):
        return f"{float(value):.4g}"
    if isinstance(value, str):
        return repr(value if len(value) <= TEXT else value[:TEXT] + "…")
    if isinstance(value, np.ndarray):
        return f"<{value.dtype} array {'×'.join(map(str, value.shape)) or 'scalar'}>"
    if isinstance(value, dict):
        keys = ", ".join(map(str, list(value)[:6])) + (", …" if len(value) > 6 else "")
        return f"{{{keys}}}"
    if isinstance(value, (list, tuple)):
        return f"[{', '.join(map(brief, value))}]" if len(value) <= 4 else f"<{len(value)} items>"
    return f"<{type(value).__name__}>"


def short_repr(record: Any) -> str:
    """``Name(field=value, …)`` over a dataclass's fields shown in its repr, each :func:`brief`."""
    shown = [f"{f.name}={brief(getattr(record, f.name))}"
             for f in dataclasses.fields(record) if f.repr]
    return f"{type(record).__name__}({', '.join(shown)})"


def number(value: Any, spec: str = ".1e") -> str:
    """``value`` formatted by ``spec``; ``–`` when it is missing (None, NaN or infinite)."""
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return "–"
    return format(value, spec)


def _markdown_line(cells: Sequence[Any]) -> str:
    return "| " + " | ".join(str(x).replace("|", "\\|") for x in cells) + " |"


def markdown_table(head: Sequence[str], align: str, rows: Iterable[Sequence[Any]]) -> list[str]:
    """A Markdown table as lines: ``head``, the separator (``align``: ``l`` or ``r`` for each
    column) and one line for each row of cells (a ``|`` in a cell escaped)."""
    rule = "|" + "".join("---:|" if a == "r" else "---|" for a in align)
    return [_markdown_line(head), rule, *map(_markdown_line, rows)]


def plain_table(head: Sequence[str], rows: Sequence[Sequence[str]]) -> list[str]:
    """A plain-text table as lines: columns left-aligned, two spaces apart."""
    widths = [max(len(x) for x in column) for column in zip(head, *rows)]
    return ["  ".join(x.ljust(w) for x, w in zip(line, widths)).rstrip() for line in [head, *rows]]


def csv_text(rows: Iterable[Mapping[str, Any]], columns: Sequence[str]) -> str:
    """``rows`` as CSV: a header of ``columns``, then a line for each row (other keys left out)."""
    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, fieldnames=columns, extrasaction="ignore", lineterminator="\n")
    writer.writeheader()
    writer.writerows(rows)
    return buffer.getvalue()


__all__ = ["brief", "short_repr", "number", "markdown_table", "plain_table", "csv_text"]
