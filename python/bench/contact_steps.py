"""What stepping one object along a path costs against pressing it afresh each step: a
path of poses and depths (the object sliding and turning under the pad, pressed deeper and
back) run through `Sensor.contact(...).step` and through `Sensor.press` per step, for a
sphere and a mesh file at the layer physics. Medians of the per-step wall times over the
path, the two runs interleaved, one process.

    python python/bench/contact_steps.py [--steps 24] [--rounds 3]
"""

from __future__ import annotations

import argparse
import math
import statistics
import time
from pathlib import Path

import tactex

ROOT = Path(__file__).resolve().parents[2]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=24)
    parser.add_argument("--rounds", type=int, default=3)
    args = parser.parse_args()
    sensor = tactex.Sensor()
    path = [
        (0.3 + 0.5 * math.sin(math.pi * k / args.steps), (3.0 * math.cos(k / 4), 2.0 * math.sin(k / 4), 5.0 * k))
        for k in range(args.steps)
    ]
    objects = {
        "sphere r 6 mm": dict(radius_mm=6),
        "pear.obj": dict(mesh=str(ROOT / "scenes/meshes/pear.obj")),
    }
    print("| object | press per step (ms) | contact.step (ms) | ratio |")
    print("|---|---:|---:|---:|")
    for name, shape in objects.items():
        fresh, stepped = [], []
        for _ in range(args.rounds):
            contact = sensor.contact(hardness="40A", **shape)
            for depth, pose in path:
                t = time.perf_counter()
                sensor.press(hardness="40A", depth_mm=depth, pose=pose, **shape)
                fresh.append(time.perf_counter() - t)
                t = time.perf_counter()
                contact.step(depth, pose)
                stepped.append(time.perf_counter() - t)
        a, b = statistics.median(fresh) * 1e3, statistics.median(stepped) * 1e3
        print(f"| {name} | {a:.2f} | {b:.2f} | {b / a:.3f} |")


if __name__ == "__main__":
    main()
