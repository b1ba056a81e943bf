"""The frame's table of subsurface profiles for a screen-space technique: the distinct (sss_model,
medium) pairs among the visible scattering meshes, in the order first met, up to MAX_PROFILES (the
shaders' table size: each technique's gather or blur indexes it by the profile index the forward pass
writes per pixel, so many media share one frame, as HDRP keeps a table of diffusion profiles). A mesh
whose profile does not fit uses the last profile kept, with a plan warning naming it."""

from __future__ import annotations

from dataclasses import dataclass, field

from skinlab.gl.uniforms import set_uniform
from skinlab.render.scattering import scattering_material
from skinlab.render.technique import ForwardHook, NodeShading
from skinlab.render.translucency import REASON, translucent_shading
from skinlab.scene.optics.material_medium import material_medium

MAX_PROFILES = 16  # rows in a frame's profile table (the MAX_*_PROFILES defines of the technique shaders)


@dataclass
class ProfileTable:
    keys: list = field(default_factory=list)  # (sss_model, Medium) by profile index
    materials: list = field(default_factory=list)  # the first material using each profile (named in the plan)
    nodes: dict = field(default_factory=dict)  # node uid -> (effective material, profile index)


def plan_profile_table(meshes, settings, plan, technique: str) -> ProfileTable:
    """The profile table of `meshes` (skipped ones recorded as '<technique>[<node>]' by
    scattering_material); the warning for a profile past MAX_PROFILES names the technique."""
    t = ProfileTable()
    for n in meshes:
        mat = scattering_material(n, settings, plan, f"{technique}[{n.name}]")
        if mat is None:
            continue
        key = (mat["sss_model"], material_medium(mat.values))
        if key not in t.keys:
            if len(t.keys) == MAX_PROFILES:
                plan.warnings.append(
                    f"{technique} keeps {MAX_PROFILES} profiles per frame: node '{n.name}' "
                    f"(material '{mat.name}') uses material '{t.materials[-1].name}''s profile"
                )
                t.nodes[n.uid] = (mat, len(t.keys) - 1)
                continue
            t.keys.append(key)
            t.materials.append(mat)
        t.nodes[n.uid] = (mat, t.keys.index(key))
    return t


class ProfileIndexForward(ForwardHook):
    """The forward pass's part of a screen-space technique that filters a second target by profile:
    every mesh writes its subsurface diffuse (with `translucency`, the light through thin parts too)
    to `target`, its alpha the mesh's profile index + 1 through the hook's `uniform` (0: not filtered,
    plain diffuse). `profiles`: node uid -> (the material to bind, profile index); `what` ends the
    forward pass's reason."""

    def __init__(self, hook: str, uniform: str, target: str, what: str, profiles: dict, translucency: bool):
        self.hook, self.uniform, self.profiles, self.translucency = hook, uniform, profiles, translucency
        self.outputs = (target,)
        self.reason = "; subsurface diffuse" + (f" and {REASON}" if translucency else "") + f" {what}"

    def shading(self, node, frame) -> NodeShading:
        mat, index = self.profiles.get(node.uid, (node.material, -1))
        value = float(index + 1)

        def bind(prog, units):
            set_uniform(prog, self.uniform, value)

        return translucent_shading(mat, self.hook, frame, self.translucency and index >= 0, bind, subsurface=index >= 0)
