"""texel over Ray: many renders, or one reference split into tiles, on a cluster.

``render(jobs)`` runs each job (a dict of ``texel.render``'s keyword arguments) as a Ray task;
``reference(scene, ...)`` splits one reference into tiles, each a task. Results equal the local
calls bit for bit: every pixel of a reference depends only on the seed and its own samples.

A scene given as a file path travels with the files it names (textures, meshes, environment
maps, and what OBJ and glTF files name in turn): each distinct scene is put once into Ray's
object store and unpacked into a temporary directory on the worker that runs it. Builtin scenes
and TOML text travel as text (the text's relative paths resolve on the worker).

``address=None`` starts or joins a local Ray (``ray.init()``); ``"auto"`` or ``"ray://HOST:PORT"``
joins a cluster. Needs the ``ray`` extra: ``pip install ./python[ray]``.
"""

from __future__ import annotations

import json
import os
import re
import tempfile
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union
from urllib.parse import unquote

import numpy as np

import texel

__all__ = ["render", "reference", "reference_estimate", "bundle"]

# The scene-file keys whose values name files: texture and environment images, mesh files.
_FILE_KEYS = re.compile(r'^\s*(path|obj|gltf|faces)\s*=(.*)$', re.MULTILINE)
_QUOTED = re.compile(r'"((?:[^"\\]|\\.)*)"|\'([^\']*)\'')


def _ray():
    try:
        import ray
    except ImportError as e:  # pragma: no cover - depends on the environment
        raise ImportError(
            "texel.distributed needs Ray: pip install ./python[ray] (or pip install ray)"
        ) from e
    return ray


def _connect(address: Optional[str]):
    ray = _ray()
    if not ray.is_initialized():
        if address is None:
            ray.init(ignore_reinit_error=True, log_to_driver=False)
        else:
            ray.init(address=address, ignore_reinit_error=True, log_to_driver=False)
    return ray


def _named_files(path: str) -> List[str]:
    """Files a scene, OBJ, MTL or glTF file names by relative path, that exist."""
    base = os.path.dirname(path)
    with open(path, "rb") as f:
        text = f.read().decode("utf-8", errors="replace")
    ext = os.path.splitext(path)[1].lower()
    names: List[str] = []
    if ext == ".obj":
        for line in text.splitlines():
            parts = line.split()
            if parts and parts[0] == "mtllib":
                names.extend(parts[1:])
    elif ext == ".mtl":
        for line in text.splitlines():
            parts = line.split()
            if len(parts) > 1 and (parts[0].startswith("map_") or parts[0] in ("bump", "norm", "disp")):
                names.append(parts[-1])
    elif ext == ".gltf":
        try:
            doc = json.loads(text)
        except ValueError:
            doc = None
        if isinstance(doc, dict):
            for key in ("buffers", "images"):
                items = doc.get(key)
                for item in items if isinstance(items, list) else []:
                    uri = item.get("uri") if isinstance(item, dict) else None
                    if isinstance(uri, str) and uri and not uri.startswith("data:"):
                        names.append(unquote(uri))
    elif ext == ".toml":
        for _, value in _FILE_KEYS.findall(text):
            names.extend(a or b for a, b in _QUOTED.findall(value))
    found = []
    for name in names:
        # An absolute path is read where the task runs (a shared file system), not shipped.
        if not name or os.path.isabs(name):
            continue
        full = os.path.normpath(os.path.join(base, name))
        if os.path.isfile(full):
            found.append(full)
    return found


def bundle(scene: Union[str, "os.PathLike[str]"]) -> Dict[str, Any]:
    """What a scene argument needs on another machine: ``{"scene": TEXT}`` for a builtin scene or
    TOML text, else ``{"path": RELATIVE, "files": {RELATIVE: BYTES}}`` with the file and every
    file it names by relative path (``path``, ``obj``, ``gltf`` and ``faces`` in a scene file; what
    OBJ, MTL and glTF files name in turn), relative to their common directory."""
    scene = os.fspath(scene)
    if scene.startswith("builtin:") or "\n" in scene:
        return {"scene": scene}
    if not os.path.isfile(scene):
        raise FileNotFoundError(f"cannot load scene {scene}: no such file")
    todo = [os.path.abspath(scene)]
    seen: List[str] = []
    while todo:
        p = todo.pop()
        if p in seen:
            continue
        seen.append(p)
        todo.extend(os.path.abspath(q) for q in _named_files(p))
    root = os.path.commonpath([os.path.dirname(p) for p in seen])
    files = {}
    for p in seen:
        with open(p, "rb") as f:
            files[os.path.relpath(p, root)] = f.read()
    return {"path": os.path.relpath(seen[0], root), "files": files}


def _unpacked(b: Dict[str, Any], work: str) -> str:
    """The scene argument of bundle ``b`` on this machine, its files written under ``work``."""
    if "scene" in b:
        return b["scene"]
    top = os.path.realpath(work)
    for rel, data in b["files"].items():
        full = os.path.realpath(os.path.join(top, rel))
        if os.path.isabs(rel) or os.path.commonpath([top, full]) != top:
            raise ValueError(f"a scene bundle names {rel!r}, outside its directory")
        os.makedirs(os.path.dirname(full), exist_ok=True)
        with open(full, "wb") as f:
            f.write(data)
    scene = os.path.realpath(os.path.join(top, b["path"]))
    if os.path.commonpath([top, scene]) != top:
        raise ValueError(f"a scene bundle's scene {b['path']!r} lies outside its directory")
    return scene


def _run_render(b: Dict[str, Any], kwargs: Dict[str, Any]) -> np.ndarray:
    with tempfile.TemporaryDirectory(prefix="texel-job-") as work:
        return texel.render(_unpacked(b, work), **kwargs)


def _run_reference(b: Dict[str, Any], kwargs: Dict[str, Any]) -> Dict[str, Any]:
    with tempfile.TemporaryDirectory(prefix="texel-tile-") as work:
        return texel.reference_estimate(_unpacked(b, work), **kwargs)


def render(
    jobs: Sequence[Dict[str, Any]],
    address: Optional[str] = None,
    cpus_per_job: int = 1,
) -> List[np.ndarray]:
    """Run each job (``texel.render``'s keyword arguments, ``scene`` included) as a Ray task with
    ``cpus_per_job`` CPUs and texel on as many threads; returns the images in the jobs' order,
    equal bit for bit to ``[texel.render(**job) for job in jobs]``."""
    ray = _connect(address)
    task = ray.remote(num_cpus=cpus_per_job)(_run_render)
    refs: Dict[str, Any] = {}
    pending = []
    for job in jobs:
        job = dict(job)
        if "scene" not in job:
            raise ValueError(f"a job needs a scene: {job!r}")
        scene = os.fspath(job.pop("scene"))
        if scene not in refs:
            refs[scene] = ray.put(bundle(scene))
        job.setdefault("threads", cpus_per_job)
        pending.append(task.remote(refs[scene], job))
    return ray.get(pending)


def _splits(n: int, parts: int) -> List[Tuple[int, int]]:
    parts = max(1, min(parts, n))
    edges = [n * k // parts for k in range(parts + 1)]
    return [(edges[k], edges[k + 1]) for k in range(parts)]


def reference_estimate(
    scene: str,
    spp: int = 256,
    size: Optional[Tuple[int, int]] = None,
    tiles: Tuple[int, int] = (4, 4),
    address: Optional[str] = None,
    cpus_per_tile: int = 1,
    **kwargs: Any,
) -> Dict[str, Any]:
    """``texel.reference_estimate`` split into ``tiles = (columns, rows)`` rectangles, each a Ray
    task; the tiles' arrays are stitched into the whole frame's, equal bit for bit to the local
    call with the same arguments."""
    if "scissor" in kwargs:
        raise ValueError("distributed.reference makes its own tiles: leave out scissor")
    columns, rows = tiles
    if columns < 1 or rows < 1:
        raise ValueError(f"tiles must be (columns, rows) of at least 1 each; got {tiles!r}")
    width, height = texel.scene_size(scene, size)
    ray = _connect(address)
    task = ray.remote(num_cpus=cpus_per_tile)(_run_reference)
    ref = ray.put(bundle(scene))
    kwargs.setdefault("threads", cpus_per_tile)
    rects = [
        (x0, y0, x1, y1) for (y0, y1) in _splits(height, rows) for (x0, x1) in _splits(width, columns)
    ]
    parts = ray.get(
        [task.remote(ref, dict(kwargs, spp=spp, size=size, scissor=r)) for r in rects]
    )
    out: Dict[str, Any] = {}
    for key in ("image", "linear", "std_error", "spp", "converged"):
        first = parts[0][key]
        full = np.zeros((height, width) + first.shape[2:], dtype=first.dtype)
        for (x0, y0, x1, y1), part in zip(rects, parts):
            full[y0:y1, x0:x1] = part[key]
        out[key] = full
    out["interrupted"] = any(p["interrupted"] for p in parts)
    return out


def reference(
    scene: str,
    spp: int = 256,
    size: Optional[Tuple[int, int]] = None,
    tiles: Tuple[int, int] = (4, 4),
    address: Optional[str] = None,
    **kwargs: Any,
) -> np.ndarray:
    """``texel.reference`` over Ray in ``tiles``: the same ``uint8`` image, bit for bit."""
    return reference_estimate(scene, spp=spp, size=size, tiles=tiles, address=address, **kwargs)[
        "image"
    ]
