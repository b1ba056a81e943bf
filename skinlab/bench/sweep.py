"""The ledger's sweep: which settings of which techniques are measured on which scenes (Sweep:
the full, quick and tiny presets; Setting: one row's technique and parameter columns)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from skinlab.resources import scenes_root

from .truth_ledger import REFERENCE_SCENES, TruthSpec, reference_scene_names

ASSETS = scenes_root()
SCENE_ALIASES = {"head": None, "bunny": ASSETS / "bunny-skimmilk.toml"}
REFERENCE_SCENE_NAMES = tuple(reference_scene_names())


@dataclass(frozen=True)
class Sweep:
    name: str
    size: tuple[int, int]
    shadow_size: int
    k_size: int  # irradiance size of the K and tap sweeps
    ks: tuple[int, ...]  # K at k_size
    sizes: tuple[int, ...]  # irradiance sizes at K = max(ks)
    taps: tuple  # tap counts (None = auto) at k_size, K = max(ks)
    ssss: tuple[int, ...]
    exact_size: int  # irradiance size of the exact reference
    frames: int  # timed frames per setting (fewer if over budget_s)
    warmup: int
    budget_s: float  # rough time budget of the timed frames of one setting
    photons: int  # Monte Carlo photons per channel
    peer_frames: int
    scenes: tuple[str, ...] = ("head", "bunny")
    extra: tuple = ()  # extra settings (tiny sweep)
    disk: tuple[int, ...] = ()  # Burley disk SSS sample counts
    every_technique: bool = True  # also a default-settings row for each registered technique not swept above
    # the path-traced truth: reference size and samples (skinlab/bench/truth_ledger.py); None: not measured
    truth: TruthSpec | None = None


FULL = Sweep(
    "full",
    (640, 640),
    2048,
    1024,
    (1, 2, 3, 4, 5, 6),
    (256, 512, 1024, 2048),
    (None, 7, 15, 31),
    (11, 17, 25),
    1024,
    frames=10,
    warmup=2,
    budget_s=25.0,
    photons=200_000,
    peer_frames=30,
    scenes=REFERENCE_SCENE_NAMES,
    disk=(8, 16, 32, 64),
    truth=TruthSpec((192, 192), 1024),
)
QUICK = Sweep(
    "quick",
    (160, 160),
    1024,
    256,
    (1, 3, 6),
    (256, 512),
    (None, 7),
    (11, 25),
    256,  # the exact convolution at 512 texels took half of the quick run; the truth is the first axis now
    frames=5,
    warmup=2,
    budget_s=2.0,
    photons=20_000,
    peer_frames=5,
    scenes=("head-skin1-matched", "bunny-skimmilk", "slab-edge-skin1"),
    disk=(8, 32),
    truth=TruthSpec((96, 96), 256),
)
# for the tests: five settings on the index-matched head at 64x64, a 32x32 truth
TINY = Sweep(
    "tiny",
    (64, 64),
    256,
    256,
    (1, 6),
    (256,),
    (None,),
    (),
    256,
    frames=2,
    warmup=2,
    budget_s=0.5,
    photons=4_000,
    peer_frames=1,
    scenes=("head-skin1-matched",),
    truth=TruthSpec((32, 32), 16, passes=2),
    every_technique=False,
)
SWEEPS = {"full": FULL, "quick": QUICK, "tiny": TINY}


@dataclass(frozen=True)
class Setting:
    """One ledger row's setting: a registered technique and the ledger columns its settings fill
    (the technique's LedgerStyle.columns maps them to its settings fields)."""

    technique: str  # a registered technique: none | tint | tsd | ssss | exact | ...
    K: int | None = None
    tsd_size: int | None = None
    taps: int | None = None  # tsd taps; None = auto (only meaningful for tsd)
    ssss_taps: int | None = None
    disk_samples: int | None = None

    def _style(self):
        from skinlab.render.registry import get_technique

        return get_technique(self.technique).ledger

    @property
    def label(self) -> str:
        style = self._style()
        if not style.label:
            return self.technique
        return style.label.format(**{c: ("auto" if v is None else v) for c, v in self._columns().items()})

    def _columns(self) -> dict:
        return {c: getattr(self, c) for c in self._style().columns}

    def render_settings(self, sweep: Sweep, size=None, supersample: int = 1):
        """The setting's render settings at the sweep's size (the timed frames) or at `size` with
        `supersample` (the frames compared with the truth)."""
        from skinlab.render.settings import RenderSettings

        w, h = size or sweep.size
        cols = self._style().columns
        opts = {f: getattr(self, c) for c, f in cols.items() if getattr(self, c) is not None}
        return RenderSettings.for_technique(
            self.technique, w, h, shadow_size=sweep.shadow_size, supersample=supersample, **opts
        )

    def cells(self) -> dict:
        """The parameter columns; empty where the parameter does not apply to the technique."""
        own = self._columns()
        return {c: ("auto" if own[c] is None else own[c]) if c in own else "" for c in SETTING_COLUMNS}


SETTING_COLUMNS = ("K", "tsd_size", "taps", "ssss_taps", "disk_samples")


def sweep_settings(sweep: Sweep) -> list[Setting]:
    """The reference first, then the rest, without duplicates (in order)."""
    kmax = max(sweep.ks)
    out = [Setting("exact", tsd_size=sweep.exact_size), Setting("none"), Setting("tint")]
    out += [Setting("tsd", K=k, tsd_size=sweep.k_size) for k in sweep.ks]
    out += [Setting("tsd", K=kmax, tsd_size=s) for s in sweep.sizes]
    out += [Setting("tsd", K=kmax, tsd_size=sweep.k_size, taps=t) for t in sweep.taps]
    out += [Setting("ssss", ssss_taps=n) for n in sweep.ssss]
    out += [Setting("disk", disk_samples=n) for n in sweep.disk]
    # the exact convolution at the smaller swept sizes: the irradiance texture's own resolution error
    out += [Setting("exact", tsd_size=s) for s in sweep.sizes if s < sweep.exact_size]
    out += list(sweep.extra)
    if sweep.every_technique:  # a newly registered technique is measured without editing the sweep
        from skinlab.render.registry import technique_names

        out += [Setting(name) for name in technique_names() if name not in {s.technique for s in out}]
    seen, uniq = set(), []
    for s in out:
        if s not in seen:
            seen.add(s)
            uniq.append(s)
    return uniq


def sheet_settings(settings: list[Setting]) -> list[Setting]:
    """One setting per technique for the error-map contact sheet: the one with the technique's default
    settings where it was swept, else the technique's first (for exact: the reference size)."""
    from skinlab.render.registry import get_technique

    out = []
    for tech in dict.fromkeys(s.technique for s in settings):
        t = get_technique(tech)
        defaults = t.settings_type()
        cols = t.ledger.columns
        default = Setting(tech, **{c: getattr(defaults, f) for c, f in cols.items()})
        cands = [s for s in settings if s.technique == tech]
        out.append(default if default in cands and tech != "exact" else cands[0])
    return out


def proxy_reference(settings: list[Setting]) -> Setting | None:
    """The most accurate tsd setting: largest irradiance texture, then largest K, auto taps first."""
    tsd = [s for s in settings if s.technique == "tsd"]
    if not tsd:
        return None
    return max(tsd, key=lambda s: (s.tsd_size, s.K, s.taps is None, s.taps or 0))


def resolve_scene(name: str):
    """'head', 'bunny' (skim milk), 'bunny-marble'... (skinlab/assets/scenes/NAME.toml) or a path to a scene file."""
    if name in SCENE_ALIASES:
        return SCENE_ALIASES[name]
    for folder in (REFERENCE_SCENES, ASSETS):
        p = folder / f"{name}.toml"
        if p.is_file():
            return p
    p = Path(name)
    if p.suffix == ".toml" and p.is_file():
        return p
    known = ", ".join([*SCENE_ALIASES, *sorted(x.stem for x in ASSETS.glob("*.toml")), *REFERENCE_SCENE_NAMES])
    raise ValueError(f"--scenes: unknown scene {name!r}; expected one of {known} or a .toml path")


def scene_label(name: str) -> str:
    return Path(name).stem if name.endswith(".toml") else name
