"""The project's one way to write an output file: to a temporary name beside the target, then
renamed into place, so a crash or an error never leaves a half-written file (GUIDE: nothing
half-written). Images (skinlab/image_output.py), the ledger's tables and figures, the demo's index and
the Monte Carlo cache all go through here."""

from __future__ import annotations

import errno
import os
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path


@contextmanager
def atomic_path(path: str | Path) -> Iterator[Path]:
    """A temporary path beside `path` (same suffix) to write to; on leaving the block it is renamed to
    `path` with ordinary permissions, or removed if the block raised."""
    path = Path(path)
    check_writable(path)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        # the temporary name is short whatever the target's (a 250-character name must not fail as ".name.XXXX")
        fd, tmp = tempfile.mkstemp(prefix=f".{path.stem[:40]}.", suffix=path.suffix[:16], dir=path.parent)
    except OSError as exc:  # the message names the user's path, never the temporary one
        raise OSError(exc.errno, f"cannot write here: {exc.strerror or exc}", str(path)) from None
    os.close(fd)
    try:
        yield Path(tmp)
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)  # mkstemp makes 0600 files; outputs get ordinary permissions
        try:
            os.replace(tmp, path)
        except OSError as exc:
            raise OSError(exc.errno, f"cannot write here: {exc.strerror or exc}", str(path)) from None
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def check_writable(path: Path) -> None:
    """Fail before any work, naming ``path``, where it cannot become a file: a name longer than the
    file system takes, a parent that is a dangling symbolic link or a file. OSError with the path as
    its filename (the CLI prints "PATH: reason")."""
    longest = 255
    for parent in path.parents:
        if parent.is_symlink() and not parent.exists():
            raise OSError(
                errno.ENOENT,
                f"folder {parent} is a symbolic link to {os.readlink(parent)}, which does not exist",
                str(path),
            )
        if parent.exists():
            try:
                longest = os.pathconf(parent, "PC_NAME_MAX")
            except (OSError, ValueError):
                pass
            break
    for part in path.parts:
        if len(os.fsencode(part)) > longest:
            raise OSError(
                errno.ENAMETOOLONG,
                f"the name {part[:24]}... is {len(os.fsencode(part))} bytes long; at most {longest}",
                str(path),
            )


def write_bytes_atomic(path: str | Path, data: bytes) -> Path:
    with atomic_path(path) as tmp:
        tmp.write_bytes(data)
    return Path(path)


def write_text_atomic(path: str | Path, text: str) -> Path:
    return write_bytes_atomic(path, text.encode("utf-8"))
