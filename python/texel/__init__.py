"""texel: texture mapping and every texture filter, from nearest to EWA, on numpy arrays.

``Texture`` holds an image and its mip pyramid and samples it with any filter at arrays of points
and footprints; ``render``, ``reference`` and ``compare`` run texel's scenes (a TOML, OBJ or glTF
file, a ``"builtin:NAME"`` or TOML text) exactly as the ``texel`` command does; ``warp`` maps an
image in perspective without aliasing; ``scene_files`` lists the files a scene reads.
``texel.distributed`` runs renders and references over Ray.

8-bit arrays are read as stored (``color="linear"``, code ``c`` is ``c / 255``, as OpenCV, scipy
and torch read them) unless ``color="srgb"`` says they are sRGB-encoded; scenes default to sRGB,
as their image files are.

Every call releases the GIL and uses texel's own threads, a pool per process (a forked child
makes its own). What a call allocates in proportion to its input is charged to ``max_memory``,
else the process's memory limit, before it is allocated. texel's errors arrive as Python
exceptions with texel's messages: ``ValueError`` for bad values and shapes, ``OSError`` for
files, ``MemoryError`` for what the memory limit refuses, ``KeyboardInterrupt`` after Ctrl-C.
"""

from __future__ import annotations

import os
from typing import Optional, Tuple

from ._texel import (
    BUILTIN_SCENES,
    DEFAULT_SEED,
    FILTERS,
    Texture,
    compare,
    encode,
    reference_estimate,
    render,
    scene_files,
    scene_size,
    warp,
)

__all__ = [
    "BUILTIN_SCENES",
    "DEFAULT_SEED",
    "FILTERS",
    "Texture",
    "compare",
    "encode",
    "reference",
    "reference_estimate",
    "render",
    "scene_files",
    "scene_size",
    "warp",
]


def reference(
    scene: "str | os.PathLike[str]",
    spp: int = 256,
    size: Optional[Tuple[int, int]] = None,
    max_spp: int = 65536,
    tolerance: float = 0.5,
    seed: int = DEFAULT_SEED,
    color: str = "srgb",
    threads: Optional[int] = None,
    max_memory: Optional[int] = None,
    exact: bool = False,
):
    """The supersampled reference of ``scene``: the ``H x W x 4`` ``uint8`` image that
    ``texel reference SCENE --spp SPP --max-spp MAX_SPP -o FILE.png`` writes, bit for bit.

    Every pixel gets at least ``spp`` samples; pixels whose 95 % interval of the displayed value
    is wider than ``tolerance`` 8-bit steps get more, doubling, up to ``max_spp``. The result
    depends on ``seed`` only, not on the thread count. ``reference_estimate`` returns the error
    bars too. With ``exact=True``, as ``texel reference --exact``: every pixel whose visible
    surface is unlit textured triangles is computed, not sampled.
    """
    return reference_estimate(
        scene,
        spp=spp,
        max_spp=max_spp,
        tolerance=tolerance,
        seed=seed,
        size=size,
        color=color,
        threads=threads,
        max_memory=max_memory,
        exact=exact,
    )["image"]
