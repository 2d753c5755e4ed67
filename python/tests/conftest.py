"""Shared helpers: the texel command (built by `cargo build --release`) and PNG reading."""

import os
import pathlib
import shutil
import subprocess

import numpy as np
import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]


def texel_bin():
    """The texel binary: $TEXEL_BIN, else the workspace's release build."""
    path = os.environ.get("TEXEL_BIN") or str(ROOT / "target" / "release" / "texel")
    return path if os.path.isfile(path) and os.access(path, os.X_OK) else None


@pytest.fixture(scope="module")
def cli():
    """Run the texel command; tests that compare with it need it built."""
    path = texel_bin()
    if path is None:
        if os.environ.get("CI") == "true":
            pytest.fail("target/release/texel is missing: cargo build --release first")
        pytest.skip("target/release/texel is not built (cargo build --release)")

    def run(*args, cwd=None):
        done = subprocess.run([path, *map(str, args)], cwd=cwd, capture_output=True, text=True)
        assert done.returncode == 0, done.stderr
        return done

    return run


def read_png(path):
    """An 8-bit RGBA PNG as an H x W x 4 uint8 array."""
    from PIL import Image

    with Image.open(path) as im:
        assert im.mode == "RGBA", im.mode
        return np.asarray(im).copy()


def write_png(path, array):
    from PIL import Image

    Image.fromarray(array).save(path)


def solid_png(path, rgb, size=4):
    """A size x size PNG of one opaque colour."""
    write_png(path, np.full((size, size, 4), [*rgb, 255], dtype=np.uint8))


def png_bytes(array):
    import io

    from PIL import Image

    out = io.BytesIO()
    Image.fromarray(array).save(out, format="PNG")
    return out.getvalue()


# A camera at +z looking at the origin, for the test scenes.
SCENE_HEAD = """[output]
width = 32
height = 24
[camera]
eye = [0.0, 0.0, 3.0]
target = [0.0, 0.0, 0.0]
fovy_deg = 60.0
near = 0.1
far = 100.0
"""


def quad_mesh(texture, z=0.0):
    """A [[meshes]] entry: the square (-1, -1)-(1, 1) at depth z facing +z, drawn with texture."""
    return f"""[[meshes]]
texture = "{texture}"
positions = [[-1.0, -1.0, {z}], [1.0, -1.0, {z}], [1.0, 1.0, {z}], [-1.0, 1.0, {z}]]
uvs = [[0.0, 1.0], [1.0, 1.0], [1.0, 0.0], [0.0, 0.0]]
triangles = [[0, 1, 2], [0, 2, 3]]
"""


def write_obj(path):
    """An OBJ file of the square (-1, -1)-(1, 1) facing +z."""
    path.write_text(
        "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\n"
        "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
        "f 1/1 2/2 3/3\nf 1/1 3/3 4/4\n"
    )


def write_gltf(path, image_png, image_uri=None, buffer_uri=None, z=0.0):
    """A glTF file (``.gltf``, its buffer at ``buffer_uri`` and its base colour image at
    ``image_uri``) or, for a ``.glb`` path, a GLB with both embedded: the square (-1, -1)-(1, 1)
    at depth z facing +z, textured with ``image_png`` (PNG bytes) through its own material."""
    import json
    import struct

    geometry = b"".join(struct.pack("<3f", x, y, z) for x, y in [(-1, -1), (1, -1), (1, 1), (-1, 1)])
    geometry += b"".join(struct.pack("<2f", *t) for t in [(0, 1), (1, 1), (1, 0), (0, 0)])
    geometry += struct.pack("<6H", 0, 1, 2, 0, 2, 3)
    views = [
        {"buffer": 0, "byteOffset": 0, "byteLength": 48},
        {"buffer": 0, "byteOffset": 48, "byteLength": 32},
        {"buffer": 0, "byteOffset": 80, "byteLength": 12},
    ]
    glb = path.suffix.lower() == ".glb"
    if glb:
        views.append({"buffer": 0, "byteOffset": 92, "byteLength": len(image_png)})
        data = geometry + image_png
        image = {"bufferView": 3, "mimeType": "image/png"}
    else:
        data = geometry
        image = {"uri": image_uri}
    while len(data) % 4:
        data += b"\0"
    buffer = {"byteLength": len(data)}
    if not glb:
        buffer["uri"] = buffer_uri
    doc = {
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "indices": 2, "material": 0}]}],
        "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}],
        "textures": [{"source": 0}],
        "images": [image],
        "buffers": [buffer],
        "bufferViews": views,
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-1, -1, z], "max": [1, 1, z]},
            {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC2"},
            {"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"},
        ],
    }
    text = json.dumps(doc).encode()
    if not glb:
        path.write_bytes(text)
        (path.parent / buffer_uri).write_bytes(data)
        return
    while len(text) % 4:
        text += b" "
    total = 12 + 8 + len(text) + 8 + len(data)
    path.write_bytes(
        b"glTF" + struct.pack("<II", 2, total)
        + struct.pack("<I", len(text)) + b"JSON" + text
        + struct.pack("<I", len(data)) + b"BIN\0" + data
    )
