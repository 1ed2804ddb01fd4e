"""The GelSight twin inside a MuJoCo scene: MuJoCo holds the world (a table, an egg-shaped
fruit, and the sensor's pad on a mocap body your code moves), its ray casts read the fruit's
surface under the pad, and ``tactex.Sensor.render`` turns that height map into the frame a
GelSight Mini would see, through the twin's contact physics and optics.

    python python/examples/mujoco_gelsight.py --out mujoco_press.png

MuJoCo's own contact is rigid and stops the pad at the fruit's skin, so the pad here does not
collide (``contype=0``): MuJoCo places it and casts the rays, the twin solves the soft contact.
The pad frame's x is the world's x and its y the world's -y (the pad looks down).
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import List

import mujoco
import numpy as np

import tactex

SCENE = """
<mujoco model="gelsight on a fruit">
  <worldbody>
    <geom name="table" type="plane" size="0.2 0.2 0.01" pos="0 0 0"/>
    <body name="fruit" pos="0.0015 -0.001 0.015">
      <geom name="fruit" type="ellipsoid" size="0.022 0.012 0.015" euler="0 0 25"/>
    </body>
    <body name="pad" mocap="true" pos="0 0 0.05">
      <geom name="pad" type="box" size="0.0102 0.0077 0.002" pos="0 0 0.002" contype="0" conaffinity="0"/>
    </body>
  </worldbody>
</mujoco>
"""

# Rays start this far above the pad's plane, so a surface the pad has pressed into (above
# the plane in the pad's frame) is still hit from outside it.
RAY_START_M = 0.02


def height_map(model: mujoco.MjModel, data: mujoco.MjData, sensor: tactex.Sensor, step_px: int) -> np.ndarray:
    """The fruit's surface under the pad, as ``Sensor.render`` reads it (mm, larger nearer
    the gel, NaN where no ray meets the fruit): one ray straight down per grid point, every
    ``step_px`` pixels of the frame."""
    pad = data.body("pad")
    plane_z = pad.xpos[2]
    w, h = sensor.size
    cols = (np.arange(0, w, step_px) + step_px / 2 - w / 2) * sensor.mm_per_px * 1e-3
    rows = (np.arange(0, h, step_px) + step_px / 2 - h / 2) * sensor.mm_per_px * 1e-3
    down = np.array([0.0, 0.0, -1.0])
    geom = np.zeros(1, dtype=np.int32)
    pad_body = model.body("pad").id
    heights = np.full((len(rows), len(cols)), np.nan)
    for j, y in enumerate(rows):
        for i, x in enumerate(cols):
            start = np.array([pad.xpos[0] + x, pad.xpos[1] - y, plane_z + RAY_START_M])
            dist = mujoco.mj_ray(model, data, start, down, None, 1, pad_body, geom)
            if dist >= 0 and geom[0] == model.geom("fruit").id:
                # Gap below the pad's plane (negative once pressed in), as a height.
                heights[j, i] = -(dist - RAY_START_M) * 1e3
    return heights


def press_down(steps: int = 4, step_mm: float = 0.4, step_px: int = 4, seed: int = 0) -> List[tactex.Press]:
    """The pad lowered onto the fruit in ``step_mm`` steps from first touch: the twin's
    press (frame, fields, force) at each step."""
    model = mujoco.MjModel.from_xml_string(SCENE)
    data = mujoco.MjData(model)
    sensor = tactex.Sensor()
    mujoco.mj_forward(model, data)
    # First touch: the pad's plane at the fruit's highest point under it.
    top = np.nanmax(height_map(model, data, sensor, step_px))
    data.mocap_pos[0, 2] += top * 1e-3
    presses = []
    for k in range(1, steps + 1):
        data.mocap_pos[0, 2] -= step_mm * 1e-3
        mujoco.mj_forward(model, data)
        surface = height_map(model, data, sensor, step_px)
        depth_mm = max(0.0, float(np.nanmax(surface)))
        press = sensor.render(
            surface, depth_mm=depth_mm, mm_per_px=sensor.mm_per_px * step_px,
            hardness="45A", fidelity="layer", seed=seed + k,
        )
        presses.append(press)
    return presses


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("mujoco_press.png"), help="PNG of the frames, side by side")
    parser.add_argument("--steps", type=int, default=4)
    args = parser.parse_args()
    presses = press_down(args.steps)
    from PIL import Image

    Image.fromarray(np.concatenate([p.frame for p in presses], axis=1)).save(args.out)
    for k, p in enumerate(presses, 1):
        print(f"step {k}: {0.4 * k:.2f} mm past first touch, force {p.force_n:.3f} N")
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
