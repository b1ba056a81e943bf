"""A scene as glTF 2.0 (``skinlab export-gltf``, :func:`export_gltf`): its meshes, materials with the
extensions skinlab/scene/gltf_materials.py reads (the inverse of that mapping, docs/scenes.md), lights
(KHR_lights_punctual) and camera, in one .glb (or a .gltf with its buffer embedded).

Every mesh node becomes a root node with its world matrix. A subsurface material is written as
KHR_materials_volume + KHR_materials_volume_scatter + KHR_materials_diffuse_transmission: the multi-scatter
colour is ``subsurface_color``, the weight the diffuse transmission factor, and the extinction of Skinlab's
medium goes into attenuationDistance / attenuationColor so that reading the file back gives the same
radius (sigma_t from the reduced mean free path and g; sigma_a = sigma_t (1 - rho_ss) with van de Hulst's
rho_ss; attenuationDistance d = 1 / max sigma_t, attenuationColor = exp(-sigma_a d)). What glTF has no
place for (``sss_model``, the subsurface weight and radius maps) goes into the material's
``extras.skinlab``, which the importer reads back.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from .graph import CameraNode, LightNode, MeshNode, Scene
from .materials import Material

_IDENTITY_TT = ((0.0, 0.0), (1.0, 1.0), 0.0)


class _Writer:
    def __init__(self, scene: Scene):
        import pygltflib

        self.p = pygltflib
        self.scene = scene
        self.g = pygltflib.GLTF2(scene=0, scenes=[pygltflib.Scene(nodes=[])], asset=pygltflib.Asset(
            version="2.0", generator="Skinlab"))  # fmt: skip
        self.blob = bytearray()
        self.used: set[str] = set()
        self.images: dict[str, int] = {}  # file -> texture index
        self.materials: dict[int, int] = {}
        self.warnings: list[str] = []

    # -- buffers ---------------------------------------------------------------------------------
    def view(self, data: bytes, target=None) -> int:
        while len(self.blob) % 4:
            self.blob += b"\0"
        self.g.bufferViews.append(
            self.p.BufferView(buffer=0, byteOffset=len(self.blob), byteLength=len(data), target=target)
        )
        self.blob += data
        return len(self.g.bufferViews) - 1

    def accessor(self, a: np.ndarray, kind: str, component, target=None, bounds: bool = False) -> int:
        a = np.ascontiguousarray(a)
        acc = self.p.Accessor(
            bufferView=self.view(a.tobytes(), target), componentType=component, count=len(a), type=kind
        )
        if bounds:
            acc.min, acc.max = a.min(0).astype(float).tolist(), a.max(0).astype(float).tolist()
        self.g.accessors.append(acc)
        return len(self.g.accessors) - 1

    def texture(self, path: Path) -> int:
        """The image file embedded as it is (PNG/JPEG), else re-encoded as PNG."""
        key = str(Path(path).resolve())
        if key not in self.images:
            data, mime = _image_bytes(Path(path))
            self.g.images.append(self.p.Image(bufferView=self.view(data), mimeType=mime))
            self.g.textures.append(self.p.Texture(source=len(self.g.images) - 1))
            self.images[key] = len(self.g.textures) - 1
        return self.images[key]

    def texture_info(self, path, m: Material, **extra) -> dict:
        info = {"index": self.texture(path), **extra}
        tt = (tuple(m["uv_offset"]), tuple(m["uv_scale"]), float(m["uv_rotation"]))
        if tt != _IDENTITY_TT:
            info["extensions"] = {"KHR_texture_transform": {"offset": list(tt[0]), "scale": list(tt[1]),
                                                             "rotation": tt[2]}}  # fmt: skip
            self.used.add("KHR_texture_transform")
        return info

    # -- materials -------------------------------------------------------------------------------
    def material(self, m: Material) -> int:
        if id(m) in self.materials:
            return self.materials[id(m)]
        v = m.values
        pbr: dict = {
            "baseColorFactor": [*map(float, v["base_color"]), float(v["alpha"])],
            "metallicFactor": float(v["metallic"]),
            "roughnessFactor": float(v["roughness"]),
        }
        out: dict = {"name": m.name, "doubleSided": True, "alphaMode": v["alpha_mode"].upper()}
        if v["alpha_mode"] == "mask":
            out["alphaCutoff"] = float(v["alpha_cutoff"])
        if v["base_color_map"] is not None:
            pbr["baseColorTexture"] = self.texture_info(v["base_color_map"], m)
        mr = _metallic_roughness_map(v)
        if mr is not None:
            pbr["metallicRoughnessTexture"] = self.texture_info(mr, m)
        out["pbrMetallicRoughness"] = pbr
        if v["normal_map"] is not None:
            out["normalTexture"] = self.texture_info(v["normal_map"], m, scale=float(v["normal_scale"]))
        if v["occlusion_map"] is not None:
            out["occlusionTexture"] = self.texture_info(v["occlusion_map"], m, strength=float(v["occlusion_strength"]))
        if v["emissive_map"] is not None:
            out["emissiveTexture"] = self.texture_info(v["emissive_map"], m)
        ext: dict = {}
        emissive = np.asarray(v["emissive"], np.float64)
        strength = float(emissive.max()) if emissive.max() > 1.0 else 1.0
        out["emissiveFactor"] = (emissive / strength).tolist()
        if strength != 1.0:
            ext["KHR_materials_emissive_strength"] = {"emissiveStrength": strength}
        f0 = 0.08 * float(v["specular"])
        s = math.sqrt(f0)
        ext["KHR_materials_ior"] = {"ior": (1.0 + s) / (1.0 - s)}
        extras = {"sss_model": v["sss_model"]}
        for key in ("subsurface_map", "subsurface_radius_map"):
            if v[key] is not None:
                extras[key] = self.texture(v[key])
        if v["subsurface"] > 0:
            ext.update(self._volume(m))
        elif v["diffuse_transmission"] > 0:
            ext["KHR_materials_diffuse_transmission"] = {
                "diffuseTransmissionFactor": float(v["diffuse_transmission"]),
                "diffuseTransmissionColorFactor": list(map(float, v["diffuse_transmission_color"])),
            }
        if ext:
            out["extensions"] = ext
            self.used.update(ext)
        out["extras"] = {"skinlab": extras}
        self.g.materials.append(self.p.Material(**_pygltf_material(self.p, out)))
        self.materials[id(m)] = len(self.g.materials) - 1
        return self.materials[id(m)]

    def _volume(self, m: Material) -> dict:
        """KHR_materials_volume + KHR_materials_volume_scatter + diffuse transmission for a subsurface material."""
        from .optics.material_medium import subsurface_albedo
        from .optics.similarity import van_de_hulst_albedo

        v = m.values
        g = float(v["subsurface_scatter_anisotropy"])
        colour = np.asarray(v["subsurface_color"], np.float64)
        rho = van_de_hulst_albedo(subsurface_albedo(v), g)  # the medium's: x the colour map's mean
        reduced = 4.0 * math.pi * self.scene.mm_per_unit / np.maximum(np.asarray(v["subsurface_radius"]), 1e-12)
        sigma_t = reduced / (1.0 - rho * g)  # 1 / scene unit
        sigma_a = sigma_t * (1.0 - rho)
        white = rho >= 1.0 - 1e-12  # no absorption: the importer reads 1 / attenuationDistance there
        d = 1.0 / float(sigma_t[white][0] if white.any() else sigma_t.max())
        if white.sum() > 1 and np.ptp(sigma_t[white]) > 1e-9 * sigma_t[white].max():
            self.warnings.append(
                f"material {m.name!r}: channels of subsurface colour 1 with different radii share one "
                "attenuationDistance in glTF; their radii change"
            )
        return {
            "KHR_materials_volume": {
                "thicknessFactor": 1.0,
                "attenuationDistance": d,
                "attenuationColor": np.exp(-sigma_a * d).tolist(),
            },
            "KHR_materials_volume_scatter": self._scatter(m, colour, g),
            "KHR_materials_diffuse_transmission": {"diffuseTransmissionFactor": float(v["subsurface"])},
        }

    def _scatter(self, m: Material, colour: np.ndarray, g: float) -> dict:
        out = {"multiscatterColorFactor": colour.tolist(), "scatterAnisotropy": g}
        if m["base_color_map"] is not None:  # the colour rule: the map multiplies the subsurface colour too
            out["multiscatterColorTexture"] = self.texture_info(m["base_color_map"], m)
        return out

    # -- nodes -----------------------------------------------------------------------------------
    def mesh(self, node: MeshNode) -> None:
        mesh = node.mesh
        p = self.p
        attrs = p.Attributes(
            POSITION=self.accessor(mesh.positions.astype(np.float32), "VEC3", p.FLOAT, p.ARRAY_BUFFER, bounds=True),
            NORMAL=self.accessor(mesh.normals.astype(np.float32), "VEC3", p.FLOAT, p.ARRAY_BUFFER),
        )
        if mesh.uvs is not None:  # glTF's convention: v = 0 at the image's top
            uv = np.column_stack([mesh.uvs[:, 0], 1.0 - mesh.uvs[:, 1]]).astype(np.float32)
            attrs.TEXCOORD_0 = self.accessor(uv, "VEC2", p.FLOAT, p.ARRAY_BUFFER)
        if mesh.colors is not None:
            attrs.COLOR_0 = self.accessor(mesh.colors.astype(np.float32), "VEC4", p.FLOAT, p.ARRAY_BUFFER)
        prim = p.Primitive(
            attributes=attrs,
            indices=self.accessor(
                mesh.indices.reshape(-1).astype(np.uint32), "SCALAR", p.UNSIGNED_INT, p.ELEMENT_ARRAY_BUFFER
            ),  # fmt: skip
            material=self.material(node.material),
        )
        self.g.meshes.append(p.Mesh(name=node.name, primitives=[prim]))
        self.node(p.Node(name=node.name, mesh=len(self.g.meshes) - 1, matrix=_matrix(node.world_matrix)))

    def node(self, n) -> None:
        self.g.nodes.append(n)
        self.g.scenes[0].nodes.append(len(self.g.nodes) - 1)

    def light(self, light: LightNode) -> None:
        """A directional, point or spot light as KHR_lights_punctual (colour, intensity, the spot's cone
        half-angles; the node's -Z is the direction, as Skinlab's). Area lights have no glTF form: the
        caller leaves them out (:func:`export_gltf` names them in its warning)."""
        assert not light.is_area, light.kind
        lights = self.g.extensions.setdefault("KHR_lights_punctual", {"lights": []})["lights"]
        kind = light.kind
        colour = np.asarray(light.color, float).tolist()
        entry = {"name": light.name, "type": kind, "color": colour, "intensity": float(light.intensity)}
        if kind == "spot":
            entry["spot"] = {
                "innerConeAngle": math.radians(light.inner_deg),
                "outerConeAngle": math.radians(light.outer_deg),
            }
        lights.append(entry)
        self.used.add("KHR_lights_punctual")
        n = self.p.Node(name=light.name, matrix=_matrix(light.world_matrix))
        n.extensions = {"KHR_lights_punctual": {"light": len(lights) - 1}}
        self.node(n)

    def camera(self, cam: CameraNode, aspect: float | None) -> None:
        persp = self.p.Perspective(
            yfov=float(cam.yfov), znear=float(cam.znear), zfar=float(cam.zfar), aspectRatio=aspect
        )
        self.g.cameras.append(self.p.Camera(type="perspective", perspective=persp, name=cam.name))
        self.node(self.p.Node(name=cam.name, camera=len(self.g.cameras) - 1, matrix=_matrix(cam.world_matrix)))

    def save(self, path: Path) -> Path:
        from skinlab.atomic_write import atomic_path

        self.g.buffers = [self.p.Buffer(byteLength=len(self.blob))]
        self.g.extensionsUsed = sorted(self.used)
        self.g.set_binary_blob(bytes(self.blob))
        with atomic_path(path) as tmp:
            if path.suffix.lower() == ".glb":
                self.g.save_binary(str(tmp))
            else:
                self.g.convert_buffers(self.p.BufferFormat.DATAURI)
                self.g.save_json(str(tmp))
        return path


def _pygltf_material(p, d: dict) -> dict:
    """Dict fields as pygltflib's objects where it wants them."""
    out = dict(d)
    pbr = dict(out.pop("pbrMetallicRoughness"))
    for k in ("baseColorTexture", "metallicRoughnessTexture"):
        if k in pbr:
            pbr[k] = p.TextureInfo(**pbr[k])
    out["pbrMetallicRoughness"] = p.PbrMetallicRoughness(**pbr)
    if "normalTexture" in out:
        out["normalTexture"] = p.NormalMaterialTexture(**out["normalTexture"])
    if "occlusionTexture" in out:
        out["occlusionTexture"] = p.OcclusionTextureInfo(**out["occlusionTexture"])
    if "emissiveTexture" in out:
        out["emissiveTexture"] = p.TextureInfo(**out["emissiveTexture"])
    return out


def _matrix(m: np.ndarray) -> list[float]:
    return [float(x) for x in np.asarray(m, np.float64).T.reshape(-1)]  # glTF: column-major


def _image_bytes(path: Path) -> tuple[bytes, str]:
    head = path.read_bytes()[:8]
    if head.startswith(b"\x89PNG"):
        return path.read_bytes(), "image/png"
    if head.startswith(b"\xff\xd8"):
        return path.read_bytes(), "image/jpeg"
    from .textures import load_texture

    img = load_texture(path, "linear")
    return _png16(img[..., : min(img.shape[2], 4)]), "image/png"


def _png16(img: np.ndarray) -> bytes:
    import io

    from PIL import Image

    a = np.clip(img, 0.0, 1.0)
    buf = io.BytesIO()
    if a.ndim == 2 or a.shape[2] == 1:
        Image.fromarray(np.round(a.reshape(a.shape[:2]) * 65535).astype(np.uint16)).save(buf, format="PNG")
    else:
        Image.fromarray(np.round(a * 255).astype(np.uint8)).save(buf, format="PNG")
    return buf.getvalue()


def _metallic_roughness_map(v: dict) -> Path | None:
    """roughness_map (R) -> G and metallic_map (R) -> B of one texture, cached by content (the importer
    splits it again); a map of one alone gets 1 in the other's channel."""
    rough, metal = v.get("roughness_map"), v.get("metallic_map")
    if rough is None and metal is None:
        return None
    import hashlib

    from .gltf_materials import cache_root
    from .textures import load_texture

    maps = [load_texture(p, "linear")[..., 0] if p is not None else None for p in (rough, metal)]
    shape = next(m.shape for m in maps if m is not None)
    if any(m is not None and m.shape != shape for m in maps):
        raise ValueError(
            f"roughness_map and metallic_map have different sizes ({rough}, {metal}): glTF packs them in one"
        )
    g_, b_ = (m if m is not None else np.ones(shape, np.float32) for m in maps)
    rgb = np.stack([np.zeros(shape, np.float32), g_, b_], axis=-1)
    data = _png16(rgb)
    path = cache_root() / f"{hashlib.sha256(data).hexdigest()[:32]}-mr.png"
    if not path.is_file():
        from skinlab.atomic_write import write_bytes_atomic

        write_bytes_atomic(path, data)
    return path


def export_gltf(scene: Scene, path: str | Path, aspect: float | None = None) -> tuple[Path, list[str]]:
    """Write `scene` as .glb or .gltf; returns the path and what could not be written exactly."""
    path = Path(path)
    if path.suffix.lower() not in (".glb", ".gltf"):
        raise ValueError(f"{path}: expected a .glb or .gltf path")
    w = _Writer(scene)
    for node in scene.mesh_nodes(visible_only=True):
        w.mesh(node)
    left_out = []
    for light in scene.lights():
        if light.is_area:
            left_out.append(f"the {light.kind} light {light.name!r}")
        else:
            w.light(light)
    env = scene.environment
    if env.map is not None:
        left_out.append(
            f"the environment map {Path(env.map).name} (rotation {float(env.rotation_deg):g} deg, intensity "
            f"{float(env.intensity):g}{', shown behind the scene' if env.show_background else ''})"
        )
    if left_out:  # one warning for all of it
        w.warnings.append(
            "not written, glTF has no form for them (KHR_lights_punctual holds directional, point and spot "
            "lights only): " + ", ".join(left_out)
        )
    if scene.camera is not None:
        w.camera(scene.camera, aspect)
    return w.save(path), w.warnings
