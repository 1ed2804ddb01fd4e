"""What a press costs from Python against the library's own time for it: `Sensor.press`'s
wall time (keywords to flags, the native call, arrays handed to numpy, the Press built)
against the `library_s` the native module measures around the press itself (the request
checked, solved and rendered). Medians over interleaved repetitions, one process.

    python python/bench/press_overhead.py [--reps 21]
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

import tactex


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--reps", type=int, default=21)
    args = parser.parse_args()
    sensor = tactex.Sensor()
    w, h = sensor.size
    ys, xs = np.mgrid[0:h, 0:w]
    r2 = ((xs + 0.5 - w / 2) ** 2 + (ys + 0.5 - h / 2) ** 2) * sensor.mm_per_px**2
    cap = np.where(r2 <= 36.0, np.sqrt(np.maximum(36.0 - r2, 0.0)), np.nan)
    cases = {
        f"sphere {fidelity}": (lambda f=fidelity: sensor.press("sphere", radius_mm=6, hardness="40A", depth_mm=0.9, fidelity=f, seed=5))
        for fidelity in ("rigid", "layer")
    }
    cases["height map layer"] = lambda: sensor.render(cap, depth_mm=0.9, hardness="40A", fidelity="layer", seed=5)
    for call in cases.values():
        call()  # warm: kernels, thread pool
    walls = {name: [] for name in cases}
    library = {name: [] for name in cases}
    for _ in range(args.reps):
        for name, call in cases.items():
            t = time.perf_counter()
            press = call()
            walls[name].append(time.perf_counter() - t)
            library[name].append(press.library_s)
            # Freed here, outside the timed window: the next call should not pay for this
            # press's arrays (a height map's weigh far more than a rigid press).
            del press
    print("| press | Python wall (ms) | library (ms) | ratio |")
    print("|---|---:|---:|---:|")
    for name in cases:
        wall, lib = statistics.median(walls[name]), statistics.median(library[name])
        print(f"| {name} | {wall * 1e3:.2f} | {lib * 1e3:.2f} | {wall / lib:.3f} |")


if __name__ == "__main__":
    main()
