"""TactEx twin in Python: GelSight presses rendered into numpy arrays, a stream of pretraining
samples drawn exactly as ``tactex datagen tactile`` draws them, the whole question
pipeline, and a real sensor's calibration and sim-to-real comparison.

Everything here runs the same Rust library as the ``tactex`` command line: a press, a sample
or an answer is the same bytes from Python as from the CLI at the same seed. Arguments are
checked by the library the CLI runs; every error is a ``tactex.TactexError``: a bad argument
``tactex.InvalidArgument`` (a ``ValueError``), a missing file ``tactex.MissingFile`` (a
``FileNotFoundError``), a failure of the machinery ``tactex.Failure`` (a ``RuntimeError``),
with a one-line message that names the keyword (``depth_mm``).

    >>> import tactex
    >>> press = tactex.Sensor().press("sphere", radius_mm=6, hardness="40A", depth_mm=1.0)
    >>> press.frame.shape, press.force_n > 0
    ((240, 320, 3), True)
"""

from __future__ import annotations

import json
import math
import os
from dataclasses import dataclass, field
from typing import Any, Dict, Iterator, List, Optional, Sequence, Tuple, Union

import numpy as np


def _runtime_dir() -> None:
    """Software Vulkan (lavapipe) prints an error on every start without a runtime
    directory: give it a private one when the environment has none, as the CLI does
    (src/cli/process.rs)."""
    current = os.environ.get("XDG_RUNTIME_DIR")
    if current and os.path.isdir(current):
        return
    import tempfile

    path = os.path.join(tempfile.gettempdir(), f"tactex-xdg-runtime-{os.getuid()}")
    try:
        os.makedirs(path, mode=0o700, exist_ok=True)
        os.environ["XDG_RUNTIME_DIR"] = path
    except OSError:
        pass


_runtime_dir()

from . import _tactex as _raw  # noqa: E402
from .errors import Failure, InvalidArgument, MissingFile, TactexError, translated


class _Native:
    """The native module with its errors raised as this package's, in Python's words."""

    def __getattr__(self, name: str) -> Any:
        value = getattr(_raw, name)
        return translated(value) if callable(value) else value


_tactex = _Native()

__all__ = [
    "TactexError",
    "InvalidArgument",
    "MissingFile",
    "Failure",
    "Sensor",
    "Contact",
    "Press",
    "PressSequence",
    "Sample",
    "generate",
    "shard_indices",
    "worker_shard",
    "ask",
    "calibrate",
    "compare",
    "read",
    "SHAPE_FAMILIES",
    "FIDELITIES",
    "__version__",
]

__version__: str = _tactex.__version__

#: The contact physics a press can be solved at, cheapest first.
FIDELITIES: Tuple[str, ...] = ("rigid", "hertz", "halfspace", "layer")
#: The shape families pretraining samples are drawn from.
SHAPE_FAMILIES: Tuple[str, ...] = ("sphere", "ellipsoid", "box", "fruit", "blob")

PathLike = Union[str, "os.PathLike[str]"]


def _shown(value: Any) -> str:
    """A value as an error shows it: short, on one line."""
    text = " ".join(repr(value).split())
    return text if len(text) <= 60 else text[:57] + "..."


def _number(name: str, value: Any) -> Optional[float]:
    """A keyword's number (an int, a float or a numpy number; not a bool or text), or None;
    anything else is an InvalidArgument naming it."""
    if value is None:
        return None
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, float, np.number)):
        raise InvalidArgument(f"{name}: give a number, got {_shown(value)}")
    try:
        return float(value)
    except (TypeError, ValueError, OverflowError):
        raise InvalidArgument(f"{name}: {_shown(value)} is not a number this can take") from None


def _flag(name: str, value: Any) -> bool:
    """A keyword's True or False (not text, which would read as True)."""
    if not isinstance(value, (bool, np.bool_)):
        raise InvalidArgument(f"{name}: give True or False, got {_shown(value)}")
    return bool(value)


def _mesh_shape(shape: Any, mesh: Any) -> Any:
    """The shape to press: "mesh" when a mesh is given (the default "sphere" gives way to
    it); another named shape beside a mesh would be dropped, so it is refused."""
    if mesh is None:
        return shape
    if shape not in ("sphere", "mesh"):
        raise InvalidArgument(f"shape: {_shown(shape)} given with a mesh; give one object")
    return "mesh"


def _pose(pose: Any) -> Optional[Tuple[float, float, float]]:
    """``pose=(x_mm, y_mm, yaw_deg)``: three numbers, or None."""
    if pose is None:
        return None
    if isinstance(pose, (str, bytes, dict)) or not hasattr(pose, "__len__") or len(pose) != 3:
        raise InvalidArgument(f"pose: give (x_mm, y_mm, yaw_deg), got {_shown(pose)}")
    try:
        x, y, yaw = (_number("pose", v) for v in pose)
    except InvalidArgument:
        raise InvalidArgument(f"pose: give (x_mm, y_mm, yaw_deg), got {_shown(pose)}") from None
    if x is None or y is None or yaw is None:
        raise InvalidArgument(f"pose: give (x_mm, y_mm, yaw_deg), got {_shown(pose)}")
    return (x, y, yaw)


def _array(name: str, value: Any, dtype: Any) -> np.ndarray:
    """A keyword's array of ``dtype``, C-contiguous; what numpy cannot make one of is an
    InvalidArgument naming the keyword."""
    try:
        return np.ascontiguousarray(np.asarray(value, dtype=dtype))
    except (TypeError, ValueError) as e:
        raise InvalidArgument(f"{name}: not an array of numbers ({e})") from None


def _geometry(
    mesh: Any = None,
    mesh_scale: Optional[float] = None,
    height_map_mm: Any = None,
    mm_per_px: Optional[float] = None,
) -> Optional[Dict[str, Any]]:
    """The caller's own object for the native press: a mesh as ``(vertices, faces)`` or any
    object with ``vertices`` and ``faces`` (a ``trimesh.Trimesh``), or a height map; None
    when the object is a named shape or a mesh file."""
    geometry: Dict[str, Any] = {
        "vertices": None,
        "faces": None,
        "mesh_scale": _number("mesh_scale", mesh_scale),
        "height_map_mm": None,
        "mm_per_px": _number("mm_per_px", mm_per_px),
    }
    if height_map_mm is not None:
        try:
            h = np.asarray(height_map_mm)
        except (TypeError, ValueError) as e:
            raise InvalidArgument(f"height_map_mm: not an array of numbers ({e})") from None
        if h.dtype.kind not in "iuf":
            raise InvalidArgument(f"height_map_mm: must hold real numbers, got dtype {h.dtype}")
        h = _array("height_map_mm", h, np.float64)
        if h.ndim != 2:
            raise InvalidArgument(f"height_map_mm: must be 2-D (rows, columns), got shape {h.shape}")
        geometry["height_map_mm"] = h
        return geometry
    if mesh is None or isinstance(mesh, (str, os.PathLike)):
        return None
    if hasattr(mesh, "vertices") and hasattr(mesh, "faces"):
        vertices, faces = mesh.vertices, mesh.faces
    elif isinstance(mesh, (tuple, list)) and len(mesh) == 2:
        vertices, faces = mesh
    else:
        raise InvalidArgument(
            "mesh: give a file path, (vertices, faces) arrays or an object with vertices and "
            f"faces (a trimesh.Trimesh), got {type(mesh).__name__}"
        )
    v = _array("mesh", vertices, np.float64)
    try:
        f = np.asarray(faces)
    except (TypeError, ValueError) as e:
        raise InvalidArgument(f"mesh: faces are not an array of indices ({e})") from None
    if v.ndim != 2 or f.ndim != 2:
        raise InvalidArgument(
            f"mesh: vertices and faces must be 2-D (N x 3, M x 3), got {v.shape} and {f.shape}"
        )
    if f.dtype.kind not in "iu":
        raise InvalidArgument(f"mesh: faces must be integer indices, got {f.dtype}")
    if f.dtype.kind == "u" and f.size and f.max() > np.iinfo(np.int64).max:
        raise InvalidArgument(f"mesh: face index {f.max()} is outside the {len(v)} vertices")
    geometry["vertices"] = v
    geometry["faces"] = np.ascontiguousarray(f.astype(np.int64))
    return geometry


def _text(name: str, value: Any) -> str:
    """A keyword's text; anything else is an InvalidArgument naming it."""
    if not isinstance(value, str):
        raise InvalidArgument(f"{name}: give text, got {value!r}")
    return value


def _numbers(name: str, value: Any) -> Optional[List[float]]:
    """A keyword's sequence of numbers, or None."""
    if value is None:
        return None
    if isinstance(value, (str, bytes, dict, set)) or not hasattr(value, "__iter__"):
        raise InvalidArgument(f"{name}: give a sequence of numbers, got {_shown(value)}")
    try:
        return [float(v) for v in (_number(name, v) for v in value)]  # type: ignore[arg-type]
    except (InvalidArgument, TypeError):
        raise InvalidArgument(f"{name}: give a sequence of numbers, got {_shown(value)}") from None


def _whole(name: str, value: Any, end: int) -> int:
    """A keyword's whole number in [0, end)."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)):
        raise InvalidArgument(f"{name}: give a whole number, got {_shown(value)}")
    if not 0 <= int(value) < end:
        raise InvalidArgument(f"{name}: {_shown(value)} is outside [0, {end - 1}]")
    return int(value)


def _seed(value: Any) -> int:
    """A camera-noise seed: a whole number in [0, 2**32)."""
    return _whole("seed", value, 2**32)


def _request(**values: Any) -> Dict[str, Any]:
    """A library request's fields as JSON takes them: None left out (the library's default
    applies), paths as text; any other value is checked by the caller or the library."""
    out: Dict[str, Any] = {}
    for name, value in values.items():
        if value is None:
            continue
        if isinstance(value, os.PathLike):
            value = os.fspath(value)
        elif isinstance(value, bytes):
            raise InvalidArgument(f"{name}: give text or a path, got bytes")
        elif isinstance(value, float) and not math.isfinite(value):
            # JSON has no NaN or infinity to carry it to the library's range check.
            raise InvalidArgument(f"{name}: {value} is not a finite number")
        out[name] = value
    return out


# Press keywords that are numbers; the others are text, paths or sequences.
_PRESS_NUMBERS = (
    "radius_mm",
    "mesh_scale",
    "modulus_mpa",
    "object_poisson",
    "grid_mm",
    "tolerance",
    "gel_modulus_mpa",
    "gel_thickness_mm",
    "marker_pitch_mm",
)


def _press_keywords(
    shape: Any, depth_mm: Any, pose: Optional[Tuple[float, float, float]], **kw: Any
) -> Dict[str, Any]:
    """A press's keywords as the native press takes them, each of its type (a number, text,
    a path), every key present; a value of the wrong type is an InvalidArgument naming its
    keyword. The library checks the values."""
    out: Dict[str, Any] = {name: _number(name, kw.get(name)) for name in _PRESS_NUMBERS}
    depth = _number("depth_mm", depth_mm)
    if depth is None:
        raise InvalidArgument("depth_mm: give the press's depth past first touch in mm")
    at_mm: Optional[List[float]] = None
    yaw: Optional[float] = None
    placed = _pose(pose)
    if placed is not None:
        x, y, yaw = placed
        at_mm = [x, y]
    mesh = kw.get("mesh")
    if mesh is not None and not isinstance(mesh, (str, os.PathLike)):
        raise InvalidArgument(f"mesh: give a file path, got {type(mesh).__name__}")
    for name in ("hardness", "marker_grid"):
        if kw.get(name) is not None:
            _text(name, kw[name])
    out.update(
        shape=_text("shape", shape),
        depth_mm=depth,
        size_mm=_numbers("size_mm", kw.get("size_mm")),
        mesh=None if mesh is None else os.fspath(mesh),
        at_mm=at_mm,
        yaw_deg=yaw,
        hardness=kw.get("hardness"),
        fidelity=_text("fidelity", kw.get("fidelity", "layer")),
        marker_grid=kw.get("marker_grid"),
        seed=_seed(kw.get("seed", 0)),
    )
    return out


@dataclass(frozen=True)
class Press:
    """One press of the gel into an object, solved and rendered.

    ``frame`` and ``reference`` are (H, W, 3) uint8 RGB: the pressed frame and a no-contact
    frame with its own camera noise. ``fields`` holds float32 maps, rows x columns: the gel's
    normal and lateral displacement over the pad (``gel_normal_mm``, ``gel_lateral_x_mm``,
    ``gel_lateral_y_mm``; grid in ``field_grid``) and the contact pressure over the solver
    grid (``pressure_mpa``; grid in ``pressure_grid``). A grid is ``(cell_mm, (x0_mm,
    y0_mm))``, the first cell's corner in the pad frame. ``report`` is what ``tactex press
    --json`` prints; ``library_s`` the library's own wall time for the press (checked,
    solved, rendered), against which the binding's cost is measured.
    """

    frame: np.ndarray
    reference: np.ndarray
    fields: Dict[str, np.ndarray]
    field_grid: Tuple[float, Tuple[float, float]]
    pressure_grid: Tuple[float, Tuple[float, float]]
    report: Dict[str, Any]
    library_s: float = field(default=0.0, repr=False, compare=False)

    @property
    def force_n(self) -> float:
        """Total contact force (N)."""
        return float(self.report["force_n"])

    @property
    def contact_radius_mm(self) -> float:
        """Radius of the circle with the contact's area (mm)."""
        return float(self.report["contact_radius_mm"])

    @property
    def gel_indentation_mm(self) -> float:
        """The gel's largest normal displacement (mm)."""
        return float(self.report["gel_max_indentation_mm"])

    @property
    def object_indentation_mm(self) -> float:
        """The object's largest indentation (mm)."""
        return float(self.report["object_max_indentation_mm"])

    @property
    def warnings(self) -> List[str]:
        """What the solver warns of (a contact cut by the pad's edge, a gel bottoming out)."""
        return list(self.report["warnings"])


class Sensor:
    """A GelSight sensor: the built-in GelSight Mini, or a sensor profile file (TOML, as
    ``tactex calibrate`` writes it).

    >>> Sensor().size
    (320, 240)
    """

    def __init__(self, profile: Optional[PathLike] = None) -> None:
        if profile is not None and not isinstance(profile, (str, os.PathLike)):
            raise InvalidArgument(f"profile: give a profile file's path, got {_shown(profile)}")
        self.profile: Optional[str] = None if profile is None else os.fspath(profile)
        if isinstance(self.profile, bytes):
            raise InvalidArgument("profile: give the path as text, not bytes")
        # Loaded once: every press through this sensor reuses it.
        self._native = _tactex.Profile(self.profile)
        #: The profile's name and content hash, as every output names it.
        self.id: str = self._native.id
        #: The profile's name and SHA-256, as data sets and model cards record it.
        self.profile_id: Dict[str, Any] = json.loads(self._native.profile_id)
        self.name: str = self._native.name
        #: Frame size (width, height) in pixels, and the scale.
        self.size: Tuple[int, int] = tuple(self._native.size)  # type: ignore[assignment]
        self.mm_per_px: float = self._native.mm_per_px
        self.gel_modulus_mpa: float = self._native.gel_modulus_mpa
        self.gel_thickness_mm: float = self._native.gel_thickness_mm
        #: Marker grid (columns, rows).
        self.markers: Tuple[int, int] = tuple(self._native.markers)  # type: ignore[assignment]

    def __repr__(self) -> str:
        return f"Sensor({self.id!r}, {self.size[0]}x{self.size[1]} px)"

    def press_sequence(
        self,
        shape: str = "sphere",
        *,
        radius_mm: Optional[float] = None,
        size_mm: Optional[Sequence[float]] = None,
        pose: Optional[Tuple[float, float, float]] = None,
        mesh: Any = None,
        mesh_scale: Optional[float] = None,
        hardness: Optional[str] = None,
        modulus_mpa: Optional[float] = None,
        object_poisson: Optional[float] = None,
        fidelity: str = "layer",
        grid_mm: Optional[float] = None,
        gel_modulus_mpa: Optional[float] = None,
        gel_thickness_mm: Optional[float] = None,
        marker_grid: Optional[str] = None,
        marker_pitch_mm: Optional[float] = None,
        phase_mm: float = 0.0,
        seed: int = 0,
    ) -> "PressSequence":
        """The paper's press protocol on the object (arguments as for :meth:`press`): two
        no-contact frames, a descent in 0.25 mm steps until the contact criterion fires
        (local SSIM against the no-contact frame, or marker motion), then 8 frames from
        the first contact frame, 0.25 mm apart. First touch falls ``phase_mm`` (0 to 0.25)
        before a step. Rendered on the CPU; ``seed`` seeds every frame's camera noise."""
        shape = _mesh_shape(shape, mesh)
        geometry = _geometry(mesh, mesh_scale)
        keywords = _press_keywords(
            "sphere" if geometry is not None else shape,
            0.0,
            pose,
            radius_mm=radius_mm,
            size_mm=size_mm,
            mesh=None if geometry is not None else mesh,
            mesh_scale=mesh_scale,
            hardness=hardness,
            modulus_mpa=modulus_mpa,
            object_poisson=object_poisson,
            fidelity=fidelity,
            grid_mm=grid_mm,
            gel_modulus_mpa=gel_modulus_mpa,
            gel_thickness_mm=gel_thickness_mm,
            marker_grid=marker_grid,
            marker_pitch_mm=marker_pitch_mm,
            seed=seed,
        )
        phase = _number("phase_mm", phase_mm)
        if phase is None:
            raise InvalidArgument("phase_mm: give a number in [0, 0.25)")
        frames, facts = _tactex.press_sequence(self._native, keywords, phase, geometry)
        return PressSequence(reference=frames[0], frames=frames[1:], labels=json.loads(facts))

    def press(
        self,
        shape: str = "sphere",
        *,
        depth_mm: float,
        radius_mm: Optional[float] = None,
        size_mm: Optional[Sequence[float]] = None,
        pose: Optional[Tuple[float, float, float]] = None,
        mesh: Any = None,
        mesh_scale: Optional[float] = None,
        hardness: Optional[str] = None,
        modulus_mpa: Optional[float] = None,
        object_poisson: Optional[float] = None,
        fidelity: str = "layer",
        grid_mm: Optional[float] = None,
        tolerance: Optional[float] = None,
        gel_modulus_mpa: Optional[float] = None,
        gel_thickness_mm: Optional[float] = None,
        marker_grid: Optional[str] = None,
        marker_pitch_mm: Optional[float] = None,
        seed: int = 0,
        device: str = "cpu",
    ) -> Press:
        """Presses the gel ``depth_mm`` past first touch into a ``sphere`` (``radius_mm``),
        ``ellipsoid`` or ``box`` (``size_mm`` X, Y, Z full extents) or a ``mesh`` file, of
        ``hardness`` ("35A", "55 00", "rigid") or ``modulus_mpa``, at ``fidelity`` (rigid,
        hertz, halfspace, layer). ``pose`` is ``(x_mm, y_mm, yaw_deg)``: where on the pad
        (origin at its centre) the object's lowest point stands, a mesh's the middle of its
        top, and its turn about the pressing axis; default the centre, unturned. An object
        that reaches past the pad's edge is cut there (``warnings`` says so). ``seed`` seeds
        the frame's camera noise. Same arguments as ``tactex press`` (``pose`` is its
        ``--at-mm X,Y --yaw-deg YAW``); the frame equals its ``tactile.png``.

        ``mesh`` is a file path, ``(vertices, faces)`` arrays (N x 3 in the mesh's units,
        z up; M x 3 indices) or a ``trimesh.Trimesh``, in metres unless ``mesh_scale`` says
        the unit; given a mesh, ``shape`` may be left out. A mesh from arrays presses exactly
        as the same mesh from a file.
        """
        shape = _mesh_shape(shape, mesh)
        geometry = _geometry(mesh, mesh_scale)
        return self._press(
            "sphere" if geometry is not None else shape,
            geometry,
            depth_mm=depth_mm,
            pose=pose,
            radius_mm=radius_mm,
            size_mm=size_mm,
            mesh=None if geometry is not None else mesh,
            mesh_scale=mesh_scale,
            hardness=hardness,
            modulus_mpa=modulus_mpa,
            object_poisson=object_poisson,
            fidelity=fidelity,
            grid_mm=grid_mm,
            tolerance=tolerance,
            gel_modulus_mpa=gel_modulus_mpa,
            gel_thickness_mm=gel_thickness_mm,
            marker_grid=marker_grid,
            marker_pitch_mm=marker_pitch_mm,
            seed=seed,
            device=device,
        )

    def render(
        self,
        height_map_mm: Any,
        *,
        depth_mm: float,
        mm_per_px: Optional[float] = None,
        pose: Optional[Tuple[float, float, float]] = None,
        hardness: Optional[str] = None,
        modulus_mpa: Optional[float] = None,
        object_poisson: Optional[float] = None,
        fidelity: str = "layer",
        grid_mm: Optional[float] = None,
        tolerance: Optional[float] = None,
        seed: int = 0,
        device: str = "cpu",
    ) -> Press:
        """A frame of an object whose surface you computed (Taxim's contract), pressed
        ``depth_mm`` past first touch through the sensor's contact physics (``fidelity``) and
        optics, of ``hardness`` ("rigid", "35A") or ``modulus_mpa``.

        ``height_map_mm`` is (rows, columns) float: the object's surface height in mm, larger
        nearer the gel, so its highest point touches first; NaN where the object is absent.
        Its points lie ``mm_per_px`` apart (default the sensor's, so a frame-sized map lines
        up with the frame's pixels), centred on the pad, or on ``pose`` ``(x_mm, y_mm,
        yaw_deg)``. A sphere's cap as a height map renders as :meth:`press` of that sphere.

        >>> s = Sensor()
        >>> ys, xs = np.mgrid[0:240, 0:320]
        >>> r2 = ((xs + 0.5 - 160) ** 2 + (ys + 0.5 - 120) ** 2) * s.mm_per_px ** 2
        >>> cap = np.sqrt(np.maximum(15.0**2 - r2, 0.0))
        >>> s.render(cap, depth_mm=0.5, hardness="rigid", fidelity="rigid").frame.shape
        (240, 320, 3)
        """
        if height_map_mm is None:
            raise InvalidArgument("height_map_mm: give the object's surface, a 2-D array of heights in mm")
        geometry = _geometry(
            height_map_mm=height_map_mm,
            mm_per_px=self.mm_per_px if mm_per_px is None else mm_per_px,
        )
        return self._press(
            "sphere",
            geometry,
            depth_mm=depth_mm,
            pose=pose,
            hardness=hardness,
            modulus_mpa=modulus_mpa,
            object_poisson=object_poisson,
            fidelity=fidelity,
            grid_mm=grid_mm,
            tolerance=tolerance,
            seed=seed,
            device=device,
        )

    def contact(
        self,
        shape: str = "sphere",
        *,
        radius_mm: Optional[float] = None,
        size_mm: Optional[Sequence[float]] = None,
        mesh: Any = None,
        mesh_scale: Optional[float] = None,
        height_map_mm: Any = None,
        mm_per_px: Optional[float] = None,
        hardness: Optional[str] = None,
        modulus_mpa: Optional[float] = None,
        object_poisson: Optional[float] = None,
        fidelity: str = "layer",
        grid_mm: Optional[float] = None,
        tolerance: Optional[float] = None,
        gel_modulus_mpa: Optional[float] = None,
        gel_thickness_mm: Optional[float] = None,
        marker_grid: Optional[str] = None,
        marker_pitch_mm: Optional[float] = None,
        seed: int = 0,
        device: str = "cpu",
    ) -> "Contact":
        """One object under the pad, to be pressed step by step along a path you drive (your
        simulator's steps, a policy's actions): ``Contact.step(depth_mm, pose)`` returns each
        step's :class:`Press`. The object is given as for :meth:`press` (a named shape, a
        mesh file, ``(vertices, faces)``, a trimesh) or as a height map as for
        :meth:`render`; it is read once, and the contact solver's kernels and the sensor's
        optics are kept between steps. Each step is the press of its pose and depth, drawn
        with its own camera noise (``seed`` + 2 + the step's number; the no-contact
        ``Contact.reference`` has ``seed`` + 1)."""
        if height_map_mm is not None:
            if mesh is not None:
                raise InvalidArgument("height_map_mm: give a mesh or a height map, not both")
            if mesh_scale is not None:
                raise InvalidArgument("mesh_scale: not read with height_map_mm (mm_per_px sets its scale)")
            geometry = _geometry(
                height_map_mm=height_map_mm,
                mm_per_px=self.mm_per_px if mm_per_px is None else mm_per_px,
            )
        else:
            if mm_per_px is not None:
                raise InvalidArgument("mm_per_px: read only with height_map_mm")
            shape = _mesh_shape(shape, mesh)
            geometry = _geometry(mesh, mesh_scale)
        keywords = _press_keywords(
            "sphere" if geometry is not None else shape,
            0.0,
            None,
            radius_mm=radius_mm,
            size_mm=size_mm,
            mesh=None if geometry is not None else mesh,
            mesh_scale=mesh_scale,
            hardness=hardness,
            modulus_mpa=modulus_mpa,
            object_poisson=object_poisson,
            fidelity=fidelity,
            grid_mm=grid_mm,
            tolerance=tolerance,
            gel_modulus_mpa=gel_modulus_mpa,
            gel_thickness_mm=gel_thickness_mm,
            marker_grid=marker_grid,
            marker_pitch_mm=marker_pitch_mm,
            seed=seed,
        )
        native = _tactex.contact(self._native, keywords, _text("device", device), geometry)
        return Contact(native)

    def _press(
        self,
        shape: str,
        geometry: Optional[Dict[str, Any]],
        *,
        depth_mm: float,
        pose: Optional[Tuple[float, float, float]] = None,
        device: str = "cpu",
        **flags: Any,
    ) -> Press:
        """One press from ``Sensor.press``'s keywords, on ``geometry`` when the caller gave
        its own object (``shape`` then names a placeholder the geometry replaces)."""
        keywords = _press_keywords(shape, depth_mm, pose, **flags)
        out = _tactex.press(self._native, keywords, _text("device", device), geometry)
        return Press(
            frame=out["frame"],
            reference=out["reference"],
            fields=dict(out["fields"]),
            field_grid=_grid(out["field_grid"]),
            pressure_grid=_grid(out["pressure_grid"]),
            report=json.loads(out["report"]),
            library_s=float(out["library_s"]),
        )


class Contact:
    """One object under the pad, pressed step by step (:meth:`Sensor.contact`)."""

    def __init__(self, native: Any) -> None:
        self._native = native
        #: The no-contact frame (H, W, 3) uint8 every step is read against.
        self.reference: np.ndarray = native.reference

    def step(self, depth_mm: float, pose: Optional[Tuple[float, float, float]] = None) -> Press:
        """The object at ``pose`` ``(x_mm, y_mm, yaw_deg)`` on the pad (default the centre,
        unturned), the sensor ``depth_mm`` past first touch: the same :class:`Press` as
        :meth:`Sensor.press` of that pose and depth gives, with this step's noise."""
        depth = _number("depth_mm", depth_mm)
        if depth is None:
            raise InvalidArgument("depth_mm: give the sensor's travel past first touch in mm")
        x, y, yaw = _pose(pose) or (0.0, 0.0, 0.0)
        out = translated(self._native.step)(x, y, yaw, depth)
        return Press(
            frame=out["frame"],
            reference=self.reference,
            fields=dict(out["fields"]),
            field_grid=_grid(out["field_grid"]),
            pressure_grid=_grid(out["pressure_grid"]),
            report=json.loads(out["report"]),
            library_s=float(out["library_s"]),
        )


def _grid(g: Any) -> Tuple[float, Tuple[float, float]]:
    return (float(g[0]), (float(g[1][0]), float(g[1][1])))


@dataclass(frozen=True)
class PressSequence:
    """A press by the paper's protocol: ``reference`` (H, W, 3) uint8, the no-contact frame;
    ``frames`` (8, H, W, 3) uint8 from the first contact frame, 0.25 mm apart; ``labels``
    the travel, approach, force, contact radius and gel indentation per frame, the search
    steps before contact, the contact criterion's evidence, warnings, fidelity and sensor."""

    reference: np.ndarray
    frames: np.ndarray
    labels: Dict[str, Any] = field(repr=False)

    @property
    def travel_mm(self) -> List[float]:
        """Each frame's travel past the first contact frame (mm)."""
        return list(self.labels["travel_mm"])

    @property
    def force_n(self) -> List[float]:
        """Each frame's contact force (N)."""
        return list(self.labels["force_n"])


@dataclass(frozen=True)
class Sample:
    """One pretraining sample, as ``tactex datagen tactile`` writes sample ``index``:
    ``frames`` (9, H, W, 3) uint8 with the no-contact reference first and then the 8 frames
    from first contact, 0.25 mm apart; ``labels`` the manifest line's fields (hardness in
    Shore A, Shore 00 and MPa, shape, pose, sensor, seeds, fidelity, and the press's travel,
    force and contact radius per frame)."""

    index: int
    frames: np.ndarray
    labels: Dict[str, Any] = field(repr=False)

    @property
    def reference(self) -> np.ndarray:
        """The no-contact frame (H, W, 3)."""
        return self.frames[0]

    @property
    def press_frames(self) -> np.ndarray:
        """The 8 recorded frames (8, H, W, 3)."""
        return self.frames[1:]

    @property
    def modulus_mpa(self) -> float:
        """The pressed object's Young's modulus (MPa): the label the models regress."""
        return float(self.labels["modulus_mpa"])

    @property
    def shore_a(self) -> float:
        """The same hardness on the Shore A scale."""
        return float(self.labels["shore_a"])


def shard_indices(count: int, shard: Tuple[int, int] = (0, 1), start: int = 0) -> range:
    """The sample indices of ``shard`` (i, n) of a data set of ``count``: i, i + n, ...,
    from ``start`` on, as ``datagen tactile --shard i/n`` takes them."""
    if isinstance(shard, (str, bytes)) or not hasattr(shard, "__len__") or len(shard) != 2:
        raise InvalidArgument(f"shard: {_shown(shard)} is not (i, n) with 0 <= i < n")
    i, n = shard
    whole = (int, np.integer)
    if not (isinstance(n, whole) and isinstance(i, whole) and n >= 1 and 0 <= i < n):
        raise InvalidArgument(f"shard: {_shown(shard)} is not (i, n) with 0 <= i < n")
    i, n = int(i), int(n)
    if count < 0 or start < 0:
        raise InvalidArgument(f"count and start must be at least 0, got {count} and {start}")
    first = start + (i - start) % n
    return range(first, count, n)


def worker_shard(shard: Tuple[int, int], worker: int, workers: int) -> Tuple[int, int]:
    """Worker ``worker`` of ``workers`` takes every ``workers``-th index of shard (i, n): the
    shard (i + worker * n, n * workers). The workers' shards partition the shard's, so that
    data-loader workers drawing their own shard yield each sample exactly once."""
    i, n = shard
    if not (isinstance(workers, int) and workers >= 1 and 0 <= worker < workers):
        raise InvalidArgument(f"worker {worker} of {workers}: not 0 <= worker < workers")
    return (i + worker * n, n * workers)


def generate(
    count: int,
    seed: int = 0,
    *,
    shard: Tuple[int, int] = (0, 1),
    start: int = 0,
    fidelity: str = "layer",
    shapes: Optional[Sequence[str]] = None,
    sensor: Optional[PathLike] = None,
    batch: Optional[int] = None,
) -> Iterator[Sample]:
    """Samples ``start`` .. ``count`` - 1 of shard (i, n) of the data set ``datagen tactile
    --count COUNT --seed SEED --fidelity F --shapes S [--sensor P]`` would write, drawn in
    memory: same seed and index, same frames and labels. Samples are drawn ``batch`` at a
    time (default 4 per Rust thread) in parallel, without the GIL.
    """
    count = _whole("count", count, 2**63)
    seed = _whole("seed", seed, 2**64)
    start = _whole("start", start, 2**63)
    if batch is not None:
        batch = _whole("batch", batch, 2**31)
    if isinstance(shapes, (str, bytes)):
        raise InvalidArgument(f"shapes: give a list of shape families, got {_shown(shapes)}")
    shape_list = [_text("shapes", s) for s in (SHAPE_FAMILIES if shapes is None else shapes)]
    fidelity = _text("fidelity", fidelity)
    profile = None if sensor is None else os.fspath(sensor)
    # A range, not a list: a data set of 10**9 samples is drawn without an index of them all.
    indices = shard_indices(count, shard, start)
    step = batch if batch is not None else 4 * _tactex.threads()
    if step < 1:
        raise InvalidArgument(f"batch: must be at least 1, got {step}")
    for k in range(0, len(indices), step):
        chunk = list(indices[k : k + step])
        drawn = _tactex.generate_samples(fidelity, shape_list, profile, seed, chunk)
        for index, (labels, frames) in zip(chunk, drawn):
            yield Sample(index=index, frames=frames, labels=json.loads(labels))


def ask(
    prompt: str,
    *,
    scene: Optional[PathLike] = None,
    seed: int = 0,
    fidelity: str = "layer",
    estimator: Optional[str] = None,
    intervals: Optional[PathLike] = None,
    detector: Optional[str] = None,
    device: Optional[str] = None,
    sensor: Optional[PathLike] = None,
    explainer: Optional[str] = None,
    parser: Optional[str] = None,
    llm_config: Optional[PathLike] = None,
    gel_modulus_mpa: Optional[float] = None,
    camera_error_mm: Optional[float] = None,
    camera_error_deg: Optional[float] = None,
    camera_error_seed: Optional[int] = None,
    camera_calibration: Optional[PathLike] = None,
    reproducible: bool = True,
) -> Dict[str, Any]:
    """Asks the twin ``prompt`` ("Which fruit is the softest?") on ``scene`` (default the
    built-in demo) and returns the object ``tactex ask --json`` prints: the query, every
    object touched with position, hardness, interval and ripeness, the answer text, timings.
    With ``reproducible`` (the default) wall-clock times are left out, so that the same
    arguments give the same result, equal to ``ask --json --reproducible``. ``parser="llm"``
    has the endpoint ``explainer="llm"`` uses read the question (``tactex ask --parser``).
    ``camera_error_mm`` (0-200) and ``camera_error_deg`` (0-20) stand the scene camera off
    the scene's pose, in directions drawn from ``camera_error_seed``, without telling the
    pipeline; ``camera_calibration`` (``tactex handeye``'s TOML) has the pipeline believe
    the calibrated pose instead (``tactex ask --camera-error-mm`` and the rest).
    """
    twin = _request(
        fidelity=_text("fidelity", fidelity),
        estimator=estimator,
        intervals=intervals,
        detector=detector,
        device=device,
        sensor=sensor,
        explainer=explainer,
        parser=parser,
        llm_config=llm_config,
        camera_error_mm=_number("camera_error_mm", camera_error_mm),
        camera_error_deg=_number("camera_error_deg", camera_error_deg),
        camera_error_seed=(
            None
            if camera_error_seed is None
            else _whole("camera_error_seed", camera_error_seed, 2**64)
        ),
        camera_calibration=camera_calibration,
    )
    request = _request(
        prompt=_text("prompt", prompt),
        scene=scene,
        seed=_whole("seed", seed, 2**64),
        reproducible=_flag("reproducible", reproducible),
        gel_modulus_mpa=_number("gel_modulus_mpa", gel_modulus_mpa),
        twin=twin,
    )
    return json.loads(_tactex.ask(json.dumps(request)))


def calibrate(
    images: PathLike,
    annotations: PathLike,
    background: PathLike,
    *,
    ball_radius_mm: float,
    mm_per_px: float,
    out: PathLike,
    name: Optional[str] = None,
    markers: Optional[PathLike] = None,
    gel_modulus_mpa: Optional[float] = None,
    gel_thickness_mm: Optional[float] = None,
    gel_poisson: Optional[float] = None,
    frame_rate_hz: Optional[float] = None,
    split: Optional[str] = None,
    mag_bins: Optional[int] = None,
    dir_bins: Optional[int] = None,
    mag_max: Optional[float] = None,
    smoothness: Optional[float] = None,
    source: str = "",
    glow: bool = True,
    fidelity: Optional[str] = None,
    interval_placements: Optional[int] = None,
) -> Dict[str, Any]:
    """Calibrates a real sensor from ball presses, as ``tactex calibrate``: the gradient ->
    colour table from the frames in ``images`` (circles in the ``annotations`` CSV:
    image,center_x_px,center_y_px,contact_radius_px) against the no-contact ``background``,
    the glow round a contact (unless ``glow`` is False), the camera's noise, and the marker
    grid of a ``markers`` frame when given. Writes the sensor profile to ``out`` (its
    background beside it) and returns what ``calibrate --json`` prints: the profile's path
    and id, presses and pixels fitted, the table's rms residual per channel, the noise and
    the markers read. ``Sensor(out)`` then presses through it. Unless ``interval_placements``
    is 0, the twin then presses every catalog fruit at that many places (default 16, 2-3
    minutes) through the new profile and writes the default estimator's interval calibration
    beside it (``intervals`` in the result; ``intervals_not_measured`` says why not when it
    could not be made), so that answers through the profile carry measured intervals.
    Arguments left as None take the command's defaults (``tactex calibrate --help``)."""
    request = _request(
        images=images,
        annotations=annotations,
        background=background,
        ball_radius_mm=_number("ball_radius_mm", ball_radius_mm),
        mm_per_px=_number("mm_per_px", mm_per_px),
        out=out,
        name=name,
        markers=markers,
        gel_modulus_mpa=_number("gel_modulus_mpa", gel_modulus_mpa),
        gel_thickness_mm=_number("gel_thickness_mm", gel_thickness_mm),
        gel_poisson=_number("gel_poisson", gel_poisson),
        frame_rate_hz=_number("frame_rate_hz", frame_rate_hz),
        split=split,
        mag_bins=None if mag_bins is None else _whole("mag_bins", mag_bins, 2**32),
        dir_bins=None if dir_bins is None else _whole("dir_bins", dir_bins, 2**32),
        mag_max=_number("mag_max", mag_max),
        smoothness=_number("smoothness", smoothness),
        source=source,
        glow=_flag("glow", glow),
        fidelity=fidelity,
        interval_placements=None if interval_placements is None
        else _whole("interval_placements", interval_placements, 2**32),
    )
    return json.loads(_tactex.calibrate(json.dumps(request)))


def compare(
    sensor: Optional[PathLike] = None,
    images: Optional[PathLike] = None,
    annotations: Optional[PathLike] = None,
    *,
    session: Optional[PathLike] = None,
    scene: Optional[PathLike] = None,
    seed: Optional[int] = None,
    gel_modulus_mpa: Optional[float] = None,
    estimator: Optional[str] = None,
    split: Optional[str] = None,
    fidelity: Optional[str] = None,
    device: Optional[str] = None,
    glow: bool = True,
    out: Optional[PathLike] = None,
) -> Dict[str, Any]:
    """Sim-to-real, as ``tactex compare``, returning what ``compare --json`` prints.

    Ball presses: each annotated press in ``images``/``annotations`` (the ``split``: eval,
    every third, held out of calibration; calib; all) is rebuilt in the twin at
    ``fidelity``, rendered through the calibrated profile ``sensor``, and scored against the
    real frame (SSIM and MAE, whole frame and contact box, and the contact circle).

    A recorded ``session`` (``tactex ask --record DIR``): every press rebuilt in the twin
    (``sensor`` default the built-in Mini; ``scene``, ``seed``, ``gel_modulus_mpa`` and
    ``estimator`` as for ``ask``) and scored recorded against rebuilt, with the hardness
    each reads. ``out`` writes the side-by-side images and the JSON there. Arguments left
    as None take the command's defaults (``tactex compare --help``: split eval, fidelity
    layer, device auto)."""
    request = _request(
        sensor=sensor,
        images=images,
        annotations=annotations,
        session=session,
        scene=scene,
        seed=None if seed is None else _whole("seed", seed, 2**64),
        gel_modulus_mpa=_number("gel_modulus_mpa", gel_modulus_mpa),
        estimator=estimator,
        split=split,
        fidelity=fidelity,
        device=device,
        glow=_flag("glow", glow),
        out=out,
    )
    return json.loads(_tactex.compare(json.dumps(request)))


def read(
    image: PathLike,
    reference: Optional[PathLike] = None,
    sensor: Optional[PathLike] = None,
    *,
    out: Optional[PathLike] = None,
) -> Dict[str, Any]:
    """What the twin reads from one tactile frame, as ``tactex read``: the frame (a real or
    rendered PNG of the ``sensor`` profile's size; default the built-in GelSight Mini) read
    against the no-contact ``reference`` (default the profile's background) through the
    profile's optics, as the estimators read every frame of a press. Returns what ``read
    --json`` prints (``peak_depth_mm``, ``contact_radius_mm``, ``contact_axes_mm``,
    ``contact_edge`` ("outline" or "half_depth"), ``within_frame``, ``readable_share``, the
    sensor's id) and ``indentation_mm``, the gel's
    indentation map (H x W float32, mm into the gel). ``out`` writes the frame beside the map
    as a PNG."""
    request = _request(image=image, reference=reference, sensor=sensor, out=out)
    native = _tactex.read(json.dumps(request))
    report = json.loads(native["report"])
    report["indentation_mm"] = native["indentation_mm"]
    return report

