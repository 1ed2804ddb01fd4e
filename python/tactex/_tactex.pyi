"""Type stubs of the native module (python/src/lib.rs); use the ``tactex`` package instead."""

from typing import Any, Dict, List, Optional, Tuple

import numpy as np

__version__: str

class Profile:
    """A sensor profile loaded once: the built-in GelSight Mini (``path`` None) or a profile
    file; presses through it do not read the file again."""

    def __init__(self, path: Optional[str] = None) -> None: ...
    @property
    def id(self) -> str: ...
    @property
    def profile_id(self) -> str: ...
    @property
    def name(self) -> str: ...
    @property
    def size(self) -> Tuple[int, int]: ...
    @property
    def mm_per_px(self) -> float: ...
    @property
    def gel_modulus_mpa(self) -> float: ...
    @property
    def gel_thickness_mm(self) -> float: ...
    @property
    def markers(self) -> Tuple[int, int]: ...

def press(
    profile: Profile,
    options: Dict[str, Any],
    device: str,
    geometry: Optional[Dict[str, Any]] = None,
) -> Dict[str, Any]:
    """One press through ``profile``: ``options`` are ``Sensor.press``'s keywords, every key
    present (None where not given), checked by the library; ``geometry`` (vertices, faces,
    mesh_scale, height_map_mm, mm_per_px) the caller's own object. Returns report (JSON
    text), library_s, frame, reference, fields, field_grid, pressure_grid."""

class Steps:
    """One object pressed step by step (``contact``)."""

    @property
    def reference(self) -> np.ndarray: ...
    def step(self, x_mm: float, y_mm: float, yaw_deg: float, depth_mm: float) -> Dict[str, Any]:
        """One step's press, as ``press`` returns it without the reference."""

def contact(
    profile: Profile,
    options: Dict[str, Any],
    device: str,
    geometry: Optional[Dict[str, Any]] = None,
) -> Steps:
    """The object ``options`` and ``geometry`` describe, ready to be pressed step by step."""

def press_sequence(
    profile: Profile,
    options: Dict[str, Any],
    phase_mm: float,
    geometry: Optional[Dict[str, Any]] = None,
) -> Tuple[np.ndarray, str]:
    """The paper's press protocol through ``profile`` (``options`` and ``geometry`` as for
    ``press``): frames (9, H, W, 3) uint8 and the press's facts (JSON text)."""

def generate_samples(
    fidelity: str, shapes: List[str], sensor: Optional[str], seed: int, indices: List[int]
) -> List[Tuple[str, np.ndarray]]:
    """Samples at ``indices``: (labels JSON text, frames (9, H, W, 3) uint8)."""

def ask(request: str) -> str:
    """The answer to an ``AskRequest`` (JSON text: prompt, scene, seed, reproducible, twin
    {fidelity, estimator, ...}, ...), as ``tactex ask --json`` prints it (JSON text)."""

def calibrate(request: str) -> str:
    """Fits and writes the profile a ``CalibrateRequest`` (JSON text) describes; returns the
    fit (JSON text), as ``calibrate --json`` prints it."""

def compare(request: str) -> str:
    """The comparison a ``CompareRequest`` (JSON text) describes, as ``compare --json``
    prints it (JSON text)."""

def read(request: str) -> Dict[str, Any]:
    """One frame read as a ``ReadRequest`` (JSON text: image, reference, sensor, out) says:
    ``report`` (JSON text) and ``indentation_mm`` (H x W float32)."""

def threads() -> int:
    """Threads of the Rust pool that draws samples."""
