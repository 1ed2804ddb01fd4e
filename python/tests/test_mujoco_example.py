"""The worked example that puts the GelSight twin into a MuJoCo scene
(python/examples/mujoco_gelsight.py): MuJoCo's ray casts give the height map, the twin
renders it. CI installs MuJoCo and sets TACTEX_REQUIRE_MUJOCO=1, so the example cannot be
skipped there."""

import importlib.util
import os
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]

if os.environ.get("TACTEX_REQUIRE_MUJOCO") != "1":
    pytest.importorskip("mujoco")


def _example():
    spec = importlib.util.spec_from_file_location("mujoco_gelsight", ROOT / "python/examples/mujoco_gelsight.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_pad_lowered_in_mujoco_presses_harder_where_mujoco_put_the_fruit():
    example = _example()
    presses = example.press_down(steps=4)
    forces = [p.force_n for p in presses]
    assert all(b > a > 0 for a, b in zip(forces, forces[1:])), forces
    for p in presses:
        assert p.frame.shape == (240, 320, 3)
    # The imprint's centre (where the frame differs from the no-contact one) is where the
    # scene put the fruit: world (1.5, -1.0) mm from the pad's centre, pad (1.5, 1.0) mm.
    last = presses[-1]
    change = np.abs(last.frame.astype(float) - last.reference.astype(float)).sum(axis=2)
    change[change < 8] = 0
    ys, xs = np.nonzero(change)
    w = change[ys, xs]
    mm = 0.0634
    centre = ((np.average(xs, weights=w) + 0.5 - 160) * mm, (np.average(ys, weights=w) + 0.5 - 120) * mm)
    assert abs(centre[0] - 1.5) < 1.0 and abs(centre[1] - 1.0) < 1.0, centre


def test_the_example_writes_its_frames(tmp_path):
    import subprocess
    import sys

    out = tmp_path / "frames.png"
    run = subprocess.run([sys.executable, str(ROOT / "python/examples/mujoco_gelsight.py"), "--out", str(out)],
                         capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    from PIL import Image

    assert Image.open(out).size == (4 * 320, 240)
