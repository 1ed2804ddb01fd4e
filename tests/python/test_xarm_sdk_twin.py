"""The vendor's xArm Python SDK against `tactex twin`, with the SDK's own calls only.

Run by tests/twin_sdk.rs (which starts nothing itself: this file starts the twin from
TACTEX_BIN). The control port is set through the SDK's configuration (XCONF.SocketConf);
the SDK's report parser only knows the controller's report ports 30001-30003, so the twin
serves its reports there.
"""

import io
import os
import re
import socket
import subprocess
import urllib.request

import numpy as np
import pytest
from PIL import Image

from xarm.core.config.x_config import XCONF
from xarm.wrapper import XArmAPI

# The demo scene's lime lies at (0.03, -0.04) m on the table; the base stands at
# (-0.45, 0, 0) m: 480, -40 mm in the base frame.
LIME_MM = (480.0, -40.0)
DOWN = dict(roll=180, pitch=0, yaw=0)


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.fixture
def twin():
    control = free_port()
    proc = subprocess.Popen(
        [os.environ["TACTEX_BIN"], "twin", "--port", str(control), "--http-port", "0",
         "--time-scale", "20", "--fidelity", "hertz"],
        cwd=os.environ["TACTEX_ROOT"], stdout=subprocess.PIPE, text=True)
    lines = [proc.stdout.readline() for _ in range(5)]
    http = re.search(r"frames (http://\S+)/", "".join(lines)).group(1)
    XCONF.SocketConf.TCP_CONTROL_PORT = control
    arm = XArmAPI("127.0.0.1", forbid_uds=True)
    yield arm, http
    arm.disconnect()
    proc.kill()
    proc.wait()


def frame(http):
    png = urllib.request.urlopen(http + "/gelsight/frame.png").read()
    return np.asarray(Image.open(io.BytesIO(png)).convert("RGB"), dtype=np.float64)


def test_sdk_connects_presses_a_fruit_and_clears_faults(twin):
    arm, http = twin
    assert arm.connected
    assert arm.version_number == (2, 0, 0)
    assert arm.motion_enable(enable=True) == 0
    assert arm.set_mode(0) == 0
    assert arm.set_state(0) == 0
    code, pose = arm.get_position()
    assert code == 0 and pose[:3] == [300.0, 0.0, 300.0]

    # Above the lime, then down in the paper's 0.25 mm steps until the frame changes from
    # the no-contact reference by more than the sensor's noise, then 8 frames on.
    assert arm.set_position(*LIME_MM, 70, **DOWN, speed=100, wait=True) == 0
    reference = frame(http)
    noise = np.abs(frame(http) - reference).mean()
    z, pressed = 70.0, []
    while z > 30 and not pressed:
        z -= 0.25
        assert arm.set_position(*LIME_MM, z, **DOWN, speed=20, wait=True) == 0
        f = frame(http)
        if np.abs(f - reference).mean() > noise + 1.0:
            pressed.append(f)
    assert pressed, "the pad met the lime"
    for _ in range(7):
        z -= 0.25
        assert arm.set_position(*LIME_MM, z, **DOWN, speed=20, wait=True) == 0
        pressed.append(frame(http))
    change = [np.abs(f - reference).mean() for f in pressed]
    assert change[-1] > change[0], change
    assert arm.set_position(*LIME_MM, 70, **DOWN, speed=100, wait=True) == 0
    code, pose = arm.get_position()
    assert code == 0 and abs(pose[2] - 70) < 1e-3

    # Off the table: the controller's safety boundary error, cleared with the SDK's calls.
    assert arm.set_position(1500, 0, 150, **DOWN, speed=100, wait=True) != 0
    assert arm.get_err_warn_code()[1][0] == 35
    arm.clean_error()
    arm.motion_enable(enable=True)
    arm.set_state(0)
    assert arm.get_err_warn_code()[1] == [0, 0]

    # Far into the lime: the crush limit's collision error.
    assert arm.set_position(*LIME_MM, z - 15, **DOWN, speed=20, wait=True) != 0
    assert arm.get_err_warn_code()[1][0] == 31
    arm.clean_error()
    arm.motion_enable(enable=True)
    arm.set_state(0)
    assert arm.get_err_warn_code()[1] == [0, 0]
    assert arm.move_gohome(wait=True) == 0
    assert arm.get_position()[1][:3] == [300.0, 0.0, 300.0]
