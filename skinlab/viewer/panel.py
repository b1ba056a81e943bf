"""The parameter panel's logic, independent of any GUI toolkit (unit-tested without a window).

Widgets are derived from the declarations (``skinlab.declare.Field``: material parameters, render and
technique settings alike) through one table, :data:`WIDGETS`, so a new parameter or setting appears in
the panel without GUI code: ``float`` -> slider over its range, ``int`` -> integer slider, ``bool`` ->
checkbox, ``color`` -> colour editor, ``vec3`` / ``vec2`` -> draggable numbers within the range,
``texture`` -> file path, ``choice`` -> combo box; a field that may be None (automatic) adds an "auto"
checkbox (``<widget>_or_auto``). Edits are clamped into the declared range (``Field.clamp``) and then
applied through ``Material.update`` or the settings (which validate again and name the field on error).

Presets map a Jensen et al. 2001 medium onto the principled parameters as a scene file's ``preset``
does (skinlab.scene.materials.medium_values): base and ``subsurface_color`` the medium's diffuse surface
albedo (``Medium.surface_albedo()``, photon-beam-diffusion total reflectance), ``subsurface_radius``
its artist radius ``R = 4 pi l`` in mm (``Medium.artist_radius_mm``; Cycles' convention, see
``skinlab/scene/optics/media.py``), subsurface 1 and the specular of its index.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from skinlab.declare import Field, declared_fields
from skinlab.scene import transform as tf
from skinlab.scene.graph import CameraNode, LightNode, MeshNode, Node, Scene
from skinlab.scene.materials import Material

# Field.kind -> widget kind, for every declaration the panel shows; a field that may be None
# (automatic) gets "<widget>_or_auto"
WIDGETS = {
    "float": "slider_float",
    "int": "slider_int",
    "bool": "checkbox",
    "color": "color_edit3",
    "vec3": "drag_float3",
    "vec2": "drag_float2",
    "texture": "file_path",
    "choice": "combo",
}


@dataclass(frozen=True)
class Widget:
    """What to draw for one parameter: the widget kind plus everything it needs."""

    param: str
    widget: str
    value: Any
    range: tuple[float, float] | None = None
    choices: tuple[str, ...] = ()
    unit: str = ""
    doc: str = ""
    logarithmic: bool = False  # sliders over ranges spanning decades (e.g. radius 0-1000 mm)


def widget_for(decl: Field, value: Any = None) -> Widget:
    """The widget of one declaration showing `value` (None: the default, or automatic where the field
    allows None); its tooltip is the declaration's help (meaning, values, default with its unit)."""
    kind = WIDGETS.get(decl.kind)
    if kind is None:
        raise ValueError(
            f"parameter {decl.name!r}: no panel widget for kind {decl.kind!r} (known kinds: {', '.join(WIDGETS)})"
        )
    if value is None and decl.kind != "texture" and not decl.none:
        value = decl.default
    rng = tuple(float(x) for x in decl.range) if decl.range is not None else None
    log = bool(decl.kind != "int" and rng and rng[0] >= 0 and rng[1] >= 1000 * max(rng[0], 1e-3))
    kind += "_or_auto" if decl.none else ""
    return Widget(decl.name, kind, value, rng, tuple(decl.choices), decl.unit, decl.help(), log)


def widget_label(w: Widget) -> str:
    """What the panel prints beside a widget: the parameter and its unit (colours: linear RGB)."""
    return f"{w.param} ({w.unit})" if w.unit else w.param


def texture_text(value: Any) -> str:
    """A texture field shows the file's name (the full path is the tooltip); empty: no map."""
    return "" if value is None else Path(str(value)).name


def resolve_texture_input(text: str, current: Any, scene_dir: Path | None) -> str:
    """A texture typed into the panel: an absolute path as is; a relative one (a bare file name
    included) next to the current map, else relative to the scene file's folder."""
    text = text.strip()
    if not text:
        return ""
    p = Path(text).expanduser()
    if p.is_absolute():
        return str(p)
    base = Path(str(current)).parent if current is not None else scene_dir
    return str((base / p) if base is not None else p)


def sss_override_note(material: Material, override: str | None) -> str | None:
    """The line that says the M key (RenderSettings.sss_model) overrides the material's own model."""
    if override is None:
        return None
    own = material.values.get("sss_model")
    if own == override:
        return f"sss_model: M forces '{override}' on every material (this one's own is the same)"
    return f"sss_model: M forces '{override}' on every material; this one's own '{own}' is not used"


def clamp_value(param: Field, value: Any) -> Any:
    """The value a widget hands back, made valid for ``param``: numbers are clamped into the
    range (NaN -> the default), colours/vec3 element-wise; choices must be one of the options;
    textures must name an existing file (or be empty: no map). Errors name the parameter."""
    if param.kind in ("float", "color", "vec3", "vec2", "choice"):
        return param.clamp(value)
    if param.kind == "texture":
        if value is None or str(value).strip() == "":
            return None
        p = Path(str(value).strip()).expanduser()
        if not p.is_file():
            raise ValueError(f"{param.name}: texture file not found: {p}")
        return p.resolve()
    raise ValueError(f"parameter {param.name!r}: unknown kind {param.kind!r}")


def material_widgets(material: Material) -> list[Widget]:
    return [widget_for(p, material.values.get(p.name)) for p in material.params]


def medium_to_params(medium) -> dict:
    """What a preset sets, the same in the viewer as in a scene file (``preset = NAME``), the API
    (``Material.apply_preset``) and ``skinlab render --preset``: skinlab.scene.materials.medium_values
    (base and subsurface colour, radius, subsurface 1, the specular of its index; a colour map stays
    and multiplies the colour: the colour rule, docs/scenes.md)."""
    from skinlab.scene.materials import medium_values

    return medium_values(medium)


def direction_from_angles(azimuth_deg: float, elevation_deg: float) -> np.ndarray:
    """Direction a light travels for a light placed at (azimuth, elevation): azimuth about +Y
    from +Z, elevation above the XZ plane; the light shines from there towards the origin."""
    az, el = math.radians(azimuth_deg), math.radians(elevation_deg)
    towards_light = np.array([math.cos(el) * math.sin(az), math.sin(el), math.cos(el) * math.cos(az)])
    return -towards_light


def angles_from_direction(direction) -> tuple[float, float]:
    d = -np.asarray(direction, np.float64)
    d = d / np.linalg.norm(d)
    return math.degrees(math.atan2(d[0], d[2])), math.degrees(math.asin(float(np.clip(d[1], -1, 1))))


@dataclass
class TreeRow:
    node: Node
    depth: int
    label: str


@dataclass
class PanelModel:
    """State behind the panel: the scene tree, the selected node, material edits, presets and
    the key light. ``version`` increases whenever something that affects the image changed."""

    scene: Scene
    presets: Callable[[], dict] | None = None  # name -> Medium (the viewer's last good set)
    selected: Node | None = None
    version: int = 0
    error: str | None = None  # last rejected edit, shown in the panel
    applied_presets: dict[int, str] = field(default_factory=dict)  # id(material) -> preset name
    _ambient_before_map: np.ndarray | None = None  # the scene's ambient while the viewer's map replaces it

    def __post_init__(self) -> None:
        self.set_scene(self.scene)

    # -- scene tree ---------------------------------------------------------------------------
    def set_scene(self, scene: Scene) -> None:
        """Switch to a (re)loaded scene, keeping the selection by name where it still exists."""
        old = self.selected.name if self.selected is not None else None
        self.scene = scene
        self.applied_presets = {}
        self._ambient_before_map = None
        self.selected = None
        meshes = scene.mesh_nodes(visible_only=False)
        if old is not None:
            self.selected = next((n for n in scene.nodes() if n.name == old), None)
        if self.selected is None and meshes:
            self.selected = meshes[0]
        self.version += 1

    def tree(self) -> list[TreeRow]:
        rows = []

        def visit(node: Node, depth: int) -> None:
            kind = (
                "mesh"
                if isinstance(node, MeshNode)
                else "light"
                if isinstance(node, LightNode)
                else "camera"
                if isinstance(node, CameraNode)
                else "group"
            )
            rows.append(TreeRow(node, depth, f"{node.name} ({kind})"))
            for c in node.children:
                visit(c, depth + 1)

        for c in self.scene.root.children:
            visit(c, 0)
        return rows

    def select(self, name: str) -> Node:
        node = self.scene.find(name)  # KeyError names the scene and node
        self.selected = node
        return node

    @property
    def material(self) -> Material | None:
        return self.selected.material if isinstance(self.selected, MeshNode) else None

    def material_users(self) -> list[MeshNode]:
        m = self.material
        return [n for n in self.scene.mesh_nodes(visible_only=False) if n.material is m] if m else []

    def widgets(self) -> list[Widget]:
        return material_widgets(self.material) if self.material is not None else []

    # -- edits --------------------------------------------------------------------------------
    def edit(self, name: str, value: Any) -> Any:
        """Clamp and apply one parameter of the selected node's material (shared by every node
        that uses the same material). Returns the applied value; errors are kept in ``error``
        and re-raised as ValueError naming the parameter."""
        m = self.material
        if m is None:
            raise ValueError(f"edit {name}: the selected node {getattr(self.selected, 'name', None)!r} has no material")
        param = m.param_map.get(name)
        if param is None:
            raise ValueError(f"material {m.name!r}: unknown parameter {name!r}; known: {', '.join(m.param_map)}")
        try:
            if param.kind == "texture" and isinstance(value, str):
                source = getattr(self.scene, "source", None)
                value = resolve_texture_input(value, m.values.get(name), Path(source).parent if source else None)
            v = clamp_value(param, value)
            m.update({name: v})
        except ValueError as exc:
            self.error = f"material {m.name!r}: {exc}" if m.name not in str(exc) else str(exc)
            raise ValueError(self.error) from None
        self.error = None
        if name in ("subsurface_color", "subsurface_radius"):
            self.applied_presets.pop(id(m), None)  # hand edits detach the preset
        self.version += 1
        return m.values[name]

    def preset_names(self) -> list[str]:
        return sorted(self.presets()) if self.presets else []

    def apply_preset(self, name: str) -> dict:
        m = self.material
        if m is None:
            raise ValueError(f"preset {name}: the selected node has no material")
        media = self.presets() if self.presets else {}
        if name not in media:
            raise ValueError(f"preset: unknown material {name!r}; choose one of {', '.join(sorted(media))}")
        values = medium_to_params(media[name])
        for k, v in values.items():
            self.edit(k, v)
        self.applied_presets[id(m)] = name
        return values

    def reapply_presets(self) -> list[str]:
        """After the preset file changed: apply the new numbers to materials that use a preset."""
        done = []
        media = self.presets() if self.presets else {}
        mats = {id(n.material): n.material for n in self.scene.mesh_nodes(visible_only=False)}
        for mid, name in list(self.applied_presets.items()):
            m = mats.get(mid)
            if m is None or name not in media:
                continue
            m.update(medium_to_params(media[name]))
            done.append(f"{m.name}: {name}")
        if done:
            self.version += 1
        return done

    # -- key light ----------------------------------------------------------------------------
    def key_light(self) -> LightNode | None:
        """The light named 'key', else the first shadow-casting light, else the first light."""
        lights = [n for n in self.scene.nodes() if isinstance(n, LightNode)]
        for pick in (lambda l: l.name == "key", lambda l: l.cast_shadow, lambda l: True):
            for l in lights:
                if pick(l):
                    return l
        return None

    def lights(self) -> list[LightNode]:
        """Every light of the scene, the key light first (the panel shows a row of controls each)."""
        key = self.key_light()
        rest = [n for n in self.scene.nodes() if isinstance(n, LightNode) and n is not key]
        return ([key] if key is not None else []) + rest

    def set_light_direction(self, direction, light: LightNode | None = None) -> np.ndarray:
        """Turn a light (the key light by default) to travel along ``direction``."""
        light = light or self.key_light()
        if light is None:
            raise ValueError("light direction: the scene has no light")
        d = np.asarray(direction, np.float64).reshape(-1)
        if d.size != 3 or not np.isfinite(d).all() or np.linalg.norm(d) == 0:
            raise ValueError(f"light direction: expected 3 finite numbers, not all zero; got {direction!r}")
        d = d / np.linalg.norm(d)
        if light.kind == "directional":
            light.rotation = tf.look_at_rotation(np.zeros(3), d)
        else:  # a local light: move it to the same distance from the origin, opposite the direction
            r = float(np.linalg.norm(light.translation)) or 1.0
            light.translation = -d * r
            if light.kind in ("spot", "rect"):  # and turn it to shine at the origin
                light.rotation = tf.look_at_rotation(np.zeros(3), d)
        self.version += 1
        return d

    def light_direction(self, light: LightNode | None = None) -> np.ndarray | None:
        light = light or self.key_light()
        if light is None:
            return None
        if light.kind == "directional":
            return light.direction
        p = light.world_position
        n = np.linalg.norm(p)
        return -p / n if n else np.array([0.0, 0.0, -1.0])

    def set_light_intensity(self, light: LightNode, value: float) -> float:
        """A light's intensity, clamped into LIGHT_INTENSITY (NaN: unchanged)."""
        v = float(value)
        if not math.isfinite(v):
            return light.intensity
        light.intensity = min(max(v, LIGHT_INTENSITY[0]), LIGHT_INTENSITY[1])
        self.version += 1
        return light.intensity

    def set_light_color(self, light: LightNode, rgb) -> np.ndarray:
        """A light's linear RGB colour, each channel clamped into [0, LIGHT_COLOR_MAX]."""
        c = np.asarray(rgb, np.float64).reshape(-1)
        if c.size != 3 or not np.isfinite(c).all():
            raise ValueError(f"light {light.name!r} color: expected 3 finite numbers, got {rgb!r}")
        light.color = np.clip(c, 0.0, LIGHT_COLOR_MAX)
        self.version += 1
        return light.color

    # -- exposure -----------------------------------------------------------------------------
    def exposure(self) -> float:
        return float(self.scene.environment.exposure)

    def set_exposure(self, value: float) -> float:
        """The scene's exposure (a linear multiplier before tone mapping), clamped into EXPOSURE."""
        v = float(value)
        if not math.isfinite(v):
            return self.exposure()
        self.scene.environment.exposure = min(max(v, EXPOSURE[0]), EXPOSURE[1])
        self.version += 1
        return self.scene.environment.exposure

    # -- the selected light -------------------------------------------------------------------
    @property
    def light(self) -> LightNode | None:
        return self.selected if isinstance(self.selected, LightNode) else None

    def light_widgets(self) -> list[Widget]:
        light = self.light
        return light_widgets(light) if light is not None else []

    def edit_light(self, name: str, value: Any, light: LightNode | None = None) -> Any:
        """Set one of a light's values (the selected light's by default; light_widgets), clamped into
        its range; a spot's inner half-angle never exceeds its outer one. Errors name the light and the
        value."""
        light = light or self.light
        if light is None:
            raise ValueError(f"edit {name}: the selected node {getattr(self.selected, 'name', None)!r} is not a light")
        known = {w.param: w for w in light_widgets(light)}
        if name not in known:
            raise ValueError(f"light {light.name!r}: no value {name!r} (it has {', '.join(known)})")
        w = known[name]
        try:
            if w.widget == "checkbox":
                v = bool(value)
            elif w.widget == "color_edit3":
                v = np.clip(np.asarray(value, np.float64).reshape(3), 0.0, None)
                if not np.isfinite(v).all():
                    raise ValueError(f"{name}: expected 3 finite numbers, got {value!r}")
            else:
                v = float(value)
                if not math.isfinite(v):
                    raise ValueError(f"{name}: expected a finite number, got {value!r}")
                v = min(max(v, w.range[0]), w.range[1])
                if name == "angular_radius_deg":
                    name, v = "angular_radius", math.radians(v)
            old = getattr(light, name)
            setattr(light, name, v)
            if light.kind == "spot" and light.inner_deg > light.outer_deg:
                if name == "inner_deg":
                    light.outer_deg = light.inner_deg
                else:
                    light.inner_deg = light.outer_deg
            try:
                light.check_shape()
            except ValueError:
                setattr(light, name, old)
                raise
        except ValueError as exc:
            self.error = f"light {light.name!r}: {exc}" if light.name not in str(exc) else str(exc)
            raise ValueError(self.error) from None
        self.error = None
        self.version += 1
        return getattr(light, name)

    # -- the environment map ---------------------------------------------------------------------
    def environment_choices(self) -> list[str]:
        """What the map picker offers: none, the bundled maps, and the scene's own map file."""
        from skinlab.scene.envmap import bundled_maps

        names = [ENV_NONE, *bundled_maps()]
        current = self.environment_name()
        return names if current in names else [*names, current]

    def environment_name(self) -> str:
        from skinlab.scene.envmap import bundled_maps

        m = self.scene.environment.map
        if m is None:
            return ENV_NONE
        bundled = {str(p): n for n, p in bundled_maps().items()}
        return bundled.get(str(m), str(m))

    def set_environment(self, choice: str) -> None:
        """Light the scene with a bundled map (by name), a map file (a path, relative to the scene's
        folder), or none. A scene that had no map loses its uniform ambient while it has one (as a
        scene file with a map does) and gets it back with none."""
        from skinlab.scene.envmap import EnvironmentMapError, load_pixels, resolve_map

        env = self.scene.environment
        try:
            if choice in ("", ENV_NONE):
                if env.map is not None and self._ambient_before_map is not None:
                    env.ambient = self._ambient_before_map
                    self._ambient_before_map = None
                env.map = None
            else:
                source = getattr(self.scene, "source", None)
                path = resolve_map(choice.strip(), Path(source).parent if source else None)
                load_pixels(path)  # refuse a bad map here, with its one line
                if env.map is None:
                    self._ambient_before_map = np.array(env.ambient)
                    env.ambient = np.zeros(3)
                env.map = path
        except EnvironmentMapError as exc:
            self.error = str(exc)
            raise ValueError(self.error) from None
        self.error = None
        self.version += 1

    def set_environment_value(self, name: str, value: Any) -> Any:
        """rotation_deg (wrapped to [-180, 180]), intensity (clamped to [0, 100]) or show_background."""
        env = self.scene.environment
        if name == "show_background":
            env.show_background = bool(value)
        elif name in ("rotation_deg", "intensity"):
            v = float(value)
            if not math.isfinite(v):
                self.error = f"environment {name}: expected a finite number, got {value!r}"
                raise ValueError(self.error)
            setattr(env, name, (v + 180.0) % 360.0 - 180.0 if name == "rotation_deg" else min(max(v, 0.0), 100.0))
        else:
            raise ValueError(f"environment: no value {name!r} (rotation_deg, intensity, show_background)")
        self.error = None
        self.version += 1
        return getattr(env, name)


EXPOSURE = (1.0 / 256.0, 256.0)  # the panel's exposure slider (logarithmic): +-8 stops
LIGHT_INTENSITY = (0.0, 100.0)  # the panel's light intensity slider
LIGHT_COLOR_MAX = 10.0  # a light's colour channels in the panel (linear, may exceed 1)

ENV_NONE = "(none)"


# a light's angular radius (soft shadows of a directional light): the viewer's own setting (a scene
# file's directional lights are points at infinity; an environment map's sources get theirs from the map)
LIGHT_ANGULAR_RADIUS = Field(
    "angular_radius_deg",
    "float",
    0.0,
    (0.0, 10.0),
    unit="deg",
    doc="the light's angular radius: soft shadows (0: a point at infinity)",
)


def _light_widget(name: str, value: Any, rng: tuple[float, float] | None = None) -> Widget:
    """A light's widget from its [[lights]] scene-key declaration; `rng` the slider's reach where the
    declared range is open-ended (intensity, sizes)."""
    from skinlab.scene.scene_keys import scene_key

    decl = scene_key("[[lights]]", name)
    return widget_for(decl if rng is None else dataclasses.replace(decl, range=rng), value)


def light_widgets(light: LightNode) -> list[Widget]:
    """The panel's widgets for a light: its colour, intensity and shadow, and what its kind has (a
    spot's cone, an area light's size, a directional light's angular radius: soft shadows), each from
    its declaration (the scene file's [[lights]] keys; LIGHT_ANGULAR_RADIUS)."""
    top = max(10.0, 2.0 * light.intensity)
    out = [
        _light_widget("color", tuple(float(x) for x in light.color), (0.0, LIGHT_COLOR_MAX)),
        _light_widget("intensity", light.intensity, (0.0, top)),
        _light_widget("cast_shadow", light.cast_shadow),
    ]
    if light.kind == "spot":
        out += [_light_widget("inner_deg", light.inner_deg), _light_widget("outer_deg", light.outer_deg, (0.1, 90.0))]
    elif light.kind in ("rect", "sphere"):
        scale = 4.0 * max(light.width, light.height, light.radius)
        names = ("width", "height") if light.kind == "rect" else ("radius",)
        out += [_light_widget(n, getattr(light, n), (1e-3 * scale, scale)) for n in names]
    elif light.kind == "directional":
        out.append(widget_for(LIGHT_ANGULAR_RADIUS, math.degrees(light.angular_radius)))
    return out


# -- the current technique's and the render settings (declared with skinlab.declare.option) --------------------


def technique_widgets(settings) -> list[Widget]:
    """One widget per field of a technique's settings, from its declaration (range, meaning, default)."""
    return [widget_for(f, getattr(settings, name)) for name, f in settings.options().items()]


def render_widgets(settings) -> list[Widget]:
    """One widget per render setting the panel offers (RenderSettings.panel_options(): supersampling,
    interreflection, compute shaders), from its declaration like a technique's."""
    return [widget_for(f, getattr(settings, name)) for name, f in settings.panel_options().items()]


def technique_value(settings, name: str, value: Any) -> Any:
    """A widget's value made valid for the field (``Field.clamp``): numbers clamped into the declared
    range, integers rounded (odd counts to the nearest odd one inside the range); None (automatic)
    where the field allows it."""
    return declared_fields(type(settings))[name].clamp(value)
