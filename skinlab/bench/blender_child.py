"""The Blender side of the EEVEE and Cycles peers: runs as a script in a Python that has bpy
(``python blender_child.py``, started by skinlab/bench/blender_peer.py), never imported by Skinlab.
It imports bpy, numpy and the standard library only, so it runs in an environment of its own (bpy
5.0 needs numpy < 2; Skinlab's has numpy 2).

Why a child process: bpy is Blender, one per process, with process-global state (its scene data,
its GPU backend's EGL context, which would take the current context from under moderngl in the
same process, as pyrender would) and no way to reset it; a crash in it should end a measurement,
not the test session or the ledger run.

Protocol: one JSON object per line on stdin, one JSON reply per line on the file descriptor that
was stdout (everything Blender prints goes to stderr):

* ``{"cmd": "load", "spec": PATH}``: build the scene of a spec (blender_scene.save_spec);
* ``{"cmd": "readback", "out": PATH}``: write what bpy holds (meshes, normals, UVs, camera, lights,
  material inputs, render settings) to an .npz, for the mapping test;
* ``{"cmd": "render", "engine": "eevee" | "cycles", "spp": N, "method": RANDOM_WALK | RANDOM_WALK_SKIN,
  "size": [W, H], "frames": K, "image": PATH | null, "seed": S}``: render ``image`` (OpenEXR, linear
  RGBA, alpha = coverage) if given, timed on its own, then K frames without writing, each timed
  (wall time of ``bpy.ops.render.render``); the reply has ``image_ms`` and ``frames_ms``;
* ``{"cmd": "quit"}`` (or end of input).
"""

from __future__ import annotations

import json
import math
import os
import sys
import time

import numpy as np

ENGINES = {"eevee": "BLENDER_EEVEE", "cycles": "CYCLES"}


def load_spec(path: str) -> tuple[dict, list[dict]]:
    with np.load(path) as z:
        header = json.loads(bytes(z["header"]).decode())
        arrays = []
        for i in range(len(header["objects"])):
            arrays.append(
                {k: z[f"obj{i}_{k}"] for k in ("positions", "normals", "faces", "uvs", "texture") if f"obj{i}_{k}" in z}
            )
        if header.get("environment") is not None:
            header["environment_pixels"] = np.asarray(z["environment"], np.float32)
    return header, arrays


def _matrix(m):
    from mathutils import Matrix

    return Matrix([list(r) for r in m])


def _mesh(bpy, name: str, a: dict):
    pos = np.asarray(a["positions"], np.float32)
    faces = np.asarray(a["faces"], np.int32)
    me = bpy.data.meshes.new(name)
    me.vertices.add(len(pos))
    me.vertices.foreach_set("co", pos.ravel())
    me.loops.add(3 * len(faces))
    me.loops.foreach_set("vertex_index", faces.ravel())
    me.polygons.add(len(faces))
    me.polygons.foreach_set("loop_start", np.arange(0, 3 * len(faces), 3, dtype=np.int32))
    if "uvs" in a:
        uv = me.uv_layers.new(name="UVMap")
        uv.data.foreach_set("uv", np.asarray(a["uvs"], np.float32)[faces.ravel()].ravel())
    me.update()
    me.shade_smooth()
    me.normals_split_custom_set_from_vertices([tuple(n) for n in np.asarray(a["normals"], np.float64)])
    return me


def _socket(node, name: str):
    """An input by name; ``node.inputs[name]`` misses sockets its current mode hides (Subsurface IOR)."""
    for s in node.inputs:
        if s.name == name:
            return s
    raise KeyError(f"{node.name}: no input {name!r}")


def _material(bpy, spec: dict, texture):
    mat = bpy.data.materials.new(spec["name"])
    mat.use_nodes = True
    node = mat.node_tree.nodes["Principled BSDF"]
    for k, v in spec["inputs"].items():
        _socket(node, k).default_value = v
    if texture is not None:
        h, w = texture.shape[:2]
        img = bpy.data.images.new(f"{spec['name']}-base", w, h, float_buffer=True)
        img.colorspace_settings.name = "Linear Rec.709"
        rgba = np.concatenate([texture[::-1], np.ones((h, w, 1), np.float32)], axis=2)  # Blender: bottom row first
        img.pixels.foreach_set(rgba.astype(np.float32).ravel())
        tex = mat.node_tree.nodes.new("ShaderNodeTexImage")
        tex.image = img
        mat.node_tree.links.new(tex.outputs["Color"], node.inputs["Base Color"])
    return mat


def build(bpy, header: dict, arrays: list[dict]) -> None:
    bpy.ops.wm.read_factory_settings(use_empty=True)
    sc = bpy.context.scene
    sc.render.resolution_x, sc.render.resolution_y = header["width"], header["height"]
    sc.render.resolution_percentage = 100
    sc.render.film_transparent = True  # alpha = coverage, the background hidden (as the truth's)
    sc.view_settings.view_transform = "Standard"  # linear EXR either way; no AgX look in any preview
    sc.render.image_settings.file_format = "OPEN_EXR"
    sc.render.image_settings.color_depth = "32"
    sc.render.image_settings.color_mode = "RGBA"
    for o, a in zip(header["objects"], arrays):
        me = _mesh(bpy, o["name"], a)
        me.materials.append(_material(bpy, o["material"], a.get("texture")))
        ob = bpy.data.objects.new(o["name"], me)
        sc.collection.objects.link(ob)
    cam = bpy.data.cameras.new("camera")
    cam.sensor_fit = "VERTICAL"
    cam.angle_y = math.radians(header["camera"]["fov_y_deg"])
    cam.clip_start, cam.clip_end = header["camera"]["clip"]
    co = bpy.data.objects.new("camera", cam)
    co.matrix_world = _matrix(header["camera"]["matrix"])
    sc.collection.objects.link(co)
    sc.camera = co
    for light in header["lights"]:
        ld = bpy.data.lights.new(light["name"], light["type"])
        ld.color = light["color"]
        ld.energy = light["strength"]
        if light["type"] == "SUN":
            ld.angle = light["angle"]
        elif light["type"] == "AREA":
            ld.shape = light["shape"]
            ld.size, ld.size_y = light["size"], light["size_y"]
        else:  # POINT (a sphere where it has a radius) and SPOT
            ld.shadow_soft_size = light.get("radius", 0.0)
            ld.use_soft_falloff = False
            if light["type"] == "SPOT":
                ld.spot_size, ld.spot_blend = light["spot_size"], light["spot_blend"]
        lo = bpy.data.objects.new(light["name"], ld)
        lo.matrix_world = _matrix(light["matrix"])
        lo.visible_camera = False  # as the truth's hidden emitters (a sphere or rect in view is not drawn)
        sc.collection.objects.link(lo)
    sc.world = _world(bpy, header)


def _world(bpy, header: dict):
    """The ambient as the Background's colour; an environment map as an Environment Texture of its pixels
    (read at the Mapping node's turn of the world direction) on a second Background, the two added."""
    world = bpy.data.worlds.new("world")
    world.use_nodes = True
    nodes, links = world.node_tree.nodes, world.node_tree.links
    bg = nodes["Background"]
    bg.inputs["Color"].default_value = [*(header["world"] or [0.0, 0.0, 0.0]), 1.0]
    bg.inputs["Strength"].default_value = 1.0
    env = header.get("environment")
    if env is None:
        return world
    px = header["environment_pixels"]
    h, w = px.shape[:2]
    img = bpy.data.images.new("environment", w, h, float_buffer=True)
    img.colorspace_settings.name = "Linear Rec.709"
    rgba = np.concatenate([px[::-1], np.ones((h, w, 1), np.float32)], axis=2)  # Blender: bottom row first
    img.pixels.foreach_set(rgba.astype(np.float32).ravel())
    coords = nodes.new("ShaderNodeTexCoord")  # Generated, in a world: the direction, in world axes
    mapping = nodes.new("ShaderNodeMapping")
    mapping.vector_type = "VECTOR"
    mapping.inputs["Rotation"].default_value = env["rotation_euler"]
    tex = nodes.new("ShaderNodeTexEnvironment")
    tex.image, tex.projection, tex.interpolation = img, "EQUIRECTANGULAR", "Linear"
    sky = nodes.new("ShaderNodeBackground")
    sky.name = "Environment"
    sky.inputs["Strength"].default_value = env["strength"]
    add = nodes.new("ShaderNodeAddShader")
    links.new(coords.outputs["Generated"], mapping.inputs["Vector"])
    links.new(mapping.outputs["Vector"], tex.inputs["Vector"])
    links.new(tex.outputs["Color"], sky.inputs["Color"])
    links.new(bg.outputs["Background"], add.inputs[0])
    links.new(sky.outputs["Background"], add.inputs[1])
    links.new(add.outputs["Shader"], nodes["World Output"].inputs["Surface"])
    return world


def configure(bpy, header: dict, req: dict) -> None:
    """Engine, samples, size and subsurface method of one render request."""
    sc = bpy.context.scene
    sc.render.engine = ENGINES[req["engine"]]
    w, h = req.get("size") or (header["width"], header["height"])
    sc.render.resolution_x, sc.render.resolution_y = int(w), int(h)
    method = req.get("method", "RANDOM_WALK")
    for o in header["objects"]:
        sss = o["material"].get("subsurface")
        if not sss:
            continue
        node = bpy.data.objects[o["name"]].data.materials[0].node_tree.nodes["Principled BSDF"]
        node.subsurface_method = method
        for k, v in sss[method].items():
            _socket(node, k).default_value = v
    if req["engine"] == "cycles":
        cy = sc.cycles
        cy.device = "CPU"
        cy.samples = int(req["spp"])
        cy.use_adaptive_sampling = False
        cy.use_denoising = False
        cy.seed = int(req.get("seed", 0))
        cy.sample_clamp_direct = 0.0  # no clamping: an unbiased estimate, like the truth's
        cy.sample_clamp_indirect = 0.0
        cy.pixel_filter_type = "BOX"  # each pixel the mean over its area, as the truth's box filter
        cy.filter_width = 1.0
        for k in ("max_bounces", "diffuse_bounces", "glossy_bounces", "transmission_bounces"):
            setattr(cy, k, 64)
    else:
        sc.eevee.taa_render_samples = int(req["spp"])  # everything else at EEVEE's defaults


def render(bpy, header: dict, req: dict) -> dict:
    configure(bpy, header, req)
    sc = bpy.context.scene
    out = {"engine": req["engine"], "spp": int(req["spp"]), "size": [sc.render.resolution_x, sc.render.resolution_y]}
    if req.get("image"):
        sc.render.filepath = req["image"]
        t0 = time.perf_counter()
        bpy.ops.render.render(write_still=True)
        out["image_ms"] = (time.perf_counter() - t0) * 1e3
    times = []
    for _ in range(int(req.get("frames", 0))):
        t0 = time.perf_counter()
        bpy.ops.render.render(write_still=False)
        times.append((time.perf_counter() - t0) * 1e3)
    out["frames_ms"] = times
    return out


def _get(coll, attr: str, n: int, width: int) -> np.ndarray:
    buf = np.zeros(n * width, np.float32)
    coll.foreach_get(attr, buf)
    return buf.reshape(n, width) if width > 1 else buf


def readback(bpy, path: str) -> None:
    """What bpy holds, as arrays and a JSON header (read back without rendering)."""
    sc = bpy.context.scene
    arrays, info = {}, {"objects": [], "lights": []}
    for ob in sc.objects:
        if ob.type == "MESH":
            me = ob.data
            nl = len(me.loops)
            loops = np.zeros(nl, np.int32)
            me.loops.foreach_get("vertex_index", loops)
            arrays[f"{ob.name}_positions"] = _get(me.vertices, "co", len(me.vertices), 3)
            arrays[f"{ob.name}_corners"] = loops
            arrays[f"{ob.name}_corner_normals"] = _get(me.corner_normals, "vector", nl, 3)
            if me.uv_layers:
                arrays[f"{ob.name}_uvs"] = _get(me.uv_layers[0].data, "uv", nl, 2)
            node = me.materials[0].node_tree.nodes["Principled BSDF"]
            inputs = {}
            for s in node.inputs:
                v = getattr(s, "default_value", None)
                if isinstance(v, (int, float)):
                    inputs[s.name] = float(v)
                elif v is not None and hasattr(v, "__len__"):
                    inputs[s.name] = [float(x) for x in v]
            linked = [s.name for s in node.inputs if s.is_linked]
            info["objects"].append(
                {
                    "name": ob.name,
                    "material": me.materials[0].name,
                    "inputs": inputs,
                    "linked": linked,
                    "subsurface_method": node.subsurface_method,
                    "matrix_world": [list(r) for r in ob.matrix_world],
                }
            )
        elif ob.type == "CAMERA":
            c = ob.data
            info["camera"] = {
                "matrix_world": [list(r) for r in ob.matrix_world],
                "angle_y": c.angle_y,
                "sensor_fit": c.sensor_fit,
                "clip": [c.clip_start, c.clip_end],
            }
        elif ob.type == "LIGHT":
            ld = ob.data
            info["lights"].append(
                {
                    "name": ob.name,
                    "type": ld.type,
                    "energy": ld.energy,
                    "color": list(ld.color),
                    "angle": getattr(ld, "angle", 0.0),
                    "radius": getattr(ld, "shadow_soft_size", 0.0),
                    "soft_falloff": getattr(ld, "use_soft_falloff", None),
                    "spot_size": getattr(ld, "spot_size", None),
                    "spot_blend": getattr(ld, "spot_blend", None),
                    "shape": getattr(ld, "shape", None),
                    "size": [getattr(ld, "size", 0.0), getattr(ld, "size_y", 0.0)],
                    "visible_camera": ob.visible_camera,
                    "matrix_world": [list(r) for r in ob.matrix_world],
                }
            )
    nodes = sc.world.node_tree.nodes
    info["world"] = list(nodes["Background"].inputs["Color"].default_value)[:3]
    if "Environment" in nodes:
        from mathutils import Euler

        sky = nodes["Environment"]
        tex = sky.inputs["Color"].links[0].from_node
        mapping = tex.inputs["Vector"].links[0].from_node
        rot = mapping.inputs["Rotation"].default_value
        img = tex.image
        info["environment"] = {
            "strength": sky.inputs["Strength"].default_value,
            "projection": tex.projection,
            "vector_type": mapping.vector_type,
            "coordinates": mapping.inputs["Vector"].links[0].from_socket.name,
            "matrix": [list(r) for r in Euler(rot, "XYZ").to_matrix()],  # Blender's own Euler -> matrix
            "size": list(img.size),
            "colorspace": img.colorspace_settings.name,
            "output": nodes["World Output"].inputs["Surface"].links[0].from_node.bl_idname,
        }
        px = np.zeros(img.size[0] * img.size[1] * 4, np.float32)
        img.pixels.foreach_get(px)
        arrays["environment"] = px.reshape(img.size[1], img.size[0], 4)[::-1, :, :3]  # row 0 at the top
    info["render"] = {
        "size": [sc.render.resolution_x, sc.render.resolution_y],
        "film_transparent": sc.render.film_transparent,
        "version": bpy.app.version_string,
    }
    arrays["header"] = np.frombuffer(json.dumps(info).encode(), np.uint8)
    with open(path, "wb") as fh:
        np.savez(fh, **arrays)


def main() -> int:
    proto = os.fdopen(os.dup(1), "w", buffering=1)
    os.dup2(2, 1)  # Blender's own output (render progress) goes to stderr, never into the replies
    t0 = time.perf_counter()
    import bpy

    proto.write(
        json.dumps({"ready": True, "version": bpy.app.version_string, "import_ms": (time.perf_counter() - t0) * 1e3})
        + "\n"
    )
    header = None
    for line in sys.stdin:
        if not line.strip():
            break
        req = json.loads(line)
        try:
            if req["cmd"] == "quit":
                break
            if req["cmd"] == "load":
                t0 = time.perf_counter()
                header, arrays = load_spec(req["spec"])
                build(bpy, header, arrays)
                reply = {"ok": True, "build_ms": (time.perf_counter() - t0) * 1e3}
            elif header is None:
                raise RuntimeError(f"{req['cmd']!r} before a scene was loaded")
            elif req["cmd"] == "readback":
                readback(bpy, req["out"])
                reply = {"ok": True}
            elif req["cmd"] == "render":
                reply = {"ok": True, **render(bpy, header, req)}
            else:
                raise ValueError(f"unknown command {req['cmd']!r}")
        except Exception as exc:  # the parent raises it with the message
            reply = {"ok": False, "error": f"{type(exc).__name__}: {exc}"}
        proto.write(json.dumps(reply) + "\n")
    proto.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
