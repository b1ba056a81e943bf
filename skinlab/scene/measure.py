"""What a scene tests, as its file's ``[measure]`` table declares it (docs/scenes.md; the ledger reads it,
docs/ledger.md "Edges and profiles").

```toml
[measure]
tests = "the line spread function of skin1 on a flat slab"   # shown in the ledger
profile = "line"              # "line": a slit or stripe of light (line spread function);
                              # "edge": a shadow or light edge (edge spread function); "none"
profile_origin = [0, 20, 0]   # a point on the slit's centre line / on the edge, scene units
profile_axis = [0, 1, 0]      # the direction ACROSS the slit / edge: the profile's coordinate
profile_range_mm = 30         # the profile spans +-30 mm across (default 30)
profile_band_mm = 40          # average only pixels within 40 mm of the origin along the slit (default: all)
line_width_mm = 2             # a line's (slit's) width, for its edge region (default 0)
edge_mm = 10                  # the edge region: within 10 mm of the edge (a line: of its sides)
                              # (default: 3 diffusion lengths of the scene's most diffuse material)
ledger = false                # left out of the ledger's default scene list (default true)
```

With no profile the edge region comes from the plain frame's light: pixels within ``edge_mm`` of
where its luminance changes by more than a factor of 2 between neighbouring pixels (shadow and light
edges; skinlab/truth/regions.py).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

PROFILES = ("none", "line", "edge")


@dataclass(frozen=True)
class MeasureSpec:
    tests: str = ""
    profile: str = "none"
    profile_origin: tuple[float, float, float] | None = None  # scene units
    profile_axis: tuple[float, float, float] | None = None  # unit vector across the line / edge
    profile_range_mm: float = 30.0
    profile_band_mm: float | None = None
    line_width_mm: float = 0.0
    edge_mm: float | None = None
    ledger: bool = True  # in the ledger's default scene list (skinlab/bench/truth_ledger.py reference_scene_names)

    def __post_init__(self) -> None:
        if self.profile not in PROFILES:
            raise ValueError(f"[measure].profile: expected one of {', '.join(PROFILES)}, got {self.profile!r}")
        if self.profile != "none":
            for name in ("profile_origin", "profile_axis"):
                if getattr(self, name) is None:
                    raise ValueError(f"[measure].{name}: needed for profile = {self.profile!r}")
            a = np.asarray(self.profile_axis, np.float64)
            n = float(np.linalg.norm(a))
            if not n > 0:
                raise ValueError("[measure].profile_axis: must be non-zero")
            object.__setattr__(self, "profile_axis", tuple(float(x) for x in a / n))

    @property
    def has_profile(self) -> bool:
        return self.profile != "none"


def parse_measure(table: dict, num, vec, string, boolean=None) -> MeasureSpec:
    """A MeasureSpec from a scene file's [measure] table, with the scene file's typed readers
    (num(where, value, lo, hi, lo_open), vec(where, value), string(where, value), boolean(where, value))."""
    w = "[measure]"
    kw: dict = {}
    if "tests" in table:
        kw["tests"] = string(f"{w}.tests", table["tests"])
    if "profile" in table:
        kw["profile"] = string(f"{w}.profile", table["profile"])
    for key in ("profile_origin", "profile_axis"):
        if key in table:
            kw[key] = tuple(float(x) for x in vec(f"{w}.{key}", table[key]))
    for key in ("profile_range_mm", "profile_band_mm"):
        if key in table:
            kw[key] = num(f"{w}.{key}", table[key], 0.0, None, True)
    for key in ("line_width_mm", "edge_mm"):
        if key in table:
            kw[key] = num(f"{w}.{key}", table[key], 0.0, None, False)
    if "ledger" in table:
        if boolean is None:
            raise ValueError("[measure].ledger: no boolean reader given")
        kw["ledger"] = boolean(f"{w}.ledger", table["ledger"])
    return MeasureSpec(**kw)
