"""The ledger's sweep: which settings of which techniques are measured on which scenes (Sweep:
the full, quick and tiny presets; Setting: one row's technique and parameter columns)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from skinlab.resources import scenes_root

from .ledger_row import LedgerRow, setting_columns
from .truth_ledger import REFERENCE_SCENES, TruthSpec, reference_scene_names

ASSETS = scenes_root()
SCENE_ALIASES = {"head": None, "bunny": ASSETS / "bunny-skimmilk.toml"}
REFERENCE_SCENE_NAMES = tuple(reference_scene_names())


@dataclass(frozen=True)
class Sweep:
    """A sweep preset. Which settings of which technique it measures is declared by each technique
    (``LedgerStyle.sweep[name]``, skinlab/render/technique.py); the preset holds the conditions."""

    name: str
    size: tuple[int, int]
    shadow_size: int
    frames: int  # timed frames per setting (fewer if over budget_s)
    warmup: int
    budget_s: float  # rough time budget of the timed frames of one setting
    photons: int  # Monte Carlo photons per channel
    peer_frames: int
    scenes: tuple[str, ...] = ("head", "bunny")
    extra: tuple = ()  # extra settings
    # a technique that declares no sweep for this preset is measured once with its default settings
    every_technique: bool = True
    # the path-traced truth: reference size and samples (skinlab/bench/truth_ledger.py); None: not measured
    truth: TruthSpec | None = None
    # settings fields of the image reference's base setting changed from its declaration (--exact-size)
    reference_values: tuple[tuple[str, object], ...] = ()


FULL = Sweep(
    "full",
    (640, 640),
    2048,
    frames=10,
    warmup=2,
    budget_s=25.0,
    photons=200_000,
    peer_frames=30,
    scenes=REFERENCE_SCENE_NAMES,
    truth=TruthSpec((192, 192), 1024),
)
QUICK = Sweep(
    "quick",
    (160, 160),
    1024,
    frames=5,
    warmup=2,
    budget_s=2.0,
    photons=20_000,
    peer_frames=5,
    scenes=("head-skin1-matched", "bunny-skimmilk", "slab-edge-skin1"),
    truth=TruthSpec((96, 96), 256),
)
# for the tests: the techniques that declare a tiny sweep on the index-matched head at 64x64, a 32x32 truth
TINY = Sweep(
    "tiny",
    (64, 64),
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


def _style(technique: str):
    from skinlab.render.registry import get_technique

    return get_technique(technique).ledger


def _fields(technique: str) -> list[str]:
    """The settings fields the technique's ledger columns show (in column order, once each)."""
    return list(dict.fromkeys(_style(technique).columns.values()))


@dataclass(frozen=True)
class Setting:
    """One ledger row's setting: a registered technique and the values of the settings fields its
    ledger columns show (LedgerStyle.columns), every one filled in (defaults where not given), so
    that two ways of spelling one setting are one setting."""

    technique: str  # a registered technique
    values: tuple[tuple[str, object], ...] = ()

    @classmethod
    def of(cls, technique: str, **values) -> Setting:
        from skinlab.render.registry import get_technique

        t = get_technique(technique)
        fields = _fields(technique)
        unknown = set(values) - set(fields)
        if unknown:
            raise ValueError(
                f"ledger setting {technique}: {', '.join(sorted(unknown))} is not among its ledger columns' "
                f"fields ({', '.join(fields) or 'none'})"
            )
        defaults = t.settings_type.defaults()
        return cls(technique, tuple((f, values.get(f, defaults[f])) for f in fields))

    def value(self, field: str):
        return dict(self.values)[field]

    @property
    def style(self):
        return _style(self.technique)

    @property
    def label(self) -> str:
        if not self.style.label:
            return self.technique
        return self.style.label.format(**{f: ("auto" if v is None else v) for f, v in self.values})

    def render_settings(self, sweep: Sweep, size=None, supersample: int = 1):
        """The setting's render settings at the sweep's size (the timed frames) or at `size` with
        `supersample` (the frames compared with the truth)."""
        from skinlab.render.settings import RenderSettings

        w, h = size or sweep.size
        return RenderSettings.for_technique(
            self.technique, w, h, shadow_size=sweep.shadow_size, supersample=supersample, **dict(self.values)
        )

    def cells(self) -> dict:
        """The parameter columns; empty where the parameter does not apply to the technique."""
        own = {c: dict(self.values)[f] for c, f in self.style.columns.items()}
        return {c: ("auto" if own[c] is None else own[c]) if c in own else "" for c in setting_columns()}

    def varied(self, base: Setting) -> list[str]:
        """The fields in which this setting differs from `base` (same technique)."""
        b = dict(base.values)
        return [f for f, v in self.values if b.get(f) != v]


def declared_settings(technique: str, sweep: Sweep) -> list[Setting]:
    """The technique's settings in `sweep`: its declared base, then each axis varied alone from it;
    [] where it declares none for this preset (unless the preset measures every technique: then the
    defaults)."""
    style = _style(technique)
    decl = style.sweep.get(sweep.name)
    if decl is None:
        return [Setting.of(technique)] if sweep.every_technique else []
    base = dict(decl.base)
    if style.reference:
        base.update(dict(sweep.reference_values))
    out = [Setting.of(technique, **base)]
    for field, values in decl.axes.items():
        out += [Setting.of(technique, **{**base, field: v}) for v in values]
    return out


def base_setting(technique: str, sweep: Sweep) -> Setting | None:
    got = declared_settings(technique, sweep)
    return got[0] if got else None


def reference_technique() -> str | None:
    from skinlab.render.registry import techniques

    return next((t.name for t in techniques() if t.ledger.reference), None)


def sweep_settings(sweep: Sweep) -> list[Setting]:
    """The image reference's base setting first, then every registered technique's declared settings
    (registry order) and the preset's extras, without duplicates (in order)."""
    from skinlab.render.registry import technique_names

    ref = reference_technique()
    out = declared_settings(ref, sweep)[:1] if ref else []
    for name in technique_names():
        out += declared_settings(name, sweep)
    out += list(sweep.extra)
    seen, uniq = set(), []
    for s in out:
        if s not in seen:
            seen.add(s)
            uniq.append(s)
    return uniq


def sheet_settings(settings: list[Setting]) -> list[Setting]:
    """One setting per technique for the error-map contact sheet: the one with the technique's default
    settings where it was swept, else its first (for the image reference: its base)."""
    out = []
    for tech in dict.fromkeys(s.technique for s in settings):
        default = Setting.of(tech)
        cands = [s for s in settings if s.technique == tech]
        out.append(default if default in cands and not _style(tech).reference else cands[0])
    return out


def sheet_settings_of_rows(rows: list[LedgerRow]) -> dict[str, list[str]]:
    """Per scene, the labels of one ok row per technique (as sheet_settings picks them); every row of a
    peer (a renderer that is not a registered technique: skinlab/bench/blender_peer.py)."""
    out: dict[str, list[str]] = {}
    for scene in dict.fromkeys(r.scene for r in rows):
        srows = [r for r in rows if r.scene == scene and r.status == "ok"]
        labels = []
        for tech in dict.fromkeys(r.technique for r in srows):
            cands = [r.setting for r in srows if r.technique == tech]
            if any(r.peer for r in srows if r.technique == tech):
                labels += cands
                continue
            default = Setting.of(tech).label
            labels.append(default if default in cands and not _style(tech).reference else cands[0])
        out[scene] = labels
    return out


def proxy_reference(settings: list[Setting]) -> Setting | None:
    """The most accurate setting of a technique that declares a proxy order: the largest values of
    its LedgerStyle.proxy fields, in order (None, e.g. automatic taps, counts as largest)."""
    cands = [s for s in settings if s.style.proxy]
    if not cands:
        return None

    def rank(s):
        v = dict(s.values)
        return tuple((1, 0) if v.get(f) is None else (0, v.get(f)) for f in s.style.proxy)

    return max(cands, key=rank)


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
