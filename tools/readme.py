"""Write the README's generated blocks from the committed artefacts they quote.

    .venv/bin/python tools/readme.py          # after `signorini validate --out docs/validation`

Each block sits between ``<!-- generated: NAME -->`` and ``<!-- end generated -->``;
``tests/test_readme_numbers.py`` fails when a block differs from what this writes.
"""

from __future__ import annotations

import json
import re
import sys
from pathlib import Path

from signorini.files import atomic_write_text
from signorini.output.report import readme_validation

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"


def blocks() -> dict[str, str]:
    report = json.loads((ROOT / "docs" / "validation" / "report.json").read_text())
    return {"validation": readme_validation(report)}


def pattern(name: str) -> re.Pattern:
    return re.compile(rf"(<!-- generated: {name} -->\n)(.*?)(\n<!-- end generated -->)", re.S)


def current(text: str, name: str) -> str | None:
    match = pattern(name).search(text)
    return match.group(2) if match else None


def main() -> int:
    text = README.read_text(encoding="utf-8")
    for name, body in blocks().items():
        if current(text, name) is None:
            print(f"README.md has no block '{name}'", file=sys.stderr)
            return 1
        text = pattern(name).sub(lambda m: m.group(1) + body + m.group(3), text)
    atomic_write_text(README, text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
