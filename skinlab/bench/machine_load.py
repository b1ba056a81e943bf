"""The machine's load average, reported beside every benchmark's figures (the machine may be shared)."""

from __future__ import annotations

import os


def load_average() -> list[float] | None:
    """The 1, 5 and 15-minute load averages, rounded to 0.01; None where the system has none."""
    try:
        return [round(x, 2) for x in os.getloadavg()]
    except OSError:
        return None
