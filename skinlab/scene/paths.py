"""Input files named by a scene: a path that is a regular file, or one clear error naming it (not
found, a folder, a symbolic link loop), before any reader sees it."""

from __future__ import annotations

import errno
import os
import stat
from pathlib import Path


def absolute(path: Path) -> Path:
    """``path.resolve()`` where the links resolve; the plain absolute path where they loop (the file
    check then says so)."""
    try:
        return path.resolve()
    except (RuntimeError, OSError):  # Python 3.11 raises RuntimeError("Symlink loop ..."), 3.13 OSError
        return Path(os.path.abspath(path))


def existing_file(path: str | Path, what: str) -> Path:
    """``path`` if it names a regular file; FileNotFoundError "<what> not found: PATH" if nothing is
    there, ValueError for a folder or a symbolic link loop."""
    path = Path(path)
    try:
        mode = path.stat().st_mode
    except OSError as exc:
        if exc.errno == errno.ELOOP:
            raise ValueError(f"{what} {path}: is a symbolic link loop (it links back to itself)") from None
        raise FileNotFoundError(f"{what} not found: {path}") from None
    if stat.S_ISDIR(mode):
        raise ValueError(f"{what} {path}: is a folder, expected a file")
    if not stat.S_ISREG(mode):
        raise ValueError(f"{what} {path}: is not a regular file")
    return path
