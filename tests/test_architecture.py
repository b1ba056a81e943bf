"""The architecture habits as checks: docs/architecture.md's worked example registers and renders; the
core loops over the technique registry; no import cycles, no library module importing the CLI layer;
material uniforms declared only from their parameter declarations; tests use public names only."""

from __future__ import annotations

import ast
import re
import sys
import types
from pathlib import Path

import numpy as np
import pytest

from skinlab.render import registry
from skinlab.render.boundary import material_boundary
from skinlab.render.settings import RenderSettings
from skinlab.scene.graph import MeshNode
from skinlab.scene.materials import PRINCIPLED_PARAMS, Material
from tests.tsd_scenes import quad_mesh, skin, slab_scene

ROOT = Path(__file__).resolve().parents[1]
DOC = ROOT / "docs" / "architecture.md"


def doc_blocks(lang: str) -> list[str]:
    return re.findall(rf"```{lang}\n(.*?)```", DOC.read_text(encoding="utf-8"), re.S)


@pytest.fixture
def lambert(tmp_path):
    """The worked example of docs/architecture.md, exactly as written there, registered for one test."""
    glsl = next(b for b in doc_blocks("glsl") if "u_lambert_strength" in b)
    hook = tmp_path / "lambert_forward.glsl"
    hook.write_text(glsl, encoding="utf-8")
    (code,) = [b for b in doc_blocks("python") if "class LambertTechnique" in b]
    mod = types.ModuleType("lambert_example")  # the package, as if imported (dataclasses need it)
    sys.modules[mod.__name__] = mod
    exec(compile(code, str(DOC), "exec"), mod.__dict__)
    mod.HOOK = str(hook)  # the package's shader file lives under shaders/; here in tmp_path
    registry.register(mod.TECHNIQUE)
    try:
        yield mod
    finally:
        registry.unregister("lambert")
        del sys.modules[mod.__name__]


def test_worked_example_renders_what_it_says(renderer, lambert):
    assert "lambert" in registry.technique_names()
    scene = slab_scene(material=skin("burley", color=(0.8, 0.5, 0.25)))
    light = scene.lights()[0]
    res = {s: renderer.render(scene, RenderSettings.for_technique("lambert", 16, 16, strength=s)) for s in (0.0, 2.0)}
    # subsurface 1: no plain Burley diffuse, specular 0; the light falls straight on the slab. What is
    # left at strength 0 is the single scattering the forward pass adds for every scattering mesh
    # (Jensen's term at normal light and view, per unit subsurface albedo, times the subsurface colour:
    # the colour rule, docs/scenes.md)
    mat = scene.find("slab").material
    single = light.radiance * material_boundary(mat).single * np.array([0.8, 0.5, 0.25]) / (8 * np.pi)
    np.testing.assert_allclose(res[0.0].hdr[8, 8, :3], single, rtol=2e-3)
    expected = 2.0 * np.array([0.8, 0.5, 0.25]) * light.radiance / np.pi + single
    np.testing.assert_allclose(res[2.0].hdr[8, 8, :3], expected, rtol=1e-3)
    assert "Lambertian subsurface term for 1" in res[2.0].plan.explain()
    # a mesh that does not scatter is plain diffuse, with its skip in the plan
    scene.add(MeshNode("plain", quad_mesh("plain", 0.5, 1.5, 0.5, 1.5, z=0.1), Material("plain", {})))
    plan = renderer.render(scene, RenderSettings.for_technique("lambert", 16, 16), readback=False).plan
    assert any(w == "lambert[plain]" and "subsurface weight is 0" in why for w, why in plan.skipped)
    with pytest.raises(ValueError, match=r"lambert setting strength: expected a number in \[0, 4\], got 5"):
        RenderSettings.for_technique("lambert", 16, 16, strength=5)


def render_help(capsys) -> str:
    from skinlab.cli import build_parser

    with pytest.raises(SystemExit):
        build_parser().parse_args(["render", "--help"])
    return " ".join(capsys.readouterr().out.split())


def test_worked_example_is_measured_by_the_ledger(lambert):
    from skinlab.bench import sweep

    row = next(s for s in sweep.sweep_settings(sweep.QUICK) if s.technique == "lambert")
    assert row.label == "lambert" and row.cells() == dict.fromkeys(sweep.setting_columns(), "")
    st = row.render_settings(sweep.QUICK)
    assert st.technique_name == "lambert" and st.technique.strength == 1.0 and st.size == sweep.QUICK.size
    assert "lambert" not in {s.technique for s in sweep.sweep_settings(sweep.TINY)}  # the tests' sweep


def test_worked_example_gets_cli_options_from_its_declaration(lambert, capsys):
    from skinlab.cli import build_parser
    from skinlab.commands.render import settings_from_args

    text = render_help(capsys)
    assert "lambert: Lambertian subsurface term tinted" in text and "--lambert-strength" in text
    args = build_parser().parse_args(["render", "--technique", "lambert", "--lambert-strength", "2.5"])
    st = settings_from_args(args, 8, 8)
    assert st.technique_name == "lambert" and st.technique.strength == 2.5


def test_help_lists_every_registered_technique_with_its_description(capsys):
    text = render_help(capsys)
    for t in registry.techniques():
        assert f"{t.name}: {t.description}" in text
        for field in t.settings_type.options():
            assert f"--{t.name}-{field.replace('_', '-')}" in text


def test_registry_refuses_clashes():
    tsd = registry.get_technique("tsd")
    with pytest.raises(ValueError, match="technique 'tsd' is already registered"):
        registry.register(tsd)

    class Clash(type(tsd)):
        name = "clash"

    with pytest.raises(ValueError, match="settings class TsdSettings says technique = 'tsd'"):
        registry.register(Clash())
    with pytest.raises(ValueError, match="render setting technique: expected one of tsd, exact, ssss, tint, none"):
        registry.get_technique("fog")
    assert registry.technique_names()[:5] == ["tsd", "exact", "ssss", "tint", "none"]


def test_every_registered_pass_and_settings_class_keeps_the_interfaces():
    import inspect

    from skinlab.render.options import TechniqueSettings
    from skinlab.render.technique import RenderPass, TechniqueState

    for t in registry.techniques():
        assert t.description and "\n" not in t.description, t.name
        assert issubclass(t.settings_type, TechniqueSettings) and t.settings_type.technique == t.name
        t.settings_type()  # the defaults are valid
        if t.state is not None:
            assert issubclass(t.state[1], TechniqueState), t.name
        for kind, cls in t.passes.items():
            # the RenderPass base (skinlab/render/technique.py): made with the renderer, run per planned pass
            assert issubclass(cls, RenderPass), (t.name, kind)
            assert list(inspect.signature(cls.run).parameters) == ["self", "frame", "p"], (t.name, kind)
            assert list(inspect.signature(cls.__init__).parameters) == ["self", "renderer"], (t.name, kind)


def test_render_pass_defaults_are_no_ops(ctx):
    """RenderPass's optional parts: a pass naming no outputs (never reused), publishing and releasing
    nothing; run must be written."""
    from skinlab.render.renderer import Renderer
    from skinlab.render.technique import RenderPass

    r = Renderer(ctx)
    p = RenderPass(r)
    assert p.r is r and p.outputs(None, None) == () and p.publish(None, None) is None and p.release() is None
    with pytest.raises(NotImplementedError, match="RenderPass.run"):
        p.run(None, None)
    r.release()


def test_settings_for_a_name_import_that_technique_alone():
    """RenderSettings resolves a technique's name without the registry: only that package is imported
    (and the packages it builds on)."""
    import subprocess

    code = (
        "import sys\n"
        "from skinlab.render.settings import RenderSettings\n"
        "st = RenderSettings(16, 16, technique='ssss')\n"
        "pkgs = {m.split('.')[3] for m in sys.modules if m.startswith('skinlab.render.techniques.')}\n"
        "print(st.technique_name, sorted(pkgs), 'skinlab.render.registry' in sys.modules)"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.split() == ["ssss", "['ssss']", "False"], out


def test_release_frees_every_pass_and_state_and_the_renderer_stays_usable(ctx):
    from skinlab.render.renderer import Renderer

    r = Renderer(ctx)
    scene = slab_scene(occluder=True)
    r.render(scene, RenderSettings.for_technique("exact", 16, 16, shadow_size=64, size=64), readback=False)
    first = r.render(scene, RenderSettings.for_technique("ssss", 16, 16, shadow_size=64)).hdr
    assert {"ssss_blur", "tsd_exact", "shadow", "forward"} <= set(r.passes) and r.states
    made = dict(r.last_frame.targets)  # shadow map, forward targets, the screen-space blur's, tone mapping
    assert {"shadow_map0", "hdr_color", "ssss_blurred", "ldr_color", "depth"} <= set(made)
    r.release()
    assert r.states == {} and r.programs.entries == {} and r.passes["shadow"].maps == {}
    alive = [name for name, tex in made.items() if "InvalidObject" not in type(tex.mglo).__name__]
    assert alive == [], alive
    again = r.render(scene, RenderSettings.for_technique("ssss", 16, 16, shadow_size=64)).hdr
    np.testing.assert_array_equal(again, first)
    r.release()


def test_core_modules_never_name_a_technique():
    """plan.py, renderer.py, the forward pass and shader, the CLI's render options, the viewer and the
    ledger's run loop loop over the registry."""
    names = [n for n in registry.technique_names() if n != "none"]
    files = [
        "skinlab/render/plan.py",
        "skinlab/render/renderer.py",
        "skinlab/render/passes/forward.py",
        "skinlab/render/gpu_resources.py",
        "skinlab/render/vertex_streams.py",
        "skinlab/shaders/passes/forward.frag",
        "skinlab/shaders/passes/forward.vert",
        "skinlab/shaders/lib/surface_inputs.glsl",
        "skinlab/shaders/lib/material_sample.glsl",
        "skinlab/commands/render.py",
        "skinlab/commands/technique_options.py",
        "skinlab/viewer/core.py",
        "skinlab/viewer/gui.py",
    ]
    for f in files:
        text = (ROOT / f).read_text(encoding="utf-8")
        code = "\n".join(line.split("#")[0].split("//")[0] for line in text.splitlines())
        for n in names:
            assert not re.search(rf"[\"'/]{n}[\"'/_]|\b{n.upper()}_", code), (f, n)


def test_pass_shaders_of_one_technique_live_in_its_folder():
    """skinlab/shaders/passes/ holds the core's pass shaders: each is named by code outside the technique
    packages; a technique's own pass shaders are under skinlab/shaders/techniques/<name>/."""
    core = [p for p in (ROOT / "skinlab").rglob("*.py") if "techniques" not in p.relative_to(ROOT / "skinlab").parts]
    text = "\n".join(p.read_text(encoding="utf-8") for p in core)
    shaders = sorted((ROOT / "skinlab" / "shaders" / "passes").iterdir())
    assert any(p.name == "forward.frag" for p in shaders)
    for p in shaders:
        assert f"passes/{p.name}" in text, f"skinlab/shaders/passes/{p.name}: no core module uses it"


# -- imports ----------------------------------------------------------------------------------------------


def module_name(path: Path) -> str:
    parts = list((path.relative_to(ROOT) if path.is_relative_to(ROOT) else Path(path.name)).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(parts)


def imports_of(path: Path, modules: set[str]) -> set[str]:
    """Modules of the project imported anywhere in the file: functions too, and those imported for type
    annotations only (under TYPE_CHECKING), so that the types form no cycle either."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    me = module_name(path)
    pkg = me if path.name == "__init__.py" else me.rsplit(".", 1)[0]
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                up = pkg.split(".")[: len(pkg.split(".")) - node.level + 1]
                base = ".".join(up + ([base] if base else []))
            names = [f"{base}.{a.name}" if f"{base}.{a.name}" in modules else base for a in node.names]
        else:
            continue
        for n in names:
            while n and n not in modules:
                n = n.rpartition(".")[0]
            if n and n != me:
                out.add(n)
    return out


def project_graph() -> dict[str, set[str]]:
    files = list((ROOT / "skinlab").rglob("*.py"))
    modules = {module_name(p) for p in files}
    return {module_name(p): imports_of(p, modules) for p in files}


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """Strongly connected components with more than one module (Tarjan)."""
    index, low, stack, on, out = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in graph.get(v, ()):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    for v in graph:
        if v not in index:
            visit(v)
    return out


def test_no_import_cycles():
    graph = project_graph()
    assert "skinlab.bench.accuracy" in graph and graph["skinlab.render.plan"]  # the graph is real
    assert cycles(graph) == []


def test_the_cycle_check_finds_a_cycle(tmp_path):
    assert cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]
    # an import made for annotations only is an edge too
    mod = tmp_path / "m.py"
    mod.write_text("from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    from skinlab.render import frame\n")
    assert imports_of(mod, {"skinlab.render.frame"}) == {"skinlab.render.frame"}


def test_library_modules_never_import_the_cli_layer():
    for mod, deps in project_graph().items():
        if mod.startswith(("skinlab.commands", "skinlab.cli")):
            continue
        bad = {d for d in deps if d.startswith(("skinlab.commands", "skinlab.cli"))}
        assert not bad, (mod, bad)


def test_tests_use_public_names_only():
    """No test imports a private name of the project or reaches one through an imported module."""
    for path in sorted((ROOT / "tests").rglob("*.py")):
        tree = ast.parse(path.read_text(encoding="utf-8"))
        modules = set()  # names bound to project modules
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom) and (node.module or "").startswith("skinlab"):
                private = [a.name for a in node.names if a.name.startswith("_")]
                assert not private, (path.name, node.module, private)
                modules |= {a.asname or a.name for a in node.names}
            elif isinstance(node, ast.Import):
                modules |= {a.asname or a.name.split(".")[0] for a in node.names if a.name.startswith("skinlab")}
        for node in ast.walk(tree):
            if isinstance(node, ast.Attribute) and node.attr.startswith("_") and not node.attr.startswith("__"):
                assert ast.unparse(node.value) not in modules, (path.name, ast.unparse(node))


# -- material uniforms from the parameter declarations -----------------------------------------------------


def test_material_uniforms_are_declared_only_by_the_generated_include():
    from skinlab.scene.materials import glsl_material_uniforms

    generated = glsl_material_uniforms()
    for p in PRINCIPLED_PARAMS:
        if p.kind in ("float", "color", "vec3", "vec2", "texture"):
            assert re.search(rf"uniform \w+ {p.uniform};", generated), p.name
    for f in (ROOT / "shaders").rglob("*"):
        if f.suffix in (".glsl", ".frag", ".vert"):
            for p in PRINCIPLED_PARAMS:
                assert not re.search(rf"uniform\s+\w+\s+{p.uniform}\s*[;\[]", f.read_text()), (f, p.name)


def test_every_program_binding_materials_uses_the_declared_uniforms(renderer):
    """The forward and irradiance programs compiled for the head (maps set) and a plain material keep
    the uniforms their code reads; a renamed parameter would fail to compile instead."""
    from skinlab.scene.scenefile import load_scene

    for scene in (load_scene(), slab_scene()):
        for t in ("tsd", "tint", "ssss"):
            renderer.render(scene, RenderSettings.for_technique(t, 16, 16, shadow_size=64), readback=False)
    used = {"u_base_color", "u_roughness", "u_metallic", "u_specular"}
    progs = [(k, e.program) for k, e in renderer.programs.entries.items() if k[1] == "passes/forward.frag"]
    assert len(progs) >= 4
    for key, prog in progs:
        active = set(prog)
        assert used <= active, key
        if "techniques/none/" not in str(key):  # every hook but the plain one weighs by u_subsurface
            assert "u_subsurface" in active, key
        if "('HAS_NORMAL_MAP', '1')" in str(key):
            assert {"u_normal_map", "u_normal_scale"} <= active, key
    irr = [e.program for k, e in renderer.programs.entries.items() if k[1] == "techniques/tsd/irradiance.frag"]
    # the irradiance pass weighs each light by the shared entry factor (skinlab/render/boundary.py)
    assert irr and all({"u_subsurface_color", "u_sss_entry"} <= set(p) for p in irr)


def test_texture_units_are_handed_out_once_per_sampler(ctx):
    from skinlab.render.texture_units import TextureUnits

    class Tex:
        def __init__(self):
            self.units = []

        def use(self, unit):
            self.units.append(unit)

    class Prog(dict):
        pass

    units, a, b = TextureUnits(ctx), Tex(), Tex()
    prog = Prog()
    assert units.bind(prog, "u_a", a) == 0 and units.bind(prog, "u_b", b) == 1 and units.bind(prog, "u_a", a) == 0
    assert a.units == [0, 0] and b.units == [1] and units.limit >= 16
    small = TextureUnits()
    small.limit = 1
    small.bind(prog, "u_a", a)
    with pytest.raises(RuntimeError, match="u_b needs unit 1, but the GL offers 1"):
        small.bind(prog, "u_b", b)


def test_citations_resolve_inside_the_repo():
    """Every docs/references.md#section a comment points to exists; no comment points outside the repo."""
    sections = set(re.findall(r"^## ([\w-]+)$", (ROOT / "docs" / "references.md").read_text(), re.M))
    cited = set()
    for d in ("skinlab", "docs"):
        for f in (ROOT / d).rglob("*"):
            if f.suffix not in (".py", ".glsl", ".frag", ".vert", ".md", ".csv", ".toml"):
                continue
            text = f.read_text(encoding="utf-8", errors="replace")
            assert "shared/reference" not in text and "FACTS.md" not in text, f
            for anchor in re.findall(r"references\.md#([\w-]+)", text):
                assert anchor in sections, (f, anchor)
                cited.add(anchor)
    assert len(cited) >= 8, cited


def test_tools_run_as_modules_of_the_repository_without_editing_sys_path():
    """tools/ is a package run from the repository root (``python -m tools.NAME``): no script puts
    itself on sys.path; only full_over_plain's --code puts another checkout first, on purpose."""
    tools = ROOT / "tools"
    assert (tools / "__init__.py").is_file()
    editing = sorted(p.name for p in tools.glob("*.py") if "sys.path" in p.read_text(encoding="utf-8"))
    assert editing == ["__init__.py", "full_over_plain.py"], editing  # __init__ only says so
    assert "if args.code:" in (tools / "full_over_plain.py").read_text(encoding="utf-8")
    docs = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
    assert not [d.name for d in docs if "python tools/" in d.read_text(encoding="utf-8")]
    # neither the package nor the tools import the tests; the package does not import the tools
    pattern = re.compile(r"^\s*(?:from|import)\s+(tests|tools)\b", re.M)
    for f in [*sorted((ROOT / "skinlab").rglob("*.py")), *sorted(tools.glob("*.py"))]:
        found = {m.group(1) for m in pattern.finditer(f.read_text(encoding="utf-8"))}
        assert "tests" not in found and (f.parent == tools or "tools" not in found), f
