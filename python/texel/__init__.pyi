"""Type stubs of texel's Python package (see docs/guide/python.md)."""

import os
from typing import Dict, List, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

FILTERS: List[str]
BUILTIN_SCENES: List[str]
DEFAULT_SEED: int

_Scene = Union[str, "os.PathLike[str]"]
_Coords = npt.NDArray[Union[np.float32, np.float64]]

class Texture:
    """A texture and its mip pyramid, with the address modes and border colour its samples use."""

    def __init__(
        self,
        array: npt.NDArray[Union[np.uint8, np.float32]],
        color: str = "linear",
        address: str = "repeat",
        address_u: Optional[str] = None,
        address_v: Optional[str] = None,
        border: str = "transparent-black",
        max_memory: Optional[int] = None,
    ) -> None: ...
    @property
    def width(self) -> int: ...
    @property
    def height(self) -> int: ...
    @property
    def dtype(self) -> str: ...
    @property
    def color(self) -> str: ...
    @property
    def address_u(self) -> str: ...
    @property
    def address_v(self) -> str: ...
    @property
    def border(self) -> str: ...
    def levels(self) -> List[npt.NDArray[Union[np.uint8, np.float32]]]: ...
    def sample(
        self,
        uv: _Coords,
        duv_dx: Optional[_Coords] = None,
        duv_dy: Optional[_Coords] = None,
        filter: str = "trilinear",
        lod_bias: float = 0.0,
        coords: str = "uv",
        threads: Optional[int] = None,
        max_memory: Optional[int] = None,
    ) -> npt.NDArray[np.float32]: ...
    def __reduce__(self) -> Tuple[type, Tuple[object, ...]]: ...

def render(
    scene: _Scene,
    filter: Optional[str] = "trilinear",
    size: Optional[Tuple[int, int]] = None,
    color: str = "srgb",
    view: str = "color",
    threads: Optional[int] = None,
    max_memory: Optional[int] = None,
    texture_storage: str = "stored",
) -> npt.NDArray[np.uint8]: ...
def reference(
    scene: _Scene,
    spp: int = 256,
    size: Optional[Tuple[int, int]] = None,
    max_spp: int = 65536,
    tolerance: float = 0.5,
    seed: int = ...,
    color: str = "srgb",
    threads: Optional[int] = None,
    max_memory: Optional[int] = None,
    exact: bool = False,
) -> npt.NDArray[np.uint8]: ...
def reference_estimate(
    scene: _Scene,
    spp: int = 256,
    max_spp: int = 65536,
    tolerance: float = 0.5,
    seed: int = ...,
    size: Optional[Tuple[int, int]] = None,
    color: str = "srgb",
    threads: Optional[int] = None,
    scissor: Optional[Tuple[int, int, int, int]] = None,
    max_memory: Optional[int] = None,
    exact: bool = False,
) -> Dict[str, Union[np.ndarray, bool]]: ...
def compare(
    scene: _Scene,
    filters: Optional[Sequence[str]] = None,
    spp: int = 256,
    max_spp: Optional[int] = None,
    tolerance: float = 0.5,
    seed: int = ...,
    size: Optional[Tuple[int, int]] = None,
    color: str = "srgb",
    threads: Optional[int] = None,
    max_memory: Optional[int] = None,
    exact: bool = True,
) -> Dict[str, Dict[str, Union[float, int, List[str]]]]: ...
def warp(
    image: npt.NDArray[Union[np.uint8, np.float32]],
    corners: Union[Sequence[float], Sequence[Tuple[float, float]]],
    size: Optional[Tuple[int, int]] = None,
    filter: str = "ewa",
    color: str = "linear",
    max_memory: Optional[int] = None,
) -> npt.NDArray[Union[np.uint8, np.float32]]: ...
def encode(
    linear: npt.NDArray[np.float32], color: str = "linear", max_memory: Optional[int] = None
) -> npt.NDArray[np.uint8]: ...
def scene_size(scene: _Scene, size: Optional[Tuple[int, int]] = None) -> Tuple[int, int]: ...
def scene_files(scene: _Scene, max_memory: Optional[int] = None) -> List[str]: ...
