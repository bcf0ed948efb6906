"""Writing result files whole or not at all: write a temporary file, then rename it."""

from __future__ import annotations

import json
import math
import os
import tempfile
from pathlib import Path
from typing import Any

import numpy as np

from signorini.errors import InputError


def writable_directory(path: str | os.PathLike) -> Path:
    """Create ``path`` if needed; InputError when it cannot be a writable directory."""
    directory = Path(path)
    try:
        directory.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise InputError(f"--out {str(directory)!r} cannot be created ({exc.strerror}): "
                         "choose a writable directory") from None
    if not os.access(directory, os.W_OK):
        raise InputError(f"--out {str(directory)!r} is not writable: choose a writable directory")
    return directory


def check_output_file(path: str | os.PathLike, flag: str) -> Path:
    """InputError unless a file can be written at ``path`` (checked before any work).

    The folder must exist and be writable, the path must not be a folder, and
    the name must fit the file system's limit.
    """
    target = Path(path)
    parent = target.parent if str(target.parent) else Path(".")
    if not parent.is_dir():
        raise InputError(f"{flag} {str(target)!r}: the folder {str(parent)!r} does not exist: "
                         "create it or choose another path")
    try:
        longest = os.pathconf(parent, "PC_NAME_MAX")
    except (OSError, ValueError):
        longest = 255
    if len(os.fsencode(target.name)) > longest:
        raise InputError(f"{flag}: the file name is {len(os.fsencode(target.name))} bytes long, "
                         f"over this file system's {longest}: choose a shorter name")
    if target.is_dir():
        raise InputError(f"{flag} {str(target)!r} is a directory: give a file name, "
                         f"e.g. {flag} {target / 'result.json'}")
    if not os.access(parent, os.W_OK) or (target.exists() and not os.access(target, os.W_OK)):
        raise InputError(f"{flag} {str(target)!r} is not writable: choose a writable path")
    return target


def atomic_write_bytes(path: str | os.PathLike, data: bytes) -> None:
    """Write ``data`` to ``path`` so that readers see the old file or the new one, never half."""
    target = Path(path)
    if target.is_dir():
        raise InputError(f"cannot write {str(target)!r}: it is a directory; give a file name")
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", dir=target.parent or ".")
    except OSError as exc:
        raise InputError(f"cannot write {str(target)!r} ({exc.strerror}): choose a writable path") from None
    try:
        with os.fdopen(fd, "wb") as handle:
            handle.write(data)
        os.chmod(tmp, 0o666 & ~_umask())  # mkstemp's 0600 would hide results from other users
        os.replace(tmp, target)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


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
