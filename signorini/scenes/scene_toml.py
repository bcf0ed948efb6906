"""A scene file's TOML, read with errors that name the file, the table, the key and the line."""

from __future__ import annotations

import re
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from signorini.errors import InputError
from signorini.paths import check_input_file

__all__ = ["SceneFileContext", "read_scene_file"]


class Locator:
    """Finds the line of ``key`` inside ``[table]`` (or the k-th ``[[table]]``) of a TOML text."""

    _HEADER = re.compile(r"^\s*(\[\[?)\s*([A-Za-z0-9_.\-\"' ]+?)\s*\]\]?\s*(#.*)?$")

    def __init__(self, text: str):
        self.lines = text.splitlines()

    def line(self, table: str | None, key: str | None = None, index: int = 0) -> int | None:
        current, seen = None, -1
        for number, line in enumerate(self.lines, start=1):
            header = self._HEADER.match(line)
            if header:
                current = header.group(2).strip().strip("\"'")
                if current == table:
                    seen += 1
                    if key is None and seen == index:
                        return number
                continue
            if key is not None and current == table and seen == index and \
                    re.match(rf"^\s*[\"']?{re.escape(key)}[\"']?\s*=", line):
                return number
        return None


@dataclass
class SceneFileContext:
    """Where an error happened: the file and its text."""

    path: Path
    locate: Locator

    def error(self, message: str, table: str | None, key: str | None = None,
              index: int = 0) -> InputError:
        where = f"[{table}] {key}" if table and key else (f"[{table}]" if table else key or "")
        line = self.locate.line(table, key, index)
        at = f", line {line}" if line else ""
        return InputError(f"scene file {self.path}{at}: {where}: {message}".replace(": : ", ": "))


def read_scene_file(path: str | Path) -> tuple[dict[str, Any], SceneFileContext]:
    """The parsed TOML of a scene file; InputError with the line on a syntax error."""
    if sys.version_info >= (3, 11):  # on use: only a scene file needs a TOML parser
        import tomllib
    else:  # pragma: no cover - exercised on Python 3.10 only
        import tomli as tomllib

    path = Path(path)
    check_input_file(str(path), "scene file", "give the path to a .toml file (examples: the sdist's "
                     "examples/; a built-in scene runs by name: signorini scenes)")
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"scene file {path} cannot be read ({exc})") from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"scene file {path}: invalid TOML: {exc}") from None
    except RecursionError:  # tomllib parses nested arrays and tables by recursion
        raise InputError(f"scene file {path}: arrays or tables nested too deeply to read") from None
    return data, SceneFileContext(path, Locator(text))
