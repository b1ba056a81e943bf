"""A path-traced reference's scene as a Mitsuba 3 scene file (``skinlab reference --export-xml DIR``):
``DIR/scene.xml`` with its meshes as binary PLY files (``DIR/meshes/``) and baked textures as EXR
(``DIR/textures/``), so that Mitsuba alone renders what ``skinlab reference`` renders:

    mitsuba -o image.exr DIR/scene.xml        # or mitsuba.load_file("DIR/scene.xml") in Python

It is written from the same :class:`~skinlab.truth.description.ReferenceDescription` the reference renders
(integrator, sensor, emitters, shapes with their BSDFs and interior media), so the two cannot drift apart:
each dictionary of the description becomes the XML element of the same plugin
(:func:`dict_to_xml`). The reference frame is millimetres, centred on the media (skinlab/truth/export.py).
"""

from __future__ import annotations

from pathlib import Path
from xml.sax.saxutils import quoteattr

import numpy as np

from .description import ReferenceDescription, ShapeDesc

_PLUGIN_TAGS = {
    # the keys under which the description nests plugins -> the XML tag of that plugin
    "bsdf": "bsdf",
    "interior": "medium",
    "exterior": "medium",
    "phase": "phase",
    "emitter": "emitter",
    "base_color": "texture",
    "reflectance": "texture",
    "opacity": "texture",
    "bsdf_0": "bsdf",
    "bsdf_1": "bsdf",
    "albedo": "texture",
    "sigma_t": "texture",
}


def _float(x) -> str:
    return repr(float(x))


def _value(name: str, v, indent: str) -> list[str]:
    """One property as XML lines."""
    if isinstance(v, dict):
        if v.get("type") == "rgb":
            rgb = ", ".join(_float(x) for x in v["value"])
            return [f'{indent}<rgb name="{name}" value="{rgb}"/>']
        return dict_to_xml(v, _PLUGIN_TAGS.get(name, "bsdf"), name, indent)
    if isinstance(v, bool):
        return [f'{indent}<boolean name="{name}" value="{"true" if v else "false"}"/>']
    if isinstance(v, int | np.integer):
        return [f'{indent}<integer name="{name}" value="{int(v)}"/>']
    if isinstance(v, float | np.floating):
        return [f'{indent}<float name="{name}" value="{_float(v)}"/>']
    if isinstance(v, str):
        return [f"{indent}<string name={quoteattr(name)} value={quoteattr(v)}/>"]
    raise ValueError(f"Mitsuba XML: no element for {name} = {v!r}")


def dict_to_xml(d: dict, tag: str, name: str | None = None, indent: str = "    ") -> list[str]:
    """A Mitsuba plugin dictionary (``{"type": ..., property: value, nested plugin: {...}}``) as XML."""
    attrs = f' type="{d["type"]}"' + (f' name="{name}"' if name and tag in ("texture", "bsdf") else "")
    if tag in ("medium",) and name:
        attrs += f' name="{name}"'
    body = []
    for k, v in d.items():
        if k == "type":
            continue
        body += _value(k, v, indent + "    ")
    if not body:
        return [f"{indent}<{tag}{attrs}/>"]
    return [f"{indent}<{tag}{attrs}>", *body, f"{indent}</{tag}>"]


def _matrix(m: np.ndarray, indent: str) -> list[str]:
    vals = " ".join(_float(x) for x in np.asarray(m, np.float64).reshape(-1))
    return [f'{indent}<transform name="to_world">', f'{indent}    <matrix value="{vals}"/>', f"{indent}</transform>"]


def write_ply(path: Path, s: ShapeDesc) -> None:
    """A binary little-endian PLY with positions, normals, texture coordinates (if any), triangles."""
    pos = np.ascontiguousarray(s.positions, np.float32)
    nrm = np.ascontiguousarray(s.normals, np.float32)
    cols = [pos, nrm]
    props = ["x", "y", "z", "nx", "ny", "nz"]
    if s.texcoords is not None:
        cols.append(np.ascontiguousarray(s.texcoords, np.float32))
        props += ["u", "v"]
    verts = np.concatenate(cols, axis=1).astype("<f4")
    faces = np.ascontiguousarray(s.faces, np.uint32)
    header = ["ply", "format binary_little_endian 1.0", f"element vertex {len(verts)}"]
    header += [f"property float {p}" for p in props]
    header += [f"element face {len(faces)}", "property list uchar uint vertex_indices", "end_header"]
    rec = np.empty(len(faces), dtype=[("n", "u1"), ("i", "<u4", (3,))])
    rec["n"], rec["i"] = 3, faces
    from skinlab.atomic_write import atomic_path

    with atomic_path(path) as tmp, open(tmp, "wb") as f:
        f.write(("\n".join(header) + "\n").encode("ascii"))
        f.write(verts.tobytes())
        f.write(rec.tobytes())


def _emitter(e: dict, indent: str) -> list[str]:
    i2 = indent + "    "
    rgb = lambda name, v: f'{i2}<rgb name="{name}" value="{", ".join(_float(x) for x in v)}"/>'  # noqa: E731
    if e["kind"] == "directional":
        towards = ", ".join(_float(x) for x in e["direction"])
        return [f'{indent}<emitter type="directional">', f'{i2}<vector name="direction" value="{towards}"/>',
                rgb("irradiance", e["irradiance"]), f"{indent}</emitter>"]  # fmt: skip
    if e["kind"] == "point":
        at = ", ".join(_float(x) for x in e["position"])
        return [f'{indent}<emitter type="point">', f'{i2}<point name="position" value="{at}"/>',
                rgb("intensity", e["intensity"]), f"{indent}</emitter>"]  # fmt: skip
    if e["kind"] == "constant":
        return [f'{indent}<emitter type="constant">', rgb("radiance", e["radiance"]), f"{indent}</emitter>"]
    if e["kind"] == "sun_disk":
        c, n, r = np.asarray(e["centre"]), np.asarray(e["normal"]), float(e["radius"])
        up = [0.0, 0.0, 1.0] if abs(n[1]) > 0.9 else [0.0, 1.0, 0.0]
        j = ", ".join
        return [
            f'{indent}<shape type="disk">',
            f'{i2}<transform name="to_world">',
            f'{i2}    <scale value="{_float(r)}"/>',
            f'{i2}    <lookat origin="{j(map(_float, c))}" target="{j(map(_float, c + n))}" '
            f'up="{j(map(_float, up))}"/>',
            f"{i2}</transform>",
            f'{i2}<emitter type="area">',
            f'{i2}    <rgb name="radiance" value="{j(map(_float, e["radiance"]))}"/>',
            f"{i2}</emitter>",
            f"{indent}</shape>",
        ]
    j = ", ".join
    if e["kind"] == "envmap":  # the pixels are written beside the XML (write_mitsuba_xml)
        return [
            f'{indent}<emitter type="envmap">',
            f'{i2}<string name="filename" value="{e["file"]}"/>',
            f'{i2}<float name="scale" value="{_float(e["scale"])}"/>',
            f'{i2}<transform name="to_world"><rotate y="1" angle="{_float(e["rotation_deg"])}"/></transform>',
            f"{indent}</emitter>",
        ]
    if e["kind"] == "spot":
        p, d = np.asarray(e["position"]), np.asarray(e["direction"])
        up = [0.0, 0.0, 1.0] if abs(d[1]) > 0.9 else [0.0, 1.0, 0.0]
        return [
            f'{indent}<emitter type="spot">',
            f'{i2}<transform name="to_world"><lookat origin="{j(map(_float, p))}" target="{j(map(_float, p + d))}" '
            f'up="{j(map(_float, up))}"/></transform>',
            rgb("intensity", e["intensity"]),
            f'{i2}<float name="cutoff_angle" value="{_float(e["cutoff_deg"])}"/>',
            f'{i2}<float name="beam_width" value="{_float(e["beam_deg"])}"/>',
            f"{indent}</emitter>",
        ]
    if e["kind"] in ("sphere", "rect"):
        from .description import rect_to_world

        head = [f'{indent}<shape type="{"sphere" if e["kind"] == "sphere" else "rectangle"}">']
        if e["kind"] == "sphere":
            head += [f'{i2}<point name="center" value="{j(map(_float, e["centre"]))}"/>',
                     f'{i2}<float name="radius" value="{_float(e["radius"])}"/>']  # fmt: skip
        else:
            head += _matrix(rect_to_world(e), i2)
        return [
            *head,
            f'{i2}<bsdf type="diffuse"><rgb name="reflectance" value="0, 0, 0"/></bsdf>',
            f'{i2}<emitter type="area">',
            f'{i2}    <rgb name="radiance" value="{j(map(_float, e["radiance"]))}"/>',
            f"{i2}</emitter>",
            f"{indent}</shape>",
        ]
    raise ValueError(f"Mitsuba XML: emitter kind {e['kind']!r} unknown")


def _bsdf(s: ShapeDesc, texture_file: str | None, opacity_file: str | None = None, b: dict | None = None) -> dict:
    """The shape's BSDF with a baked texture's (and opacity's) reference as a bitmap file."""
    b = dict(s.bsdf if b is None else b)
    if b.get("type") == "mask":
        op = b["opacity"]
        if isinstance(op, dict) and op.get("type") == "opacity_ref":
            op = {"type": "bitmap", "filename": opacity_file, "raw": True}
        return {"type": "mask", "opacity": op, "bsdf": _bsdf(s, texture_file, opacity_file, b["bsdf"])}
    if b.get("type") == "twosided" and isinstance(b["bsdf"].get("base_color"), dict):
        if b["bsdf"]["base_color"].get("type") == "texture_ref":
            inner = dict(b["bsdf"])
            inner["base_color"] = {"type": "bitmap", "filename": texture_file, "raw": True}
            b = {"type": "twosided", "bsdf": inner}
    return b


# [environment] show_background has no counterpart in the truth: the reference hides the emitters (its alpha
# is the objects' coverage, as the frame's), and so does the XML, saying how to show the map
ENVMAP_BACKGROUND_NOTE = (
    "    <!-- hide_emitters true: the environment map lights the scene but is not drawn behind it, as skinlab "
    "reference renders it (alpha = coverage); set it to false to see the map behind the scene, as [environment] "
    "show_background does in the frame -->"
)


def write_mitsuba_xml(desc: ReferenceDescription, folder: str | Path, spp: int = 256) -> Path:
    """``folder/scene.xml`` and its meshes and textures; returns the XML's path."""
    from skinlab.atomic_write import write_text_atomic
    from skinlab.image_output import write_image

    folder = Path(folder)
    (folder / "meshes").mkdir(parents=True, exist_ok=True)
    lines = ['<?xml version="1.0" encoding="utf-8"?>', "<!-- written by skinlab reference (its export-xml option) -->",
             '<scene version="3.0.0">']  # fmt: skip
    if any(e["kind"] == "envmap" for e in desc.emitters):
        lines.append(ENVMAP_BACKGROUND_NOTE)
    lines += dict_to_xml(desc.integrator, "integrator")
    cam = np.asarray(desc.camera_to_world, np.float64)
    lines += [
        '    <sensor type="perspective">',
        f'        <float name="fov" value="{_float(desc.fov_y_deg)}"/>',
        '        <string name="fov_axis" value="y"/>',
        f'        <float name="near_clip" value="{_float(desc.near)}"/>',
        f'        <float name="far_clip" value="{_float(desc.far)}"/>',
        *_matrix(cam, "        "),
        f'        <sampler type="independent"><integer name="sample_count" value="{int(spp)}"/></sampler>',
        '        <film type="hdrfilm">',
        f'            <integer name="width" value="{desc.width}"/>',
        f'            <integer name="height" value="{desc.height}"/>',
        '            <string name="pixel_format" value="rgba"/>',
        '            <rfilter type="box"/>',
        "        </film>",
        "    </sensor>",
    ]
    for e in desc.emitters:
        if e["kind"] == "envmap":  # its pixels beside the XML, as an EXR Mitsuba reads
            from skinlab.scene.envmap import write_map

            if desc.environment is None:
                raise ValueError("the description has an environment map emitter but not its pixels")
            (folder / "textures").mkdir(exist_ok=True)
            write_map(folder / "textures" / "envmap.exr", desc.environment)
            e = {**e, "file": "textures/envmap.exr"}
        lines += _emitter(e, "    ")
    for i, s in enumerate(desc.shapes):
        stem = f"{i:03d}-{''.join(c if c.isalnum() or c in '-_' else '_' for c in s.name)}"
        write_ply(folder / "meshes" / f"{stem}.ply", s)
        tex = opacity = None
        if s.texture is not None:
            (folder / "textures").mkdir(exist_ok=True)
            tex = f"textures/{stem}.exr"
            rgba = np.concatenate([s.texture, np.ones(s.texture.shape[:2] + (1,), np.float32)], axis=2)
            write_image(folder / tex, rgba.astype(np.float32))
        if s.opacity is not None:
            (folder / "textures").mkdir(exist_ok=True)
            opacity = f"textures/{stem}-opacity.exr"
            op = np.repeat(np.asarray(s.opacity, np.float32).reshape(s.opacity.shape[:2] + (1,)), 3, axis=2)
            write_image(folder / opacity, np.concatenate([op, np.ones(op.shape[:2] + (1,), np.float32)], axis=2))
        lines.append(f'    <shape type="ply" id={quoteattr(stem)}>')
        lines.append(f'        <string name="filename" value="meshes/{stem}.ply"/>')
        lines.append('        <boolean name="face_normals" value="false"/>')
        lines += dict_to_xml(_bsdf(s, tex, opacity), "bsdf", None, "        ")
        if s.interior is not None:
            lines += dict_to_xml(s.interior, "medium", "interior", "        ")
        lines.append("    </shape>")
    lines.append("</scene>")
    return write_text_atomic(folder / "scene.xml", "\n".join(lines) + "\n")
