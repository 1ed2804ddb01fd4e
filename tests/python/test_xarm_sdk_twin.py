"""The vendor's xArm Python SDK against `tactex twin`, with the SDK's own calls only.

Run by tests/integration/twin_sdk.rs (which starts nothing itself: this file starts the twin from
TACTEX_BIN). The control port is set through the SDK's configuration (XCONF.SocketConf);
the SDK's report parser only knows the controller's report ports 30001-30003, so the twin
serves its reports there.
"""

import io
import json
import math
import os
import re
import signal
import socket
import struct
import subprocess
import time
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


SEED = 3


class Twin:
    """`tactex twin` on free ports, recording its session into `session`, and the SDK's
    XArmAPI connected to it."""

    def __init__(self, session):
        control = free_port()
        self.session = session
        self.proc = subprocess.Popen(
            [os.environ["TACTEX_BIN"], "twin", "--port", str(control), "--http-port", "0",
             "--time-scale", "20", "--seed", str(SEED), "--record", str(session)],
            cwd=os.environ["TACTEX_ROOT"], stdout=subprocess.PIPE, text=True)
        lines = [self.proc.stdout.readline() for _ in range(5)]
        self.http = re.search(r"frames (http://\S+)/", "".join(lines)).group(1)
        XCONF.SocketConf.TCP_CONTROL_PORT = control
        self.arm = XArmAPI("127.0.0.1", forbid_uds=True)

    def stop(self):
        """Stops the twin as Ctrl-C does: it writes its session."""
        if self.proc.poll() is None:
            self.arm.disconnect()
            self.proc.send_signal(signal.SIGINT)
            out, _ = self.proc.communicate(timeout=30)
            assert self.proc.returncode == 0, out
            assert "session written" in out, out


@pytest.fixture
def twin(tmp_path):
    t = Twin(tmp_path / "twin-session")
    yield t.arm, t.http
    t.stop()


@pytest.fixture
def recording_twin(tmp_path):
    t = Twin(tmp_path / "twin-session")
    yield t
    if t.proc.poll() is None:
        t.proc.kill()
        t.proc.wait()


def frame(http):
    png = urllib.request.urlopen(http + "/gelsight/frame.png").read()
    return np.asarray(Image.open(io.BytesIO(png)).convert("RGB"), dtype=np.float64)


def ssim_map(a, b):
    """scikit-image's SSIM map (7x7 uniform window, sample covariance, data range 255) of two
    RGB frames' grey levels, as the pipeline's contact criterion computes it."""
    w = np.array([0.2125, 0.7154, 0.0721])
    x, y = a @ w, b @ w

    def mean7(v):
        c = np.pad(v, ((1, 0), (1, 0))).cumsum(0).cumsum(1)
        return (c[7:, 7:] - c[:-7, 7:] - c[7:, :-7] + c[:-7, :-7]) / 49.0

    ux, uy = mean7(x), mean7(y)
    norm = 49.0 / 48.0
    vx = (mean7(x * x) - ux * ux) * norm
    vy = (mean7(y * y) - uy * uy) * norm
    vxy = (mean7(x * y) - ux * uy) * norm
    c1, c2 = (0.01 * 255) ** 2, (0.03 * 255) ** 2
    return ((2 * ux * uy + c1) * (2 * vxy + c2)) / ((ux * ux + uy * uy + c1) * (vx + vy + c2))


def worst_tile(m, t=32):
    """The lowest mean of the SSIM map over half-overlapping 32 px tiles."""
    def starts(n):
        return sorted(set(range(0, n - t + 1, t // 2)) | {n - t})

    return min(m[y:y + t, x:x + t].mean() for y in starts(m.shape[0]) for x in starts(m.shape[1]))


class ContactCriterion:
    """The pipeline's contact criterion (`tactex_core::perception::contact`), from the frames
    alone: the worst 32 px tile's SSIM against the no-contact frame at or below 0.88, or below
    1.3x the dissimilarity the sensor's noise gives between two no-contact frames. The paper's
    reading (frame-wide SSIM <= 0.96 with marker motion) is reported beside it by `ask`."""

    def __init__(self, reference, second):
        self.reference = reference
        floor = worst_tile(ssim_map(second, reference))
        self.threshold = max(0.88, 1 - 1.3 * (1 - floor))

    def worst(self, f):
        return worst_tile(ssim_map(f, self.reference))

    def fires(self, f):
        worst = self.worst(f)
        return worst <= 0.88 or worst < self.threshold


def test_sdk_connects_presses_a_fruit_and_clears_faults(twin):
    arm, http = twin
    assert arm.connected
    assert arm.version_number == (2, 0, 0)
    assert arm.motion_enable(enable=True) == 0
    assert arm.set_mode(0) == 0
    assert arm.set_state(0) == 0
    code, pose = arm.get_position()
    assert code == 0 and pose[:3] == [300.0, 0.0, 300.0]

    # Above the lime, then down in the paper's 0.25 mm steps until the contact criterion
    # fires, then 8 frames on.
    assert arm.set_position(*LIME_MM, 70, **DOWN, speed=100, wait=True) == 0
    reference = frame(http)
    criterion = ContactCriterion(reference, frame(http))
    z, pressed = 70.0, []
    while z > 30 and not pressed:
        z -= 0.25
        assert arm.set_position(*LIME_MM, z, **DOWN, speed=20, wait=True) == 0
        f = frame(http)
        if criterion.fires(f):
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


def rpy_deg(q):
    """Roll, pitch and yaw (degrees, the SDK's convention) of a session's x, y, z, w quaternion."""
    x, y, z, w = q
    roll = math.atan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y))
    pitch = math.asin(max(-1.0, min(1.0, 2 * (w * y - z * x))))
    yaw = math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))
    return [math.degrees(a) for a in (roll, pitch, yaw)]


def test_sdk_press_equals_what_ask_presses_at_the_same_pose_and_seed(recording_twin, tmp_path):
    # `tactex ask` presses the lime on the same scene and seed and records its session.
    session = tmp_path / "session"
    subprocess.run(
        [os.environ["TACTEX_BIN"], "ask", "How hard is the lime?", "--seed", str(SEED),
         "--record", str(session)],
        cwd=os.environ["TACTEX_ROOT"], check=True, stdout=subprocess.DEVNULL)
    manifest = json.loads((session / "manifest.json").read_text())
    (lime,) = manifest["answer"]["objects"]
    recorded = manifest["tactile"]["frames"]
    start = recorded[0]["arm_pose"]
    # Where ask began its descent, in the base frame (the base stands at -0.45, 0, 0 m).
    x, y, z = ((start["position"][0] + 0.45) * 1e3, start["position"][1] * 1e3,
               start["position"][2] * 1e3)
    turn = rpy_deg(start["rotation"])

    # The same protocol with the SDK's calls: above the lime, two no-contact frames, down in
    # 0.25 mm steps until the criterion fires, then 7 frames more, retract.
    arm, http = recording_twin.arm, recording_twin.http
    arm.motion_enable(enable=True)
    arm.set_mode(0)
    arm.set_state(0)
    assert arm.set_position(x, y, z + 100, *turn, speed=100, wait=True) == 0
    assert arm.set_position(x, y, z, *turn, speed=100, wait=True) == 0
    reference, second = frame(http), frame(http)
    criterion = ContactCriterion(reference, second)
    taken, steps = [reference, second], 0
    while steps < 24:
        steps += 1
        assert arm.set_position(x, y, z - 0.25 * steps, *turn, speed=20, wait=True) == 0
        taken.append(frame(http))
        if criterion.fires(taken[-1]):
            break
    else:
        pytest.fail("the criterion never fired within 6 mm")
    for j in range(1, 8):
        assert arm.set_position(x, y, z - 0.25 * (steps + j), *turn, speed=20, wait=True) == 0
        taken.append(frame(http))
    assert arm.set_position(x, y, z + 100, *turn, speed=100, wait=True) == 0

    # The criterion fired where ask's did, on the same evidence ...
    assert steps * 0.25 == lime["contact_search_mm"]
    assert abs(criterion.worst(taken[steps + 1]) - lime["contact"]["min_tile_ssim"]) < 1e-3
    # ... and every frame is ask's: the SDK carries positions as 32-bit floats (0.03 um at
    # these distances), which can move a pixel's rounding by one grey level.
    assert len(taken) == len(recorded)
    for mine, theirs in zip(taken, recorded):
        ask_frame = np.asarray(Image.open(session / theirs["image"]).convert("RGB"), dtype=np.float64)
        diff = np.abs(mine - ask_frame)
        assert diff.max() <= 1 and (diff > 0).mean() < 1e-4, (theirs["image"], diff.max())

    # The twin's own session holds the frames as served, with the pad's pose at each.
    recording_twin.stop()
    twin_manifest = json.loads((recording_twin.session / "manifest.json").read_text())
    served = twin_manifest["tactile"]["frames"]
    assert len(served) == len(taken)
    for mine, record, theirs in zip(taken, served, recorded):
        png = np.asarray(Image.open(recording_twin.session / record["image"]).convert("RGB"))
        assert (png == mine).all()
        for a, b in zip(record["arm_pose"]["position"], theirs["arm_pose"]["position"]):
            assert abs(a - b) < 1e-6

    # ... which `tactex compare --session` rebuilds in the twin: one press, on the lime.
    out = tmp_path / "compare"
    subprocess.run(
        [os.environ["TACTEX_BIN"], "compare", "--session", str(recording_twin.session),
         "--out", str(out)],
        cwd=os.environ["TACTEX_ROOT"], check=True, stdout=subprocess.DEVNULL)
    report = json.loads((out / "compare-session.json").read_text())
    assert report["recorded_backend"] == "twin"
    (press,) = report["presses"]
    assert press["object"] == "lime"
    assert all(f["ssim"] > 0.999 for f in press["frames"])



def ready_down_at(arm, x, y, z, speed=200):
    """Enabled, in position mode and ready, the pad pointing down at (x, y, z) mm."""
    arm.motion_enable(enable=True)
    arm.set_mode(0)
    arm.set_state(0)
    assert arm.set_position(x, y, z, **DOWN, speed=speed, wait=True) == 0


def notice(http):
    return json.loads(urllib.request.urlopen(http + "/state").read())["last_notice"] or ""


def test_sdk_relative_tool_and_servo_moves_modes_and_emergency_stop(twin):
    arm, http = twin
    ready_down_at(arm, *LIME_MM, 80, speed=100)
    # Relative moves add in the base frame; tool-frame moves go along the pad (its +z is
    # down when it points down).
    assert arm.set_position(z=-10, relative=True, speed=50, wait=True) == 0
    assert abs(arm.get_position()[1][2] - 70) < 1e-3
    assert arm.set_tool_position(z=5, speed=50, wait=True) == 0
    assert abs(arm.get_position()[1][2] - 65) < 1e-3

    # In servo mode a planned move is not executed (the twin says why); servo targets run.
    arm.set_mode(1)
    arm.set_state(0)
    arm.set_position(*LIME_MM, 40, **DOWN, speed=50, wait=False)
    time.sleep(0.3)
    assert abs(arm.get_position()[1][2] - 65) < 1e-3
    assert "mode 1" in notice(http)
    assert arm.set_servo_cartesian([LIME_MM[0], LIME_MM[1], 62, 180, 0, 0]) == 0
    time.sleep(0.3)
    assert abs(arm.get_position()[1][2] - 62) < 1e-3
    # A servo step over 10 mm is not executed.
    arm.set_servo_cartesian([LIME_MM[0], LIME_MM[1], 40, 180, 0, 0])
    time.sleep(0.3)
    assert abs(arm.get_position()[1][2] - 62) < 1e-3
    assert "10" in notice(http)

    # Emergency stop mid-move: the pad stops short, where the GelSight images it.
    arm.set_mode(0)
    arm.set_state(0)
    assert arm.set_position(*LIME_MM, 300, **DOWN, speed=5, wait=False) == 0
    time.sleep(1.0)
    arm.emergency_stop()
    assert arm.state == 4
    z = arm.get_position()[1][2]
    assert 62 < z < 300, z
    time.sleep(0.5)
    assert arm.get_position()[1][2] == z, "stopped"
    state = json.loads(urllib.request.urlopen(http + "/state").read())
    assert state["state"] == 4 and abs(state["pose"][2] - z) < 1e-3
    arm.motion_enable(enable=True)
    arm.set_state(0)
    assert arm.set_position(*LIME_MM, 100, **DOWN, speed=100, wait=True) == 0


def test_sdk_joint_reading_forward_and_inverse_kinematics_agree_with_the_pose(twin):
    """The UF850's chain behind the twin: the joints `get_servo_angle` reads hold the pose
    `get_position` reads (`get_forward_kinematics` of them), and `get_inverse_kinematics` of
    that pose gives those joints back; an unreachable pose is refused."""
    arm, _ = twin
    arm.motion_enable(enable=True)
    arm.set_mode(0)
    arm.set_state(0)
    for target in [(300, 0, 300), (420, -60, 180), (250, 120, 260)]:
        assert arm.set_position(*target, **DOWN, speed=200, wait=True) == 0
        code, pose = arm.get_position(is_radian=False)
        assert code == 0
        code, angles = arm.get_servo_angle(is_radian=False)
        assert code == 0 and any(abs(a) > 1 for a in angles[:6]), angles
        code, fk = arm.get_forward_kinematics(angles, input_is_radian=False, return_is_radian=False)
        assert code == 0
        assert max(abs(a - b) for a, b in zip(fk[:3], pose[:3])) < 0.1, (fk, pose)
        for a, b in zip(fk[3:], pose[3:]):
            assert abs((a - b + 180) % 360 - 180) < 0.01, (fk, pose)
        code, ik = arm.get_inverse_kinematics(pose, input_is_radian=False, return_is_radian=False)
        assert code == 0
        assert max(abs(a - b) for a, b in zip(ik[:6], angles[:6])) < 0.1, (ik, angles)
    code, _ = arm.get_inverse_kinematics([3000, 0, 0, 180, 0, 0], input_is_radian=False)
    assert code != 0


def test_sdk_joint_moves_end_on_the_joints_commanded(twin):
    """`set_servo_angle` (MOVE_JOINT): the arm ends on the joints it was sent, `get_position`
    is their forward kinematics, and a target that would tilt the pad (the twin presses with
    the pad down) is not executed, with warning 12."""
    arm, _ = twin
    ready_down_at(arm, 350, 0, 250)
    _, start = arm.get_servo_angle(is_radian=False)
    target = list(start[:6])
    target[0] += 15   # the base turns
    target[5] -= 30   # the pad turns about its axis: still pointing down
    assert arm.set_servo_angle(angle=target, speed=30, wait=True) == 0
    code, now = arm.get_servo_angle(is_radian=False)
    assert code == 0
    assert max(abs(a - b) for a, b in zip(now[:6], target)) < 0.01, (now, target)
    _, pose = arm.get_position(is_radian=False)
    _, fk = arm.get_forward_kinematics(target, input_is_radian=False, return_is_radian=False)
    assert max(abs(a - b) for a, b in zip(fk[:3], pose[:3])) < 0.1, (fk, pose)
    tilted = list(target)
    tilted[4] += 20
    arm.set_servo_angle(angle=tilted, speed=30, wait=True)
    _, after = arm.get_servo_angle(is_radian=False)
    assert max(abs(a - b) for a, b in zip(after[:6], target)) < 0.01, (after, target)
    assert arm.warn_code == 12
    arm.clean_warn()


def test_sdk_relative_joint_moves_and_joint_motion_to_a_pose_follow_the_joints(twin):
    """`set_servo_angle(relative=True)` adds to the joints; the pad follows the joints' arc
    (a turn of the base keeps the pad at its distance from the base, where a line would cut
    the chord); a Cartesian move by joint motion (motion type 2) from nearby joints comes
    back to the same joints; an unreachable one is refused with warning 14."""
    arm, http = twin
    ready_down_at(arm, 380, -60, 200)
    _, start = arm.get_servo_angle(is_radian=False)
    _, start_pose = arm.get_position(is_radian=False)
    reach = math.hypot(start_pose[0], start_pose[1])

    # The base turns 25 degrees: sampled on the way, the pad stays on its circle (the chord
    # of a line would pass 9 mm inside it).
    assert arm.set_servo_angle(angle=[25, 0, 0, 0, 0, 0], relative=True, speed=5,
                               wait=False) == 0
    radii = []
    for _ in range(400):
        code, pose = arm.get_position(is_radian=False)
        radii.append(math.hypot(pose[0], pose[1]))
        if arm.get_state()[1] != 1:
            break
        time.sleep(0.005)
    assert len(radii) > 3, radii
    assert max(abs(r - reach) for r in radii) < 1.0, (reach, min(radii), max(radii))
    _, turned = arm.get_servo_angle(is_radian=False)
    expected = list(start[:6])
    expected[0] += 25
    assert max(abs(a - b) for a, b in zip(turned[:6], expected)) < 0.01, (turned, expected)

    # Back to the start pose by joint motion: the same joints as before, within 0.1 degree.
    assert arm.set_position(*start_pose[:3], **DOWN, speed=100, motion_type=2, wait=True) == 0
    _, back = arm.get_servo_angle(is_radian=False)
    assert max(abs(a - b) for a, b in zip(back[:6], start[:6])) < 0.1, (back, start)
    _, pose = arm.get_position(is_radian=False)
    assert max(abs(a - b) for a, b in zip(pose[:3], start_pose[:3])) < 0.1, (pose, start_pose)

    # A relative turn that takes joint 2 past its limit (the SDK checks only absolute
    # targets): not executed, warning 12, the joints where they were.
    arm.set_servo_angle(angle=[0, 200, 0, 0, 0, 0], relative=True, speed=30, wait=True)
    assert arm.warn_code == 12, notice(http)
    assert "joint 2" in notice(http)
    _, still = arm.get_servo_angle(is_radian=False)
    assert max(abs(a - b) for a, b in zip(still[:6], start[:6])) < 0.1
    arm.clean_warn()

    # Out of reach by joint motion: not executed, warning 14 (no solution).
    arm.set_position(2000, 0, 200, **DOWN, speed=100, motion_type=2, wait=True)
    assert arm.warn_code == 14, notice(http)
    _, still = arm.get_servo_angle(is_radian=False)
    assert max(abs(a - b) for a, b in zip(still[:6], start[:6])) < 0.1
    arm.clean_warn()


def test_sdk_servo_joint_targets_run_in_servo_mode(twin):
    """`set_servo_angle_j` in servo mode (mode 1): each target runs at once, the joints read
    back as sent; a target whose pad lies over 10 mm away is not executed, nor one in mode 0."""
    arm, http = twin
    ready_down_at(arm, 350, 0, 250)
    _, start = arm.get_servo_angle(is_radian=False)
    arm.set_servo_angle_j([a + 0.2 * (i == 0) for i, a in enumerate(start)], is_radian=False)
    time.sleep(0.2)
    assert "mode 0" in notice(http)
    arm.set_mode(1)
    arm.set_state(0)
    target = list(start[:6])
    for step in range(5):
        target[0] += 0.2
        target[5] -= 0.5
        assert arm.set_servo_angle_j(target + [0], is_radian=False) == 0
        time.sleep(0.05)
    time.sleep(0.2)
    _, now = arm.get_servo_angle(is_radian=False)
    assert max(abs(a - b) for a, b in zip(now[:6], target)) < 0.01, (now, target)
    far = list(target)
    far[0] += 20
    arm.set_servo_angle_j(far + [0], is_radian=False)
    time.sleep(0.2)
    _, after = arm.get_servo_angle(is_radian=False)
    assert max(abs(a - b) for a, b in zip(after[:6], target)) < 0.01, (after, target)
    assert "10" in notice(http)


def twin_time(http):
    return json.loads(urllib.request.urlopen(http + "/state").read())["twin_time_s"]


def test_sdk_joint_moves_keep_time_wind_past_half_a_turn_and_refuse_a_tilted_line(twin):
    """A joint move takes its largest turn over the speed sent; joint 6 wound past half a turn
    and back reads what was sent (not a turn away) and relative moves go on from it; a
    Cartesian target that tilts the pad is refused with warning 12, as a joint one is."""
    arm, http = twin
    ready_down_at(arm, 350, 0, 250)
    _, start = arm.get_servo_angle(is_radian=False)
    before = twin_time(http)
    assert arm.set_servo_angle(angle=[25, 0, 0, 0, 0, 0], relative=True, speed=10, wait=True) == 0
    assert abs(twin_time(http) - before - 2.5) < 0.05, twin_time(http) - before

    wound = list(start[:6])
    wound[5] = 340
    assert arm.set_servo_angle(angle=wound, speed=90, wait=True) == 0
    assert arm.set_servo_angle(angle=list(start[:6]), speed=90, wait=True) == 0
    _, back = arm.get_servo_angle(is_radian=False)
    assert max(abs(a - b) for a, b in zip(back[:6], start[:6])) < 0.01, (back, start)
    assert arm.set_servo_angle(angle=[0, 0, 0, 0, 0, -30], relative=True, speed=90,
                               wait=True) == 0
    _, turned = arm.get_servo_angle(is_radian=False)
    assert abs(turned[5] - (start[5] - 30)) < 0.01, turned
    assert arm.warn_code == 0, notice(http)

    _, pose = arm.get_position(is_radian=False)
    arm.set_position(350, 0, 250, roll=180, pitch=20, yaw=0, speed=100, wait=True)
    assert arm.warn_code == 12, notice(http)
    assert "tilts the pad" in notice(http)
    _, still = arm.get_position(is_radian=False)
    assert max(abs(a - b) for a, b in zip(still[:3], pose[:3])) < 1e-3
    arm.clean_warn()
    assert notice(http) == ""


def test_raw_requests_with_the_slowest_speeds_neither_panic_nor_hang_the_controller(twin):
    """Speeds of 1e-30 mm/s and rad/s sent as raw frames (the SDK raises them to the
    controller's slowest): the moves run at the slowest speed, and the controller answers on."""
    arm, http = twin
    ready_down_at(arm, 350, 0, 250)
    _, start = arm.get_servo_angle(is_radian=True)

    def request(sock, register, floats, tail=b""):
        params = b"".join(struct.pack("<f", v) for v in floats) + tail
        sock.sendall(struct.pack(">HHHB", 7, 2, 1 + len(params), register) + params)
        head = sock.recv(7)
        _, _, length, _ = struct.unpack(">HHHB", head)
        body = b""
        while len(body) < length - 1:
            body += sock.recv(length - 1 - len(body))
        return body

    with socket.create_connection(("127.0.0.1", XCONF.SocketConf.TCP_CONTROL_PORT)) as s:
        request(s, 21, [350, 0, 249, math.pi, 0, 0, 1e-30, 500, 0])
        joints = list(start[:6]) + [0]
        joints[0] += 0.01
        request(s, 23, joints + [1e-30, 1, 0])
        time.sleep(0.2)
        assert arm.get_state()[1] == 1, "moving, slowly"
        arm.emergency_stop()
        arm.motion_enable(enable=True)
        arm.set_state(0)
    assert arm.set_position(350, 0, 240, **DOWN, speed=200, wait=True) == 0
    assert abs(arm.get_position()[1][2] - 240) < 1e-3
