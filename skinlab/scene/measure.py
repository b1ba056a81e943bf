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
truth_size = "256x16"         # the ledger's truth of this scene at its own size (default: the sweep's)
truth_spp = 256               # and samples per pixel (default: the sweep's)
truth_rr_depth = 1024         # and Russian roulette depth (default 64)
deep_shadow = true            # the ledger measures the deep shadow's level (default false)
mesh_energy = true            # the ledger measures each visible mesh's energy apart (default false)
```

A ``profile = "line"`` scene also gets the ledger's tails: the share of the light in view farther than
2, 5 and 10 mm from the line, of luminance and of each channel alone (skinlab/bench/closeup.py).

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
    truth_size: tuple[int, int] | None = None  # (width, height) of the ledger's truth; None: the sweep's
    truth_spp: int | None = None
    truth_rr_depth: int | None = None
    deep_shadow: bool = False
    mesh_energy: bool = False

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

    @property
    def has_tails(self) -> bool:
        """The ledger measures the light beyond 2, 5 and 10 mm from the line (a line profile)."""
        return self.profile == "line"


# the truth's ranges as skinlab/truth/reference.py ReferenceRequest declares them (scene_keys declares these)
SIZE_LIMIT = 16384  # pixels per side
SPP_RANGE = (2, 1 << 24)
RR_DEPTH_RANGE = (1, 1 << 20)


def parse_size(where: str, value) -> tuple[int, int]:
    """A frame size written "WxH" or [W, H] (integers in [1, SIZE_LIMIT]); ValueError naming `where`."""
    want = f'{where}: expected "WxH" or [W, H], integers in [1, {SIZE_LIMIT}], got {value!r}'
    if isinstance(value, str):
        parts = value.lower().split("x")
        if len(parts) != 2 or not all(p.strip().isdigit() for p in parts):
            raise ValueError(want)
        w, h = (int(p) for p in parts)
    elif isinstance(value, list) and len(value) == 2 and all(type(v) is int for v in value):
        w, h = value
    else:
        raise ValueError(want)
    if not (1 <= w <= SIZE_LIMIT and 1 <= h <= SIZE_LIMIT):
        raise ValueError(want)
    return w, h


def _integer(where: str, value, lo: int, hi: int) -> int:
    if type(value) is not int or not lo <= value <= hi:
        raise ValueError(f"{where}: expected an integer in [{lo}, {hi}], got {value!r}")
    return value


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
    for key in ("deep_shadow", "mesh_energy"):
        if key in table:
            if boolean is None:
                raise ValueError(f"[measure].{key}: no boolean reader given")
            kw[key] = boolean(f"{w}.{key}", table[key])
    if "truth_size" in table:
        kw["truth_size"] = parse_size(f"{w}.truth_size", table["truth_size"])
    for key, (lo, hi) in (("truth_spp", SPP_RANGE), ("truth_rr_depth", RR_DEPTH_RANGE)):
        if key in table:
            kw[key] = _integer(f"{w}.{key}", table[key], lo, hi)
    return MeasureSpec(**kw)
