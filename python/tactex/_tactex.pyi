"""Type stubs of the native module (python/src/lib.rs); use the ``tactex`` package instead."""

from typing import Any, Dict, List, Optional, Tuple

import numpy as np

__version__: str

def press(argv: List[str], geometry: Optional[Dict[str, Any]] = None) -> Dict[str, Any]:
    """One press from ``tactex press`` flags, on the caller's own object when ``geometry``
    (vertices, faces, mesh_scale, height_map_mm, mm_per_px; None where not given) holds one:
    report (JSON text), frame, reference, fields, field_grid, pressure_grid."""

def press_sequence(
    argv: List[str], phase_mm: float, geometry: Optional[Dict[str, Any]] = None
) -> Tuple[np.ndarray, str]:
    """The paper's press protocol from ``tactex press`` flags (and ``geometry`` as for
    ``press``): frames (9, H, W, 3) uint8 and the press's facts (JSON text)."""

def generate_samples(
    fidelity: str, shapes: List[str], sensor: Optional[str], seed: int, indices: List[int]
) -> List[Tuple[str, np.ndarray]]:
    """Samples at ``indices``: (labels JSON text, frames (9, H, W, 3) uint8)."""

def ask(argv: List[str]) -> str:
    """``tactex ask --json`` from its flags (prompt last): the answer as JSON text."""

def calibrate(argv: List[str]) -> str:
    """``tactex calibrate --json`` from its flags: writes the profile, returns the fit (JSON
    text)."""

def compare(argv: List[str]) -> str:
    """``tactex compare --json`` from its flags: the comparison as JSON text."""

def read(argv: List[str]) -> Dict[str, Any]:
    """``tactex read`` from its flags: ``report`` (JSON text) and ``indentation_mm`` (H x W
    float32)."""

def sensor_info(path: Optional[str] = None) -> Dict[str, Any]:
    """A profile's id, name, width, height, mm_per_px, gel and markers."""

def threads() -> int:
    """Threads of the Rust pool that draws samples."""
