"""texel over Ray: many renders, or one reference split into tiles, on a cluster.

``render(jobs)`` runs the jobs (dicts of ``texel.render``'s keyword arguments) as Ray tasks, many
small jobs to a task; ``reference(scene, ...)`` splits one reference into tiles, each a task.
Results equal the local calls bit for bit: every pixel of a reference depends only on the seed
and its own samples.

A scene given as a file path travels with the files texel reads for it, as ``texel.scene_files``
finds them by loading and preparing the scene (textures, meshes, glTF buffers and images,
environment maps, however the scene file names them): each distinct scene is put once into
Ray's object store and unpacked into a temporary directory on the worker that runs it, laid out
as the files lie around the scene (a file named by a relative path outside the scene's directory,
``../common/tex.png``, travels too). Files a scene names by absolute path are read where the task
runs (a shared file system), not shipped. Builtin scenes and TOML text travel as text (the
text's relative paths resolve on the worker).

``address=None`` starts or joins a local Ray (``ray.init()``); ``"auto"`` or ``"ray://HOST:PORT"``
joins a cluster. Needs the ``ray`` extra: ``pip install ./python[ray]``.
"""

from __future__ import annotations

import math
import os
import tempfile
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np

import texel

__all__ = ["render", "reference", "reference_estimate", "bundle"]

# Tasks per worker slot that render(batch=None) aims for: enough to balance uneven jobs, few
# enough that Ray's per-task cost is spread over many small jobs.
_TASKS_PER_SLOT = 4


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


def _is_text(scene: Union[str, "os.PathLike[str]"]) -> bool:
    """Whether texel reads ``scene`` as a builtin name or TOML text rather than a file: as
    ``texel.render`` decides (a ``str`` naming no file that is ``builtin:NAME`` or holds a line
    break; an ``os.PathLike`` is always a file)."""
    if not isinstance(scene, str):
        return False
    return scene.startswith("builtin:") or ("\n" in scene and not os.path.isfile(scene))


def bundle(scene: Union[str, "os.PathLike[str]"], max_memory: Optional[int] = None) -> Dict[str, Any]:
    """What a scene argument needs on another machine: ``{"scene": TEXT}`` for a builtin scene or
    TOML text, else ``{"path": RELATIVE, "files": {RELATIVE: BYTES}}`` with the scene's file and
    every file ``texel.scene_files`` says it reads through a relative path, relative to their
    common directory. ``max_memory`` bounds the preparation that finds them, as in
    ``texel.render``."""
    if _is_text(scene):
        return {"scene": scene}
    path = os.path.abspath(os.fspath(scene))
    base = os.path.dirname(path)
    # Joined to an absolute scene path, a file the scene names relatively starts with its
    # directory; one named absolutely is read where the task runs.
    opened = texel.scene_files(path, max_memory=max_memory)
    shipped = [path]
    for p in opened:
        if p.startswith(base + os.sep):
            full = os.path.normpath(p)
            if full not in shipped:
                shipped.append(full)
    root = os.path.commonpath([os.path.dirname(p) for p in shipped])
    files = {}
    for p in shipped:
        with open(p, "rb") as f:
            files[os.path.relpath(p, root)] = f.read()
    return {"path": os.path.relpath(path, root), "files": files}


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


def _run_renders(jobs: List[Tuple[int, Dict[str, Any]]], *bundles: Dict[str, Any]) -> List[np.ndarray]:
    """Render ``jobs`` (each the index of its scene in ``bundles`` and ``texel.render``'s other
    arguments), each bundle unpacked once."""
    with tempfile.TemporaryDirectory(prefix="texel-jobs-") as work:
        scenes = [_unpacked(b, os.path.join(work, str(k))) for k, b in enumerate(bundles)]
        return [texel.render(scenes[k], **kwargs) for k, kwargs in jobs]


def _run_reference(b: Dict[str, Any], kwargs: Dict[str, Any]) -> Dict[str, Any]:
    with tempfile.TemporaryDirectory(prefix="texel-tile-") as work:
        return texel.reference_estimate(_unpacked(b, work), **kwargs)


def _batch_size(jobs: int, slots: int) -> int:
    """Jobs per task for ``jobs`` jobs on ``slots`` workers: about ``_TASKS_PER_SLOT`` tasks per
    worker, at least one job each."""
    return max(1, math.ceil(jobs / (_TASKS_PER_SLOT * max(1, slots))))


def _batches(jobs: int, size: int) -> List[range]:
    """Consecutive ranges of at most ``size`` of ``jobs`` job indices, in order."""
    return [range(k, min(k + size, jobs)) for k in range(0, jobs, size)]


def render(
    jobs: Sequence[Dict[str, Any]],
    address: Optional[str] = None,
    cpus_per_job: int = 1,
    batch: Optional[int] = None,
) -> List[np.ndarray]:
    """Run the jobs (``texel.render``'s keyword arguments, ``scene`` included) as Ray tasks of
    ``batch`` jobs each (``None``: about four tasks per worker slot of the cluster, so that many
    small jobs share a task's cost), each task with ``cpus_per_job`` CPUs and texel on as many
    threads; returns the images in the jobs' order, equal bit for bit to
    ``[texel.render(**job) for job in jobs]``."""
    if batch is not None and batch < 1:
        raise ValueError(f"batch must be at least 1 job a task, or None; got {batch!r}")
    if cpus_per_job < 1:
        raise ValueError(f"cpus_per_job must be at least 1; got {cpus_per_job!r}")
    specs: List[Tuple[str, Dict[str, Any]]] = []
    for job in jobs:
        job = dict(job)
        if "scene" not in job:
            raise ValueError(f"a job needs a scene: {job!r}")
        scene = job.pop("scene")
        job.setdefault("threads", cpus_per_job)
        specs.append((scene if isinstance(scene, str) else os.fspath(scene), job))
    ray = _connect(address)
    slots = int(ray.cluster_resources().get("CPU", 1) // cpus_per_job)
    size = batch or _batch_size(len(specs), slots)
    task = ray.remote(num_cpus=cpus_per_job)(_run_renders)
    refs: Dict[str, Any] = {}
    pending = []
    for chunk in _batches(len(specs), size):
        used: List[str] = []
        work = []
        for k in chunk:
            scene, kwargs = specs[k]
            if scene not in refs:
                refs[scene] = ray.put(bundle(scene))
            if scene not in used:
                used.append(scene)
            work.append((used.index(scene), kwargs))
        pending.append(task.remote(work, *[refs[s] for s in used]))
    return [image for part in ray.get(pending) for image in part]


def _splits(n: int, parts: int) -> List[Tuple[int, int]]:
    parts = max(1, min(parts, n))
    edges = [n * k // parts for k in range(parts + 1)]
    return [(edges[k], edges[k + 1]) for k in range(parts)]


def reference_estimate(
    scene: Union[str, "os.PathLike[str]"],
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
    ref = ray.put(bundle(scene, max_memory=kwargs.get("max_memory")))
    kwargs.setdefault("threads", cpus_per_tile)
    rects = [
        (x0, y0, x1, y1) for (y0, y1) in _splits(height, rows) for (x0, x1) in _splits(width, columns)
    ]
    parts = ray.get(
        [task.remote(ref, dict(kwargs, spp=spp, size=size, scissor=r)) for r in rects]
    )
    out: Dict[str, Any] = {}
    for key in ("image", "linear", "std_error", "spp", "converged", "exact"):
        first = parts[0][key]
        full = np.zeros((height, width) + first.shape[2:], dtype=first.dtype)
        for (x0, y0, x1, y1), part in zip(rects, parts):
            full[y0:y1, x0:x1] = part[key]
        out[key] = full
    out["interrupted"] = any(p["interrupted"] for p in parts)
    return out


def reference(
    scene: Union[str, "os.PathLike[str]"],
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
