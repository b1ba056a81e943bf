"""Where the core meets a subsurface technique: the interfaces a technique package implements.

A technique (skinlab/render/techniques/<name>/, registered in skinlab/render/registry.py) declares

- ``name`` and a one-line ``description`` (shown by `skinlab render --help` and the viewer); ``slow``
  when a frame may take seconds (the viewer's T key skips it);
- ``settings_type``: its settings dataclass (skinlab/render/options.py), the value of
  ``RenderSettings.technique``;
- :meth:`Technique.plan`: its passes for the visible meshes (PlannedPass lists with reasons, skips in
  the frame plan) and how the forward pass shades each mesh (a :class:`ForwardHook`);
- ``passes``: its pass classes by kind (each derived from :class:`RenderPass`), made once per renderer;
- ``state``: GPU state it keeps across frames (per renderer; a :class:`TechniqueState`), if any;
- ``vertex_streams``: extra per-vertex inputs its shaders read (:class:`VertexStream`, e.g.
  pre-integrated skin's curvature), computed and uploaded only in the frames it renders;
- for the accuracy ledger (skinlab/bench/): :meth:`Technique.edge_response` and its :class:`LedgerStyle`.

The forward pass (skinlab/render/passes/forward.py) shades every mesh with skinlab/shaders/passes/forward.frag;
the subsurface part of the diffuse term is one GLSL hook, ``skinlab/sss_hook.glsl``, which each
mesh's :class:`NodeShading` resolves to a technique's file (skinlab/shaders/techniques/<name>/forward.glsl).
The pass builds the surface inputs once, a ``Surface`` (skinlab/shaders/lib/surface_inputs.glsl:
position, normals, tangent frame, view, uv, the material sample ``m``, the subsurface weight
``sss_weight``), and hands it to each function of the hook:

    float sss_plain_weight(Surface s);                  // weight of the surface's own Burley diffuse
    void  sss_add_light(Surface s, vec3 e, vec3 vis, float NoL);  // per light: irradiance, shadow
                                                        // per channel, cosine
    vec3  sss_radiance(Surface s);                      // after the lights: the subsurface radiance
                                                        // added toward the viewer

A hook that defines ``SSS_HOOK_GATHERS_LIGHT`` (lib/sss_local.glsl) is given the shadow spread as the
oblique entry is (three lookups per light, lib/surface_inputs.glsl sss_entry_ramp); the others the
shadow at the mean entry point (sss_entry_visibility).

``s.m.sss_albedo`` is the subsurface albedo at the fragment: subsurface_color x the colour map x the
vertex colour (the colour rule, docs/scenes.md), not the plain part's base colour (``s.m.base``).
The forward pass adds Jensen's single scattering for every mesh that scatters; a hook whose light
enters and leaves through the shared separable boundary (lib/sss_boundary.glsl sss_entry, sss_exit)
without spreading the boundary's non-separable rest itself defines ``SSS_MS_REST_LANDS``, and the
forward pass adds that rest where the light lands (tsd, exact, preintegrated; lib/sss_local.glsl
spreads it with its light).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Generic, Protocol, TypeVar, cast

from skinlab.scene.optics.edges import step_edge

from .compute import Device, PassPath, choose_path
from .frame_plan import FramePlan, PlannedPass
from .options import TechniqueSettings
from .vertex_streams import VertexStream

if TYPE_CHECKING:
    import moderngl

    from skinlab.gl.programs import ProgramCache
    from skinlab.scene.graph import LightNode, MeshNode, Scene

    from .frame import Frame
    from .gpu_resources import GpuResources
    from .settings import RenderSettings
    from .texture_units import TextureUnits

PLAIN_HOOK = "techniques/none/forward.glsl"  # no subsurface term: Burley diffuse only
HOOK_INCLUDE = "skinlab/sss_hook.glsl"  # the include name forward.frag uses for the hook

S = TypeVar("S", bound=TechniqueSettings)


class PassHost(Protocol):
    """What a pass uses of the renderer that made it (skinlab/render/renderer.py ``Renderer``)."""

    ctx: moderngl.Context
    programs: ProgramCache
    resources: GpuResources

    def fullscreen(self, prog: moderngl.Program) -> None: ...

    def dummy_texture(self) -> moderngl.Texture: ...

    def dummy_shadow_map(self) -> moderngl.Texture: ...

    def state(self, key: str, factory: Callable[[moderngl.Context], Any]) -> Any: ...


class RenderPass:
    """A pass kind's implementation: made once per renderer, run for each planned pass of its kind.

    The optional parts have no-op defaults: ``release()`` frees the pass's own GPU objects (called by
    Renderer.release); a pass that can be reused across frames (its PlannedPass has ``inputs``;
    skinlab/render/reuse.py) returns from ``outputs(frame, planned)`` the textures holding its result
    (the default, none, runs it every frame) and has ``publish(frame, planned)`` hand them to the frame
    as ``run`` does."""

    def __init__(self, renderer: PassHost) -> None:
        self.r = renderer

    def run(self, frame: Frame, p: PlannedPass) -> None:
        raise NotImplementedError(f"{type(self).__name__}.run")

    def outputs(self, frame: Frame, p: PlannedPass) -> tuple[moderngl.Texture, ...]:
        return ()

    def publish(self, frame: Frame, p: PlannedPass) -> None:
        return None

    def release(self) -> None:
        return None


class TechniqueState:
    """GPU state a technique keeps across frames (``Technique.state``; one per renderer): told each
    frame plan before the passes run (``begin_frame``: release what the plan no longer needs) and
    released with the renderer."""

    def begin_frame(self, plan: FramePlan) -> None:
        return None

    def release(self) -> None:
        return None


@dataclass
class DrawPart:
    """Some of a mesh's triangles drawn with a variant of their own: `count` indices from `first` of
    `indices` (a uint32 index buffer into the mesh's vertices), with the NodeShading's defines updated
    by `defines`."""

    indices: moderngl.Buffer
    first: int
    count: int
    defines: dict[str, object] = field(default_factory=dict)


@dataclass
class NodeShading:
    """How the forward pass shades one mesh: the material to bind, the hook file, the variant's
    defines and a function binding the hook's uniforms and textures."""

    material: Any
    hook: str = PLAIN_HOOK
    defines: dict[str, object] = field(default_factory=dict)
    bind: Callable[[moderngl.Program, TextureUnits], object] | None = None  # its result is not used
    # the mesh scatters below its surface: the forward pass binds its medium's entry/exit factors
    # and single scattering (skinlab/render/boundary.py); False for a hook that shades it without
    subsurface: bool = True
    # the mesh's triangles in parts, each drawn with its own variant (texture-space diffusion: those
    # that can read light through thin parts, and the others without that code); () draws the mesh's
    # own triangles at once. The parts together must be every triangle once; an opaque mesh's alone
    # (a blended one is drawn whole)
    parts: tuple[DrawPart, ...] = ()


class ForwardHook:
    """A technique's part of the forward pass (planned per frame). The base class shades every mesh
    with plain Burley diffuse."""

    outputs: tuple[str, ...] = ()  # extra colour targets (frame.targets names) written at locations 1, 2...
    reason: str = ""  # appended to the forward pass's reason in the frame plan

    def shading(self, node: MeshNode, frame: Frame) -> NodeShading | None:
        """None: the node's own material with the plain hook."""
        return None


@dataclass
class ForwardParams:
    """The forward pass's parameters (skinlab/render/passes/forward.py)."""

    lights: list[LightNode]
    shadow_lights: list[LightNode]
    hook: ForwardHook  # the technique's shading of each mesh


@dataclass
class PlanContext(Generic[S]):
    """What a technique plans from."""

    scene: Scene
    settings: RenderSettings
    meshes: list[MeshNode]  # visible mesh nodes
    lights: list[LightNode]  # the lights used (at most settings.max_lights)
    shadow_lights: list[LightNode]  # those with a shadow map (at most 2)
    plan: FramePlan  # record skips and warnings here
    state: Any = None  # the technique's renderer-side state; None when planned without a renderer
    device: Device | None = None  # the GL context's abilities (compute shaders); None: planned without one

    @property
    def options(self) -> S:
        """The technique's settings (``settings.technique``, of the planning technique's type)."""
        return cast(S, self.settings.technique_options)

    def path(self, software: str = "compute") -> PassPath:
        """Compute or fragment shader for a pass with a compute variant (skinlab/render/compute.py
        choose_path; `software`: the path ``compute = auto`` takes on software GL)."""
        return choose_path(self.settings, self.device, software)


@dataclass
class TechniquePlan:
    """A technique's share of the frame plan."""

    forward: ForwardHook = field(default_factory=ForwardHook)
    before_forward: list[PlannedPass] = field(default_factory=list)
    after_forward: list[PlannedPass] = field(default_factory=list)
    shadow_distance: bool = False  # the shadow passes also write light-space distance maps


@dataclass(frozen=True)
class LedgerSweep:
    """The settings the accuracy ledger measures for a technique in one sweep preset ("full",
    "quick", "tiny"): ``base`` fixes settings fields (the others keep their defaults); each of
    ``axes`` (field -> values) is varied alone from the base. The base itself is always measured."""

    base: dict[str, Any] = field(default_factory=dict)
    axes: dict[str, tuple] = field(default_factory=dict)


@dataclass(frozen=True)
class LedgerStyle:
    """How the accuracy ledger measures, names, tabulates and plots a technique's settings
    (skinlab/bench/sweep.py reads it; nothing there names a technique)."""

    marker: str  # matplotlib marker
    colour: str
    columns: dict[str, str] = field(default_factory=dict)  # ledger CSV column -> settings field
    label: str = ""  # setting label, str.format over the settings fields (None shows as "auto"); "" = the name
    # per sweep preset, the settings measured; a preset not named: the default settings once (where the
    # preset measures every technique)
    sweep: dict[str, LedgerSweep] = field(default_factory=dict)
    reference: bool = False  # its base setting is the ledger's image reference (measured first)
    # a stand-in reference where none renders: its setting with the largest values of these fields
    # (in this order; None counts as largest)
    proxy: tuple[str, ...] = ()
    # cost slopes: field -> (what the cost scales with, power), e.g. size -> ("texels", 2): log time
    # against log(size^2) over that axis
    cost_axes: dict[str, tuple[str, float]] = field(default_factory=dict)
    levels: str = ""  # a pass kind whose count the ledger reports as `blur_levels` (0: the frame blurs nothing)


class Technique(Generic[S]):
    """Base class of a technique package's ``TECHNIQUE``; see the module docstring. ``S`` is its
    settings class (``settings_type``)."""

    name: str = ""
    description: str = ""
    settings_type: type[S]
    passes: Mapping[str, type[RenderPass]] = {}
    # (key shared by techniques, factory(ctx)): its GPU state kept across frames
    state: tuple[str, Callable[[moderngl.Context], TechniqueState]] | None = None
    ledger: LedgerStyle = LedgerStyle("o", "grey")
    scatters: bool = True  # False: the technique renders no material as scattering (its model is "none")
    # not empty: why a frame may take long (an image reference); the viewer's T key skips the technique
    # and its panel marks it with this, so a slow GPU is not stalled by one key press
    slow: str = ""
    # extra per-vertex inputs of its shaders, beyond position, normal, uv, tangent and colour
    vertex_streams: tuple[VertexStream, ...] = ()

    def plan(self, ctx: PlanContext[S]) -> TechniquePlan:
        return TechniquePlan()

    def edge_response(self, model: str, medium, plan: FramePlan):
        """The technique's edge response x_mm -> (N, 3) for a material of `model` and `medium`, as
        the frame `plan` rendered it; None where it has none. Default: no light moves (a step)."""
        return step_edge
