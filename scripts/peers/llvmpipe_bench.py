#!/usr/bin/env python3
"""Time Mesa's llvmpipe (software OpenGL) on a texel scene file, one GL filter mode at a time.

The scene's inline meshes are drawn with each of the GL sampler modes that match texel's lab modes
(nearest, bilinear, mip-nearest, trilinear, 16x anisotropic). For each mode the script prints, as
JSON, the median time of the draw plus glFinish over --frames frames, after --warmup frames. Only
the draw is timed: textures and their mip chains (glGenerateMipmap) are uploaded beforehand. Texels
are sampled as plain RGBA8, without an sRGB decode, which is what `texel bench --color raw` does.
--png DIR also saves each mode's frame, so that `texel compare --extra` can score it.

Run from the repository root, inside the environment that scripts/peers/setup.sh makes:

    .venv-peers/bin/python scripts/peers/llvmpipe_bench.py scenes/ground.toml --frames 10 --threads 2

It needs Mesa's EGL and GL drivers from the system (Debian: libegl1 libegl-mesa0 libgl1-mesa-dri
libgles2) and the Python packages numpy, pillow, moderngl and glcontext.
"""
import argparse, json, os, statistics, sys, time, tomllib

ap = argparse.ArgumentParser()
ap.add_argument("scene")
ap.add_argument("--frames", type=int, default=10)
ap.add_argument("--warmup", type=int, default=2)
ap.add_argument("--threads", type=int, default=2)
ap.add_argument("--filters", default="nearest,bilinear,mip-nearest,trilinear,aniso16")
ap.add_argument("--png", help="also write each frame as DIR/<filter>.png")
args = ap.parse_args()
os.environ["LIBGL_ALWAYS_SOFTWARE"] = "1"
os.environ["GALLIUM_DRIVER"] = "llvmpipe"
os.environ["LP_NUM_THREADS"] = str(args.threads)

import moderngl  # noqa: E402
import numpy as np  # noqa: E402
from PIL import Image  # noqa: E402


def look_at(eye, target, up):
    eye, target, up = (np.asarray(v, float) for v in (eye, target, up))
    f = target - eye; f /= np.linalg.norm(f)
    s = np.cross(f, up); s /= np.linalg.norm(s)
    u = np.cross(s, f)
    m = np.eye(4)
    m[0, :3], m[1, :3], m[2, :3] = s, u, -f
    m[:3, 3] = -m[:3, :3] @ eye
    return m


def perspective(fovy_deg, aspect, n, f):
    c = 1.0 / np.tan(np.radians(fovy_deg) / 2)
    return np.array([[c / aspect, 0, 0, 0], [0, c, 0, 0],
                     [0, 0, (f + n) / (n - f), 2 * f * n / (n - f)], [0, 0, -1, 0]])


def texture_rgba(spec, scene_dir):
    if "path" in spec:
        return np.asarray(Image.open(os.path.join(scene_dir, spec["path"])).convert("RGBA"))
    kind = spec["procedural"]
    if kind != "checker":
        sys.exit(f"procedural texture {kind!r} is not supported by this script")
    n, checks = spec.get("size", 1024), spec.get("checks", 8)
    y, x = np.mgrid[0:n, 0:n]
    g = (((x // (n // checks)) + (y // (n // checks))) % 2 * 255).astype(np.uint8)
    return np.dstack([g, g, g, np.full_like(g, 255)])


MODES = {"nearest": ("NEAREST", "NEAREST", 1.0), "bilinear": ("LINEAR", "LINEAR", 1.0),
         "mip-nearest": ("LINEAR_MIPMAP_NEAREST", "LINEAR", 1.0),
         "trilinear": ("LINEAR_MIPMAP_LINEAR", "LINEAR", 1.0),
         "aniso16": ("LINEAR_MIPMAP_LINEAR", "LINEAR", 16.0)}
WRAP = {"repeat": "repeat", "clamp-to-edge": "clamp", "mirror-repeat": "mirror"}

with open(args.scene, "rb") as fh:
    sc = tomllib.load(fh)
scene_dir = os.path.dirname(os.path.abspath(args.scene))
W, H = sc["output"]["width"], sc["output"]["height"]
cam = sc["camera"]
mvp = perspective(cam["fovy_deg"], W / H, cam["near"], cam["far"]) @ look_at(cam["eye"], cam["target"], cam["up"])
bg = np.asarray(sc["output"].get("background", [0, 0, 0, 255])) / 255.0

ctx = moderngl.create_standalone_context(backend="egl", require=330)
prog = ctx.program(
    vertex_shader="#version 330\nuniform mat4 mvp; in vec3 p; in vec2 t; out vec2 uv;\n"
                  "void main() { uv = t; gl_Position = mvp * vec4(p, 1.0); }",
    fragment_shader="#version 330\nuniform sampler2D tex; in vec2 uv; out vec4 c;\n"
                    "void main() { c = texture(tex, uv); }")
prog["mvp"].write(mvp.T.astype("f4").tobytes())
textures = {}
for name, spec in sc.get("textures", {}).items():
    img = texture_rgba(spec, scene_dir)
    t = ctx.texture((img.shape[1], img.shape[0]), 4, np.ascontiguousarray(img).tobytes())
    t.build_mipmaps()
    textures[name] = t
draws = []
for m in sc["meshes"]:
    v = np.hstack([np.asarray(m["positions"], "f4"), np.asarray(m["uvs"], "f4")])
    i = np.asarray(m["triangles"], "i4")
    vao = ctx.vertex_array(prog, [(ctx.buffer(v.tobytes()), "3f 2f", "p", "t")], index_buffer=ctx.buffer(i.tobytes()))
    draws.append((vao, textures[m["texture"]], m.get("address_mode", "repeat")))
fbo = ctx.framebuffer(color_attachments=[ctx.renderbuffer((W, H), 4)])
fbo.use()

result = {"renderer": ctx.info["GL_RENDERER"], "version": ctx.info["GL_VERSION"], "threads": args.threads,
          "width": W, "height": H, "frames": args.frames, "median_ms": {}}
for f in args.filters.split(","):
    mn, mg, an = MODES[f]
    for vao, t, wrap in draws:
        t.filter = (getattr(moderngl, mn), getattr(moderngl, mg))
        t.anisotropy = an
        t.repeat_x = t.repeat_y = wrap == "repeat"
    times = []
    for k in range(args.warmup + args.frames):
        fbo.clear(*bg, depth=1.0)
        ctx.finish()
        t0 = time.perf_counter()
        for vao, t, _ in draws:
            t.use(0)
            vao.render(moderngl.TRIANGLES)
        ctx.finish()
        if k >= args.warmup:
            times.append((time.perf_counter() - t0) * 1e3)
    result["median_ms"][f] = round(statistics.median(times), 3)
    if args.png:
        os.makedirs(args.png, exist_ok=True)
        px = np.frombuffer(fbo.read(components=4), np.uint8).reshape(H, W, 4)[::-1]
        Image.fromarray(px).save(os.path.join(args.png, f + ".png"))
print(json.dumps(result, indent=1))
