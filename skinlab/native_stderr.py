"""C libraries that print on the process's stderr themselves (libpng's "libpng error: IDAT: Read
error", libjpeg's "Premature end of JPEG file"): their lines bypass Python and land around Skinlab's
one-line error. :func:`silenced` points file descriptor 2 elsewhere for the duration of a call into
such a library; what the library says is returned for the caller's message instead."""

from __future__ import annotations

import os
import sys
import tempfile
import threading
from collections.abc import Iterator
from contextlib import contextmanager

_LOCK = threading.Lock()  # one redirection at a time (texture loads run on worker threads too)


@contextmanager
def silenced() -> Iterator[list[str]]:
    """Inside the block, native writes to stderr go to a temporary file; afterwards the list yielded
    holds their lines (empty if the library said nothing). Python's own sys.stderr is untouched."""
    lines: list[str] = []
    with _LOCK, tempfile.TemporaryFile() as tmp:
        try:
            sys.stderr.flush()
        except (OSError, ValueError):
            pass
        saved = os.dup(2)
        os.dup2(tmp.fileno(), 2)
        try:
            yield lines
        finally:
            os.dup2(saved, 2)
            os.close(saved)
            tmp.seek(0)
            lines.extend(line for line in tmp.read().decode("utf-8", "replace").splitlines() if line.strip())
