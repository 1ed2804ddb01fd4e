"""The Python package against the command line: the same press, samples and answer, byte for
byte; bad arguments raise with the CLI's one-line message; data-loader workers share a data
set without overlap."""

import json
import multiprocessing
import os
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

import tactex

ROOT = Path(__file__).resolve().parents[2]


def test_a_press_frame_equals_the_clis_tactile_png(cli, tmp_path):
    args = dict(radius_mm=6, hardness="40A", depth_mm=0.9, seed=5)
    for fidelity in ["rigid", "layer"]:
        out = tmp_path / fidelity
        cli("press", "--shape", "sphere", "--radius-mm", "6", "--hardness", "40A", "--depth-mm", "0.9",
            "--seed", "5", "--fidelity", fidelity, "--device", "cpu", "--out", str(out), "--json")
        press = tactex.Sensor().press("sphere", fidelity=fidelity, **args)
        assert press.frame.dtype == np.uint8 and press.frame.shape == (240, 320, 3)
        assert np.array_equal(press.frame, np.asarray(Image.open(out / "tactile.png")))
        assert np.array_equal(press.reference, np.asarray(Image.open(out / "reference.png")))
        report = json.loads((out / "maps.json").read_text())["press"]
        assert press.report == report
        assert press.force_n > 0 and press.contact_radius_mm > 0


def test_a_press_through_a_calibrated_profile_uses_its_frame(cli, tmp_path):
    profile = ROOT / "tests/fixtures/fots/profile/fots-9.toml"
    sensor = tactex.Sensor(profile)
    assert sensor.size == (240, 320) and sensor.name == "fots-9"
    press = sensor.press("box", size_mm=(6, 4, 3), pose=(1.5, -1, 30), modulus_mpa=1.5, depth_mm=0.5, seed=2)
    out = tmp_path / "fots"
    cli("press", "--shape", "box", "--size-mm", "6,4,3", "--at-mm", "1.5,-1", "--yaw-deg", "30", "--modulus-mpa", "1.5",
        "--depth-mm", "0.5", "--seed", "2", "--device", "cpu", "--sensor", str(profile), "--out", str(out))
    assert press.frame.shape == (320, 240, 3)
    assert np.array_equal(press.frame, np.asarray(Image.open(out / "tactile.png")))


def test_the_press_fields_are_the_gels_displacement_over_the_pad():
    press = tactex.Sensor().press("sphere", radius_mm=5, modulus_mpa=2.0, depth_mm=0.5)
    normal = press.fields["gel_normal_mm"]
    assert normal.dtype == np.float32
    # The gel takes part of the approach, never more than all of it.
    assert 0 < normal.max() <= 0.5 + 1e-6
    assert abs(normal.max() - press.gel_indentation_mm) < 1e-4
    cell, (x0, y0) = press.field_grid
    rows, cols = normal.shape
    # The map covers the pad (GelSight Mini: 320 x 240 px of 0.0634 mm).
    assert cols * cell >= 320 * 0.0634 - cell and rows * cell >= 240 * 0.0634 - cell


def _obj(path):
    """An OBJ file's vertices and triangles, read here as a user's own code would."""
    vertices, faces = [], []
    for line in Path(path).read_text().splitlines():
        parts = line.split()
        if parts and parts[0] == "v":
            vertices.append([float(v) for v in parts[1:4]])
        elif parts and parts[0] == "f":
            faces.append([int(p.split("/")[0]) - 1 for p in parts[1:4]])
    return np.array(vertices), np.array(faces)


def test_a_height_map_of_a_sphere_renders_as_the_press_of_that_sphere():
    """Taxim's contract (the object's surface over the pad, larger nearer the gel) against
    the twin's own sphere: the same frame to a grey level, through both contact models."""
    sensor = tactex.Sensor()
    w, h = sensor.size
    ys, xs = np.mgrid[0:h, 0:w]
    r2 = ((xs + 0.5 - w / 2) ** 2 + (ys + 0.5 - h / 2) ** 2) * sensor.mm_per_px**2
    cap = np.where(r2 <= 36.0, np.sqrt(np.maximum(36.0 - r2, 0.0)), np.nan)
    for fidelity in ["rigid", "layer"]:
        rendered = sensor.render(cap, depth_mm=0.9, hardness="40A", fidelity=fidelity, seed=5)
        pressed = sensor.press("sphere", radius_mm=6, depth_mm=0.9, hardness="40A", fidelity=fidelity, seed=5)
        diff = np.abs(rendered.frame.astype(int) - pressed.frame.astype(int))
        assert diff.max() <= 1, (fidelity, diff.max())
        assert abs(rendered.force_n - pressed.force_n) < 1e-3 * pressed.force_n
        assert rendered.report["shape"] == "height map"
        # The library's own time for the press, which python/bench/press_overhead.py
        # measures the binding against.
        assert 0 < rendered.library_s


def test_a_mesh_given_as_arrays_presses_as_the_same_mesh_from_its_file():
    pear = ROOT / "scenes/meshes/pear.obj"
    vertices, faces = _obj(pear)
    sensor = tactex.Sensor()
    from_arrays = sensor.press(mesh=(vertices, faces), depth_mm=0.8, hardness="40A", seed=1)
    from_file = sensor.press("mesh", mesh=pear, depth_mm=0.8, hardness="40A", seed=1)
    assert np.array_equal(from_arrays.frame, from_file.frame)
    assert abs(from_arrays.force_n - from_file.force_n) < 1e-6 * from_file.force_n

    class Trimesh:  # what trimesh.Trimesh offers the package: vertices and faces
        def __init__(self, v, f):
            self.vertices, self.faces = v, f

    sequence = sensor.press_sequence(mesh=Trimesh(vertices, faces), hardness="40A", seed=1)
    assert sequence.frames.shape == (8, 240, 320, 3)


def test_a_contact_stepped_along_a_path_gives_each_steps_press():
    """The object a simulator moves under the pad, pressed step by step: each step is the
    press of its pose and depth (same figures, same frame bytes given the step's seed), a
    mesh as a height map alike, and a pose off the pad is refused naming pose."""
    sensor = tactex.Sensor()
    path = [(0.4, None), (0.8, (2.0, -1.0, 30.0)), (0.4, None)]
    contact = sensor.contact(radius_mm=6, hardness="40A", fidelity="halfspace", seed=3)
    frames = []
    for k, (depth, pose) in enumerate(path):
        step = contact.step(depth, pose)
        alone = sensor.press(radius_mm=6, hardness="40A", fidelity="halfspace", depth_mm=depth,
                             pose=pose, seed=3 + 2 + k)
        assert step.force_n == alone.force_n
        assert np.array_equal(step.frame, alone.frame), k
        assert np.array_equal(step.fields["pressure_mpa"], alone.fields["pressure_mpa"])
        assert step.reference is contact.reference
        frames.append(step.frame)
    assert not np.array_equal(frames[0], frames[2]), "each step draws its own noise"
    w, h = sensor.size
    ys, xs = np.mgrid[0:h, 0:w]
    r2 = ((xs + 0.5 - w / 2) ** 2 + (ys + 0.5 - h / 2) ** 2) * sensor.mm_per_px**2
    cap = np.where(r2 <= 36.0, np.sqrt(np.maximum(36.0 - r2, 0.0)), np.nan)
    mapped = sensor.contact(height_map_mm=cap, hardness="40A", fidelity="rigid").step(0.5)
    assert mapped.report["shape"] == "height map" and mapped.force_n > 0
    with pytest.raises(tactex.InvalidArgument, match="pose"):
        contact.step(0.5, (40.0, 0.0, 0.0))
    with pytest.raises(tactex.InvalidArgument, match="depth_mm"):
        contact.step(float("nan"))


def test_a_press_imprint_stands_where_the_pose_puts_the_object():
    for x, y in [(0.0, 0.0), (3.0, -2.0), (-6.5, 4.0)]:
        press = tactex.Sensor().press("sphere", radius_mm=4, modulus_mpa=1.0, depth_mm=0.4, pose=(x, y, 0))
        normal = press.fields["gel_normal_mm"]
        cell, (x0, y0) = press.field_grid
        row, col = np.unravel_index(np.argmax(normal), normal.shape)
        deepest = (x0 + (col + 0.5) * cell, y0 + (row + 0.5) * cell)
        assert np.hypot(deepest[0] - x, deepest[1] - y) <= 1.5 * cell, (x, y, deepest)
        assert press.report["at_mm"] == [x, y]
    # A box's imprint turns with it: its long side along x, then along y.
    def extent(yaw):
        normal = tactex.Sensor().press("box", size_mm=(8, 3, 5), modulus_mpa=1.0, depth_mm=0.3,
                                       pose=(0, 0, yaw)).fields["gel_normal_mm"]
        rows, cols = np.nonzero(normal > 0.5 * normal.max())
        return np.ptp(cols), np.ptp(rows)
    (wx, wy), (tx, ty) = extent(0), extent(90)
    assert wx > 2 * wy and ty > 2 * tx


def test_a_press_sequence_is_eight_frames_from_first_contact_and_harder_pushes_back_harder():
    soft = tactex.Sensor().press_sequence("sphere", radius_mm=8, modulus_mpa=0.3, seed=4)
    hard = tactex.Sensor().press_sequence("sphere", radius_mm=8, modulus_mpa=3.0, seed=4)
    for seq in (soft, hard):
        assert seq.frames.shape == (8, 240, 320, 3) and seq.reference.shape == (240, 320, 3)
        assert seq.travel_mm == [0.25 * k for k in range(8)]
        forces = seq.force_n
        assert all(b > a for a, b in zip(forces, forces[1:])), forces
        assert seq.labels["contact"]["fired_by"], seq.labels["contact"]
    # Hertz: at equal travel a stiffer object takes more force (and less of the approach).
    assert hard.force_n[-1] > 1.5 * soft.force_n[-1]
    # The recorded frames change against the reference, more as the press deepens.
    change = [np.abs(f.astype(int) - soft.reference.astype(int)).mean() for f in soft.frames]
    assert change[-1] > change[0] > 0


def test_generated_samples_equal_the_data_set_datagen_writes(cli, tmp_path):
    out = tmp_path / "set"
    cli("datagen", "tactile", "--count", "6", "--seed", "11", "--format", "npz", "--shard", "1/2",
        "--out", str(out))
    lines = [json.loads(line) for line in (out / "shard-1-of-2.jsonl").read_text().splitlines()]
    samples = list(tactex.generate(6, seed=11, shard=(1, 2)))
    assert [s.index for s in samples] == [1, 3, 5] == [line["index"] for line in lines]
    for s, line in zip(samples, lines):
        with np.load(out / line.pop("files")[0]) as z:
            assert np.array_equal(s.frames, z["frames"])
        assert s.labels == line


def test_generate_starts_anywhere_and_samples_depend_on_seed_and_index_alone():
    whole = {s.index: s for s in tactex.generate(4, seed=3)}
    tail = list(tactex.generate(4, seed=3, start=2, batch=1))
    assert [s.index for s in tail] == [2, 3]
    for s in tail:
        assert np.array_equal(s.frames, whole[s.index].frames) and s.labels == whole[s.index].labels
    other = next(iter(tactex.generate(1, seed=4)))
    assert not np.array_equal(other.frames, whole[0].frames)


def test_ask_returns_what_ask_json_reproducible_prints(cli):
    prompt = "Which fruit is the softest?"
    printed = json.loads(cli("ask", "--json", "--reproducible", "--seed", "2", prompt).stdout)
    assert tactex.ask(prompt, seed=2) == printed
    assert printed["objects"], "the demo's fruit are touched"


def test_ask_takes_the_cameras_misplacement_and_calibration_as_the_cli_does(cli, tmp_path):
    # A calibration that believes the camera 5 mm off the scene's pose, turned a little.
    calib = tmp_path / "calib.toml"
    calib.write_text("[camera]\nposition_m = [0.005, 0.0, 0.7]\n"
                     "rotation_xyzw = [0.99999, 0.0044, 0.0, 0.0]\n")
    prompt = "How hard is the lime?"
    flags = ["--camera-error-mm", "20", "--camera-error-deg", "2", "--camera-error-seed", "3",
             "--camera-calibration", str(calib)]
    printed = json.loads(cli("ask", "--json", "--reproducible", *flags, prompt).stdout)
    got = tactex.ask(prompt, camera_error_mm=20, camera_error_deg=2, camera_error_seed=3,
                     camera_calibration=calib)
    assert got == printed
    plain = tactex.ask(prompt)
    moved = [abs(a - b) for a, b in zip(got["objects"][0]["position_m"], plain["objects"][0]["position_m"])]
    assert max(moved[:2]) > 0.005, f"the misplaced, miscalibrated camera places the lime elsewhere: {moved}"


FOTS = ROOT / "tests/fixtures/fots"
FOTS_SCALE = dict(ball_radius_mm=2.35, mm_per_px=0.051072522982635343)


def test_calibrate_writes_the_profile_the_cli_writes_and_returns_its_fit(cli, tmp_path):
    inputs = dict(images=FOTS / "ball-presses", annotations=FOTS / "ball-presses/annotations.csv",
                  background=FOTS / "background.png")
    fit = tactex.calibrate(**inputs, **FOTS_SCALE, markers=FOTS / "markers/press.png", out=tmp_path / "py/mine.toml",
                           interval_placements=0)
    printed = json.loads(cli(
        "calibrate", "--images", str(inputs["images"]), "--annotations", str(inputs["annotations"]),
        "--background", str(inputs["background"]), "--ball-radius-mm", "2.35",
        "--mm-per-px", "0.051072522982635343", "--markers", str(FOTS / "markers/press.png"),
        "--interval-placements", "0", "--out", str(tmp_path / "cli/mine.toml"), "--json").stdout)
    assert fit.pop("profile") == str(tmp_path / "py/mine.toml")
    printed.pop("profile")
    assert fit == printed
    for name in ["mine.toml", "mine.background.png"]:
        assert (tmp_path / "py" / name).read_bytes() == (tmp_path / "cli" / name).read_bytes()
    # Six of the nine presses (every third is held out), a table that fits them within a few
    # grey levels, and the real sensor's 9 x 11 marker grid read from its frame.
    assert fit["presses"] == 6 and max(fit["rms_grey"]) < 10 and fit["glow"]
    assert (fit["markers"]["cols"], fit["markers"]["rows"]) == (9, 11)
    sensor = tactex.Sensor(tmp_path / "py/mine.toml")
    assert sensor.name == "mine" and sensor.size == (240, 320) and sensor.markers == (9, 11)


def test_compare_scores_held_out_real_presses_as_the_cli_does(cli):
    profile = FOTS / "profile/fots-9.toml"
    scored = tactex.compare(profile, FOTS / "ball-presses", FOTS / "ball-presses/annotations.csv", device="cpu")
    printed = json.loads(cli(
        "compare", "--sensor", str(profile), "--images", str(FOTS / "ball-presses"),
        "--annotations", str(FOTS / "ball-presses/annotations.csv"), "--device", "cpu", "--json").stdout)
    assert scored == printed
    assert [p["image"] for p in scored["presses"]] == ["0005.png", "0009.png", "0014.png"]
    # The rendered press is closer to the real frame over the contact than the bare
    # background is: the press, not the background, carries the score.
    assert scored["mean"]["ssim_contact"] > scored["background_only_mean"]["ssim_contact"]


def test_read_reads_a_real_press_as_the_cli_does(cli, tmp_path):
    profile, frame = FOTS / "profile/fots-9.toml", FOTS / "ball-presses/0014.png"
    read = tactex.read(frame, sensor=profile, out=tmp_path / "read.png")
    printed = json.loads(cli("read", str(frame), "--sensor", str(profile), "--json").stdout)
    depth = read.pop("indentation_mm")
    assert read == printed
    assert depth.shape == (320, 240) and depth.dtype == np.float32
    # The map's deepest pixels are the peak; the marked contact is 39 px = 2.0 mm, the ball
    # 2.35 mm.
    assert abs(float(np.sort(depth.ravel())[-20:].mean()) - read["peak_depth_mm"]) < 1e-3
    assert 1.5 < read["contact_radius_mm"] < 3.2
    assert (tmp_path / "read.png").is_file()
    with pytest.raises(ValueError, match="reference: needed"):
        tactex.read(frame)


def test_compare_rebuilds_a_recorded_session_as_the_cli_does(cli, tmp_path):
    session = tmp_path / "session"
    cli("ask", "--record", str(session), "--seed", "3", "Which fruit is the softest?")
    scored = tactex.compare(session=session)
    printed = json.loads(cli("compare", "--session", str(session), "--json").stdout)
    assert scored == printed
    # A twin session rebuilt by the same twin: every press agrees with itself.
    assert scored["presses"] and scored["mean_ssim"] > 0.99


@pytest.mark.parametrize(
    "call, error, names",
    [
        (lambda: tactex.Sensor().press(depth_mm=-1), ValueError, "depth_mm"),
        (lambda: tactex.Sensor().press(depth_mm=1, fidelity="soft"), ValueError, "fidelity"),
        (lambda: tactex.Sensor().press(depth_mm=1, hardness="hard as nails"), ValueError, "hardness"),
        (lambda: tactex.Sensor().press("box", depth_mm=1, size_mm=(1, 2), hardness="40A"), ValueError, "size_mm"),
        (lambda: tactex.Sensor("no/such/profile.toml"), FileNotFoundError, "profile.toml"),
        (lambda: tactex.Sensor().press_sequence(modulus_mpa=1, phase_mm=0.3), ValueError, "phase_mm"),
        (lambda: tactex.Sensor().press(depth_mm=1, modulus_mpa=1, pose=(30, 0, 0)), ValueError, "pose"),
        (lambda: tactex.Sensor().press(depth_mm=1, modulus_mpa=1, pose=(1, 2)), ValueError, "pose"),
        (lambda: tactex.Sensor().press("mesh", depth_mm=1, mesh="no/such.obj", hardness="40A"), FileNotFoundError, "no/such.obj"),
        (lambda: tactex.Sensor().render(np.full((3, 3), np.inf), depth_mm=0.5, hardness="rigid"), ValueError,
         "height_map_mm"),
        (lambda: tactex.Sensor().render(np.zeros(5), depth_mm=0.5, hardness="rigid"), ValueError, "height_map_mm"),
        (lambda: tactex.Sensor().render(np.zeros((4, 4)), depth_mm=0.5, hardness="rigid", mm_per_px=-1), ValueError,
         "mm_per_px"),
        (lambda: tactex.Sensor().press(mesh=(np.zeros((4, 3)), [[0, 1, 9]]), depth_mm=0.5, hardness="40A"),
         ValueError, "mesh"),
        (lambda: tactex.Sensor().press(mesh=(np.zeros((4, 2)), [[0, 1, 2]]), depth_mm=0.5, hardness="40A"),
         ValueError, "mesh"),
        (lambda: tactex.Sensor().press(mesh=(np.zeros((4, 3)), [[0, 1, 2]]), depth_mm=0.5, hardness="40A"),
         ValueError, "mesh"),
        (lambda: list(tactex.generate(2, fidelity="soft")), ValueError, "fidelity"),
        (lambda: tactex.Sensor().render(None, depth_mm=0.5, hardness="40A"), ValueError, "height_map_mm"),
        (lambda: tactex.Sensor().render([[1, 2], [3]], depth_mm=0.5, hardness="40A"), ValueError, "height_map_mm"),
        (lambda: tactex.Sensor().render(np.zeros((4, 4)), depth_mm=0.5, hardness="40A", mm_per_px="abc"), ValueError,
         "mm_per_px"),
        (lambda: tactex.Sensor().render(np.where(np.eye(50) > 0, 1e20, 1.0), depth_mm=0.5, hardness="40A"),
         ValueError, "height_map_mm"),
        (lambda: tactex.Sensor().render(np.zeros((2000, 2000)), depth_mm=0.5, hardness="40A", mm_per_px=0.001),
         ValueError, "sample it coarser"),
        (lambda: tactex.Sensor().press("sphere", radius_mm=5, depth_mm=0.5), ValueError, "hardness"),
        (lambda: tactex.Sensor().press(mesh={"vertices": 0}, depth_mm=0.5, hardness="40A"), ValueError, "mesh"),
        (lambda: tactex.Sensor().press(mesh=([[0, 0, 0], [10, 0, 0], [0, 10, 0], [0, 0, 10]],
                                             [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]),
                                       depth_mm=0.3, hardness="rigid"), ValueError, "mesh_scale"),
        (lambda: list(tactex.generate(2, shapes=["cube"])), ValueError, "shapes"),
        (lambda: list(tactex.generate(2, shard=(2, 2))), ValueError, "shard"),
        (lambda: tactex.ask(""), ValueError, "prompt"),
        (lambda: tactex.ask("Which car is the fastest?"), ValueError, "prompt"),
        (lambda: tactex.ask("Which fruit is the softest?", scene="no/such/scene.toml"), FileNotFoundError, "scene.toml"),
        (lambda: tactex.ask("Which fruit is the softest?", fidelity="soft"), ValueError, "fidelity"),
        (lambda: tactex.calibrate(FOTS / "ball-presses", FOTS / "ball-presses/annotations.csv",
                                  FOTS / "background.png", ball_radius_mm=0, mm_per_px=0.05, out="x.toml"),
         ValueError, "ball_radius_mm"),
        (lambda: tactex.calibrate(FOTS / "ball-presses", FOTS / "no-such.csv", FOTS / "background.png",
                                  **FOTS_SCALE, out="x.toml"), FileNotFoundError, "no-such.csv"),
        (lambda: tactex.compare(ROOT / "tests/fixtures/fots/background.png", FOTS / "ball-presses",
                                FOTS / "ball-presses/annotations.csv"), ValueError, "background.png"),
        (lambda: tactex.compare(session=ROOT / "no/such/session"), FileNotFoundError, "no/such/session"),
        # From the hostile-input review of the typed requests and Sensor.contact:
        (lambda: tactex.Sensor().press(depth_mm=10**400, hardness="40A"), ValueError, "depth_mm"),
        (lambda: tactex.Sensor().press(depth_mm=True, hardness="40A"), ValueError, "depth_mm"),
        (lambda: tactex.Sensor().press(depth_mm="1", hardness="40A"), ValueError, "depth_mm"),
        (lambda: tactex.Sensor().press(depth_mm=1, hardness="40A", pose="123"), ValueError, "pose"),
        (lambda: tactex.Sensor().press(depth_mm=1, hardness="40A", size_mm={1: 1, 2: 2, 3: 3},
                                       shape="box"), ValueError, "size_mm"),
        (lambda: tactex.Sensor().press("box", mesh=(np.eye(3), [[0, 1, 2]]), depth_mm=1, hardness="40A"),
         ValueError, "shape"),
        (lambda: tactex.Sensor().contact(mesh=(np.full((4, 3), np.nan), [[0, 1, 2], [0, 2, 3]]),
                                         hardness="40A"), ValueError, "mesh"),
        (lambda: tactex.Sensor().contact(radius_mm=4, mm_per_px=4, hardness="40A"), ValueError, "mm_per_px"),
        (lambda: tactex.Sensor().contact(hardness="40A").step(10**400), ValueError, "depth_mm"),
        (lambda: tactex.Sensor(3), ValueError, "profile"),
        (lambda: list(tactex.generate(1, seed=-1)), ValueError, "seed"),
        (lambda: list(tactex.generate("2")), ValueError, "count"),
        (lambda: list(tactex.generate(2, shard="0/1")), ValueError, "shard"),
        (lambda: tactex.Sensor().press_sequence(hardness="40A", phase_mm=None), ValueError, "phase_mm"),
        (lambda: tactex.ask("Which fruit is the softest?", reproducible="no"), ValueError, "reproducible"),
        (lambda: tactex.ask("Which fruit is the softest?", camera_error_mm=500), ValueError, "camera_error_mm"),
        (lambda: tactex.ask("Which fruit is the softest?", camera_error_deg="2"), ValueError, "camera_error_deg"),
        (lambda: tactex.ask("Which fruit is the softest?", camera_error_seed=-1), ValueError, "camera_error_seed"),
        (lambda: tactex.ask("Which fruit is the softest?", camera_calibration="no/such/calib.toml"),
         FileNotFoundError, "calib.toml"),
        (lambda: tactex.ask("Which fruit is the softest?", camera_calibration=ROOT / "devices.example.toml"),
         ValueError, "devices.example.toml"),
        (lambda: tactex.read(ROOT / "tests"), ValueError, "tests"),
        (lambda: tactex.read(None), ValueError, "image"),
    ],
)
def test_bad_arguments_raise_with_one_line_naming_them(call, error, names):
    """The exception's type follows the kind of mistake, judged by the error's types in the
    library (python/src/lib.rs, src/app/error_kind.rs), not by its words; each is a
    tactex.TactexError, and its message names the keyword, not the CLI's flag."""
    with pytest.raises(error) as raised:
        call()
    assert isinstance(raised.value, tactex.TactexError)
    message = str(raised.value)
    assert names in message, message
    assert "\n" not in message and "--" not in message, message


def test_a_nan_depth_is_an_invalid_argument_naming_depth_mm():
    with pytest.raises(tactex.InvalidArgument, match="depth_mm"):
        tactex.Sensor().press(depth_mm=float("nan"), hardness="40A")


def test_an_output_the_disk_refuses_is_a_runtime_error_naming_it(tmp_path):
    blocker = tmp_path / "a-file"
    blocker.write_text("not a folder")
    with pytest.raises(RuntimeError) as raised:
        tactex.compare(FOTS / "profile/fots-9.toml", FOTS / "ball-presses", FOTS / "ball-presses/annotations.csv",
                       device="cpu", out=blocker / "out")
    assert isinstance(raised.value, tactex.Failure)
    assert str(raised.value).startswith("out ") and "\n" not in str(raised.value)


def _draw_worker_share(args):
    count, seed, worker, workers = args
    share = tactex.worker_shard((0, 1), worker, workers)
    return [(s.index, s.frames.tobytes()) for s in tactex.generate(count, seed, shard=share)]


def test_two_worker_processes_draw_each_sample_exactly_once():
    count, seed = 5, 21
    with multiprocessing.get_context("spawn").Pool(2) as pool:
        shares = pool.map(_draw_worker_share, [(count, seed, w, 2) for w in range(2)])
    drawn = sorted(i for share in shares for i, _ in share)
    assert drawn == list(range(count))
    alone = {s.index: s.frames.tobytes() for s in tactex.generate(count, seed)}
    for share in shares:
        for i, frames in share:
            assert frames == alone[i]


def _torch():
    """torch, or a skip where it is not installed; CI sets TACTEX_REQUIRE_TORCH, so that there
    a missing torch fails instead of passing by skipping."""
    if os.environ.get("TACTEX_REQUIRE_TORCH"):
        import torch

        return torch
    return pytest.importorskip("torch", reason="torch is not installed (tactex[torch])")


def test_a_torch_data_loader_with_two_workers_yields_each_sample_once():
    torch = _torch()
    from tactex.torch import TactileStream

    # Drawn here first, so that the workers are forked from a process whose thread pool runs:
    # a pool that did not survive the fork would hang them.
    alone = sorted(float(np.log(s.modulus_mpa)) for s in tactex.generate(5, 21))
    stream = TactileStream(5, seed=21)
    loader = torch.utils.data.DataLoader(stream, batch_size=None, num_workers=2, timeout=300)
    targets = sorted(float(t) for _, t in loader)
    assert len(targets) == 5 and np.allclose(targets, alone)


def test_a_torch_folder_reads_every_shard_datagen_wrote_in_index_order(cli, tmp_path):
    torch = _torch()
    from tactex.torch import TactileFolder

    out = tmp_path / "set"
    for shard in ("0/2", "1/2"):
        cli("datagen", "tactile", "--count", "3", "--seed", "5", "--shard", shard, "--out", str(out))
    folder = TactileFolder(out)
    drawn = list(tactex.generate(3, seed=5))
    assert len(folder) == 3 and [line["index"] for line in folder.lines] == [0, 1, 2]
    for k, s in enumerate(drawn):
        frames, target = folder[k]
        assert frames.dtype == torch.uint8 and tuple(frames.shape) == s.frames.shape
        assert np.array_equal(frames.numpy(), s.frames)
        assert abs(float(target) - float(np.log(s.modulus_mpa))) < 1e-6
    with pytest.raises(FileNotFoundError, match="dataset.json"):
        TactileFolder(tmp_path / "nothing")
