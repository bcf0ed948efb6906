"""Result files written whole or not at all, and every output checked before any work.

Where an output goes decides how it is written:

- a new path or a regular file: a temporary file in the same folder, renamed
  onto it (readers see the old file or the new one, never half of one);
- a symbolic link: followed, its target replaced that way, the link kept;
- a device, a FIFO or a socket (``/dev/null``, a named pipe): opened and
  written through, never replaced;
- this process's own standard output (``/dev/stdout``, ``/proc/self/fd/1``):
  the same as ``-``.

Within :func:`all_or_none` the outputs are produced under temporary names and
take their places only when the whole block succeeded; otherwise none does.
Every output path is checked before any work by :mod:`signorini.paths` (whose names this module
also exports).
"""

from __future__ import annotations

import contextlib
import json
import math
import os
import sys
import tempfile
from pathlib import Path
from typing import Any, Callable, Iterator

import numpy as np

from signorini.errors import InputError, OutputError
from signorini.paths import (STDOUT, check_input_file, check_output_file, check_output_folder,
                             check_outputs, where)

__all__ = ["PARTIAL", "STDOUT", "all_or_none", "atomic_write", "atomic_write_bytes",
           "atomic_write_text", "check_input_file", "check_output_file", "check_output_folder",
           "check_outputs", "plain", "remove_empty_folders", "remove_partial_files", "save_figure",
           "to_json", "write_stdout", "writable_directory"]

#: outputs produced inside :func:`all_or_none`, waiting to take their places
_staged: list[tuple[str | None, Path | int, bytes | None]] | None = None
#: folders :func:`writable_directory` created (removed again while still empty)
_created: list[Path] = []
#: the mark of a file being written under a temporary name (:func:`atomic_write`), and the
#: folders written into, by this process or by its workers below them (:func:`remove_partial_files`)
PARTIAL, _written = ".signorini-partial.", set[Path]()


def writable_directory(path: str | os.PathLike) -> Path:
    """Create ``path`` if needed; InputError when it cannot be a writable directory.

    Folders created here are removed again by :func:`remove_empty_folders`
    while nothing was written into them.
    """
    directory = Path(path)
    if str(path) == "":
        raise InputError(f"--out {str(path)!r} is empty: give a folder, e.g. --out report")
    missing = [p for p in (directory, *directory.parents) if not p.exists()]
    try:
        directory.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise InputError(f"--out {str(directory)!r} cannot be created ({exc.strerror}): "
                         "choose a writable directory") from None
    _created.extend(reversed(missing))
    _written.add(directory.absolute())
    if not os.access(directory, os.W_OK):
        raise InputError(f"--out {str(directory)!r} is not writable: choose a writable directory")
    return directory


def remove_partial_files() -> None:
    """Remove the temporary files of writes that never finished (a worker killed while writing,
    a signal between two steps) from the folders written into and their subfolders."""
    for leftover in [p for f in _written for p in (*f.glob(f"*{PARTIAL}*"), *f.glob(f"*/*{PARTIAL}*"))]:
        leftover.unlink(missing_ok=True)


def remove_empty_folders() -> None:
    """Remove the folders :func:`writable_directory` created that are still empty, deepest first."""
    while _created:
        with contextlib.suppress(OSError):
            _created.pop().rmdir()


@contextlib.contextmanager
def all_or_none() -> Iterator[None]:
    """Outputs written inside the block take their places only when it ends without an error."""
    global _staged
    outer, _staged = _staged, []
    staged = _staged
    try:
        yield
    except BaseException:
        _discard(staged)
        raise
    finally:
        _staged = outer
    _place_or_stage(staged)  # into the enclosing block's outputs, or in their places


def _discard(staged: list) -> None:
    for tmp, _, _ in staged:
        if tmp is not None:
            Path(tmp).unlink(missing_ok=True)


def _place(staged: list) -> None:
    """Write through first (the writes that can fail), then rename every file into place;
    OutputError, nothing written, when two of them would land on one file."""
    try:
        targets = [str(target) for tmp, target, _ in staged if tmp is not None]
        for twice in {t for t in targets if targets.count(t) > 1}:
            raise OutputError(f"two outputs of the command are the same file {twice!r}: "
                              "nothing was written; give them different paths")
        for tmp, target, data in staged:
            if tmp is None:
                _write_through(target, data)
        for tmp, target, _ in staged:
            if tmp is not None:
                os.replace(tmp, target)
    except BaseException:
        _discard(staged)
        raise


def _write_through(target: Path | int, data: bytes) -> None:
    try:
        if isinstance(target, int):  # through sys.stdout: what is buffered there stays in order
            stream = sys.stdout if target == 1 else sys.stderr
            binary = getattr(stream, "buffer", None)
            stream.flush()
            if binary is not None:
                binary.write(data)
            else:
                stream.write(data.decode("utf-8"))
            stream.flush()
        else:
            with open(target, "wb") as handle:
                handle.write(data)
    except BrokenPipeError:  # the command says so (signorini.cli.app)
        raise
    except OSError as exc:
        where = {1: "standard output", 2: "standard error"}.get(target, repr(str(target)))
        raise OutputError(f"cannot write {where} ({exc.strerror}): free some space or "
                          "choose another path") from None


def atomic_write(path: str | os.PathLike, produce: Callable[[str], None], suffix: str = "") -> None:
    """``produce(name)`` writes a file; it then takes the place of ``path`` whole, or nothing does.

    OutputError (nothing left behind) when the file cannot be produced, e.g.
    on a full disk.
    """
    kind, target = where(path)
    if kind == "folder":
        raise InputError(f"cannot write {str(path)!r}: it is a directory; give a file name")
    folder = target.parent if kind == "replace" else None
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{Path(path).name}{PARTIAL}", suffix=suffix, dir=folder)
        _written.add(Path(tmp).parent)
    except OSError as exc:  # no such folder, or one that takes no files: the path is at fault
        raise InputError(f"cannot write {str(path)!r} ({exc.strerror}): choose a writable path") \
            from None
    os.close(fd)
    try:
        produce(tmp)
        if kind != "replace":  # a device, a FIFO or stdout: written through, never replaced
            data = Path(tmp).read_bytes()
            Path(tmp).unlink()
            tmp = None
        else:
            data = None
            mode = target.stat().st_mode & 0o7777 if target.exists() else 0o666 & ~_umask()
            os.chmod(tmp, mode)  # mkstemp's 0600 would hide results from other users
    except OSError as exc:
        Path(tmp).unlink(missing_ok=True)
        raise OutputError(f"cannot write {str(path)!r} ({exc.strerror}): nothing was left "
                          "behind; free some space or choose another path") from None
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    _place_or_stage([(tmp, target, data)])


def _place_or_stage(items: list) -> None:
    if _staged is not None:
        _staged.extend(items)
    else:
        _place(items)


def write_stdout(text: str) -> None:
    """``text`` on standard output (inside :func:`all_or_none`: once every output was produced)."""
    _place_or_stage([(None, 1, text.encode("utf-8"))])


def atomic_write_bytes(path: str | os.PathLike, data: bytes) -> None:
    """Write ``data`` to ``path`` so that readers see the old file or the new one, never half."""
    atomic_write(path, lambda name: Path(name).write_bytes(data))


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def atomic_write_text(path: str | os.PathLike, text: str) -> None:
    atomic_write_bytes(path, text.encode("utf-8"))


def plain(value: Any) -> Any:
    """JSON-safe copy: arrays to lists, non-finite floats to null."""
    if isinstance(value, dict):
        return {str(k): plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [plain(v) for v in value]
    if isinstance(value, np.ndarray):
        return plain(value.tolist())
    if isinstance(value, (np.bool_, bool)):
        return bool(value)
    if isinstance(value, (np.integer,)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        return float(value) if math.isfinite(value) else None
    return value


def to_json(data: Any) -> str:
    return json.dumps(plain(data), indent=2, allow_nan=False)


def save_figure(figure, path: str | os.PathLike, dpi: int = 130) -> None:
    """Save a matplotlib figure atomically as PNG."""
    import io as _io

    buffer = _io.BytesIO()
    figure.savefig(buffer, format="png", dpi=dpi)
    atomic_write_bytes(path, buffer.getvalue())
