# Type stubs for vgpu_rt (python/vgpu_rt/__init__.py and its extension, python/vgpu_rt.cpp), so
# that editors complete it. The docstrings are in the module itself: help(vgpu_rt.render).
import os
from typing import Any, Iterator, Mapping, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

_Array = npt.NDArray[np.float32]

__version__: str

def scenes_dir() -> str: ...

class FrameStats:
    """A frame's pass statistics as the C++ library keeps them (per kernel and in total)."""
    @property
    def passes(self) -> int: ...
    def json(self) -> str: ...

class Stats(dict[str, Any]):
    frame_stats: Optional[FrameStats]
    def __init__(self, data: Mapping[str, Any], frame_stats: Optional[FrameStats] = ...) -> None: ...

class Frame:
    image: _Array  # (height, width, 3)
    depth: _Array  # (height, width)
    hit: _Array  # (height, width)
    stats: Stats

class Pass:
    index: int
    kernel: str
    paper_name: str
    iteration: int
    trace: Optional[str]  # primary, shadow, reflected; None outside a trace
    counters: dict[str, int]
    frame_totals: dict[str, int]
    query: Optional[int]
    target_name: str
    target: _Array  # (height, width, channels)
    work: Optional[_Array]  # (height, width) bool; None: every fragment ran
    written: Optional[_Array]  # (height, width) bool; None outside counting passes
    iterations: Optional[_Array]  # (height, width) uint32; None without a loop

class Passes(Iterator[Pass]):
    def __init__(self, scene: Union[str, os.PathLike[str]] = ..., **options: Any) -> None: ...
    def __iter__(self) -> Passes: ...
    def __next__(self) -> Pass: ...
    @property
    def frame(self) -> Optional[Frame]: ...

class Texture:
    @property
    def name(self) -> str: ...
    @property
    def width(self) -> int: ...
    @property
    def height(self) -> int: ...
    @property
    def channels(self) -> int: ...
    @property
    def format(self) -> str: ...
    @property
    def array(self) -> _Array: ...
    def write(self, texels: npt.ArrayLike) -> None: ...

class Kernel:
    @property
    def name(self) -> str: ...
    @property
    def paper_name(self) -> str: ...
    @property
    def outputs(self) -> int: ...
    @property
    def units(self) -> list[str]: ...
    @property
    def instructions(self) -> int: ...

class Device:
    def __init__(self, profile: str = "gf5700", threads: int = 1) -> None: ...
    @property
    def profile(self) -> str: ...
    def texture(self, name: str, width: int, height: int, channels: int = 4,
                format: str = "fp32") -> Texture: ...
    def run(self, kernel: Kernel, units: Sequence[Texture], targets: Sequence[Texture],
            query: bool = False) -> dict[str, Any]: ...
    @property
    def totals(self) -> dict[str, int]: ...

kernels: dict[str, Kernel]

def render(
    scene: Union[str, os.PathLike[str]] = "bunny",
    *,
    size: Union[str, tuple[int, int], None] = ...,
    out: Optional[str] = ...,
    bounces: Optional[int] = ...,
    shading: Optional[str] = ...,
    texture_filter: Optional[str] = ...,
    shadows: Union[str, bool, None] = ...,
    grid: Optional[str] = ...,
    accel: Optional[str] = ...,
    profile: Optional[str] = ...,
    threads: Optional[int] = ...,
    lanes: Optional[int] = ...,
    masks: Union[str, bool, None] = ...,
    mrt: Union[str, bool, None] = ...,
    ray_streams: Optional[str] = ...,
    stats: Optional[str] = ...,
    stats_json: Optional[str] = ...,
    aov: Union[str, Sequence[str], None] = ...,
    trace_pixel: Union[str, tuple[int, int], None] = ...,
    quiet: Optional[bool] = ...,
    stats_csv: Optional[str] = ...,
    report: Optional[str] = ...,
    precision: Optional[str] = ...,
    formats: Optional[str] = ...,
    engine: Optional[str] = ...,
    gl_device: Optional[str] = ...,
    gl_readback: Optional[str] = ...,
    kernels: Optional[str] = ...,
    walk: Optional[str] = ...,
    spp: Optional[int] = ...,
    aa: Optional[str] = ...,
    aa_threshold: Optional[float] = ...,
    steps_per_pass: Optional[int] = ...,
    predict: Optional[bool] = ...,
    time: Union[str, float, None] = ...,
    frames: Optional[str] = ...,
    animation: Optional[str] = ...,
    update: Optional[str] = ...,
    report_frame: Optional[int] = ...,
    textures: Optional[str] = ...,
    aa_criterion: Optional[str] = ...,
    aa_cone_depth: Optional[float] = ...,
    aa_budget: Union[str, Sequence[float], None] = ...,
    compact: Union[str, bool, None] = ...,
    beams: Union[str, bool, None] = ...,
    beam_tile: Optional[int] = ...,
) -> Frame: ...
def passes(scene: Union[str, os.PathLike[str]] = "bunny", **options: Any) -> Passes: ...
def scenes() -> dict[str, str]: ...
def profiles() -> list[dict[str, Any]]: ...
def predict(stats: Union[Frame, Mapping[str, Any]], profile: str) -> dict[str, float]: ...
