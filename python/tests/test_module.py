"""The Python module `bpm` against the program: the same image bit for bit, errors, interruption,
progress, and scenes rendered again with overrides without being read again.

Run by ctest (Python.Module) with PYTHONPATH at the built module and BPM_BINARY the program."""
import json
import os
import pathlib
import shutil
import signal
import subprocess
import threading
import time

import numpy as np
import pytest

import bpm

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
SCENES = os.path.join(ROOT, "scenes")
BPM_BINARY = os.environ.get("BPM_BINARY", os.path.join(ROOT, "build", "bpm"))
SMALL = dict(resolution=(32, 24), spp=2, seed=3)


def scene(name):
    return os.path.join(SCENES, name)


def program(tmp_path, *args):
    """Runs `bpm render ARGS -q -o tmp/out.exr` and returns the output's path."""
    out = str(tmp_path / "out.exr")
    subprocess.run([BPM_BINARY, "render", *args, "-q", "-o", out], check=True,
                   capture_output=True, text=True)
    return out


@pytest.mark.parametrize("integrator", ["path", "bpm", "fpm"])
def test_image_equals_the_programs_bit_for_bit(tmp_path, integrator):
    out = program(tmp_path, scene("caustic-sphere.pbrt"), "--integrator", integrator,
                  "--resolution", "40x30", "--spp", "3", "--seed", "7")
    r = bpm.render(scene("caustic-sphere.pbrt"), integrator=integrator, resolution="40x30",
                   spp=3, seed=7)
    assert r.image.shape == (30, 40, 3)
    assert r.image.dtype == np.float32
    assert np.array_equal(r.image, bpm.read_exr(out))
    assert r.image.mean() > 0
    assert (r.bias is None) == (integrator == "path")
    assert r.stats["settings"]["integrator"] == integrator
    assert r.stop_reason == "samples"


def test_arrays_and_statistics(tmp_path):
    r = bpm.render(scene("cornell-box.pbrt"), integrator="bpm", **SMALL)
    for a in (r.rms, r.bias, r.total_error):
        assert a.shape == (24, 32, 3)
    assert r.luminance.shape == r.luminance_error.shape == r.passes.shape == (24, 32)
    assert np.all(r.total_error >= r.rms - 1e-6)
    assert np.all(r.luminance >= 0) and r.luminance.mean() > 0
    assert r.stats["result"]["iterations"] == 2
    assert r.stats["result"]["luminance_mean_cd_per_m2"] == pytest.approx(
        float(r.luminance.mean()), rel=1e-4)
    assert "bpm" in r.stats and "outputs" not in r.stats
    assert r.sensors.shape == (0,)


def test_save_writes_the_programs_files(tmp_path):
    r = bpm.render(scene("cornell-box.pbrt"), integrator="bpm", **SMALL)
    out = tmp_path / "box.exr"
    r.save(str(out))
    for suffix in (".exr", ".png", ".error.png", ".luminance.png", ".bias.png", ".json"):
        assert (tmp_path / ("box" + suffix)).is_file(), suffix
    assert np.array_equal(bpm.read_exr(str(out)), r.image)
    record = json.loads((tmp_path / "box.json").read_text())
    assert record["outputs"]["exr"] == str(out)
    assert record["result"] == r.stats["result"]
    with pytest.raises(bpm.Error, match="does not exist"):
        r.save(str(tmp_path / "missing" / "x.exr"))
    with pytest.raises(bpm.Error, match=r"\.exr"):
        r.save(str(tmp_path / "x.png"))


def test_sensors_equal_the_programs(tmp_path):
    sensors = scene("cornell-box-sensors.txt")
    out = program(tmp_path, scene("cornell-box.pbrt"), "--no-image", "--sensors", sensors,
                  "--spp", "4", "--seed", "2")
    rows = (tmp_path / "out.sensors.csv").read_text().splitlines()[1:]
    lux = np.array([float(row.split(",")[6]) for row in rows])
    r = bpm.render(scene("cornell-box.pbrt"), no_image=True, sensors=sensors, spp=4, seed=2)
    assert r.sensors.shape == (11,) and np.all(r.sensor_errors >= 0) and r.sensor_errors.max() > 0
    np.testing.assert_allclose(r.sensors, lux, rtol=1e-8)
    assert not os.path.exists(out)  # --no-image: no EXR
    # Sensors as a list of points and normals, as the same lines in a file.
    points = [(0.5, 0.5, 0.5, 0, 1, 0), (0.5, 0.5, 1, 0, 0, -1)]
    listed = tmp_path / "two.txt"
    listed.write_text("".join(" ".join(str(v) for v in p) + "\n" for p in points))
    program(tmp_path, scene("cornell-box.pbrt"), "--no-image", "--sensors", str(listed),
            "--spp", "4", "--seed", "2")
    rows = (tmp_path / "out.sensors.csv").read_text().splitlines()[1:]
    s = bpm.render(scene("cornell-box.pbrt"), no_image=True, sensors=points, spp=4, seed=2)
    np.testing.assert_allclose(s.sensors, [float(row.split(",")[6]) for row in rows], rtol=1e-8)


def test_scene_text_renders_as_its_file(monkeypatch):
    text = open(scene("cornell-box.pbrt")).read()
    monkeypatch.chdir(SCENES)  # the text's relative names resolve against the current folder
    a = bpm.render(text, **SMALL)
    b = bpm.render(scene("cornell-box.pbrt"), **SMALL)
    assert np.array_equal(a.image, b.image)


def test_errors_name_file_line_and_column(tmp_path):
    bad = tmp_path / "bad.pbrt"
    bad.write_text('Camera "perspective"\nWorldBegin\nShape "spherex"\n')
    with pytest.raises(bpm.Error, match=rf"^{bad}:3:1: shape \"spherex\" is not supported"):
        bpm.render(str(bad))
    with pytest.raises(bpm.Error, match=r"^<string>:2:1: "):
        bpm.render('WorldBegin\nNoSuchDirective 1\n')
    with pytest.raises(bpm.Error, match="missing.pbrt"):
        bpm.Scene(str(tmp_path / "missing.pbrt"))
    with pytest.raises(bpm.Error, match="--k0"):
        bpm.render(scene("cornell-box.pbrt"), k0=-1)
    with pytest.raises(bpm.Error, match="no-such-setting"):
        bpm.render(scene("cornell-box.pbrt"), no_such_setting=1)
    with pytest.raises(TypeError, match="save"):
        bpm.render(scene("cornell-box.pbrt"), output="x.exr")
    with pytest.raises(TypeError):
        bpm.Scene(42)


def test_bad_values_from_python_are_errors_not_crashes():
    s = bpm.Scene(scene("office-downlight.pbrt"))
    with pytest.raises(bpm.Error, match="finite"):
        s.translate_light(0, (float("nan"), 0, 0))
    with pytest.raises(bpm.Error, match="finite"):
        s.translate_light(0, (1e39, 0, 0))
    with pytest.raises(bpm.Error, match="finite"):
        s.look_at((0, 1, float("inf")), (0, 0, 0), (0, 1, 0))
    with pytest.raises(bpm.Error, match="finite"):
        s.set_light(0, "float scale", float("nan"))
    with pytest.raises(bpm.Error, match="finite"):
        s.render(k0=float("nan"), **SMALL)
    with pytest.raises(bpm.Error, match="finite"):
        s.render(time=float("inf"), resolution=(8, 8))
    with pytest.raises(TypeError, match="resolution"):
        s.render(resolution=(16.5, 16), spp=1)
    with pytest.raises(TypeError, match="sensor"):
        s.render(no_image=True, sensors=[0, 0, 0, 0, 1, 0], spp=1)
    with pytest.raises(TypeError, match="material"):
        s.set_material(1.5, "float eta", 1.5)
    with pytest.raises(TypeError, match="progress"):
        s.render(progress=3, **SMALL)
    assert s.overrides == []  # nothing above changed the scene
    # numpy's bools and numbers are Python's
    r = s.render(integrator="bpm", no_guide=np.True_, k1=np.float32(2.5), **SMALL)
    assert r.stats["bpm"]["settings"]["guide_emission"] is False
    assert r.stats["bpm"]["settings"]["k1"] == pytest.approx(2.5)


def test_paths_may_be_path_objects(tmp_path):
    s = bpm.Scene(pathlib.Path(scene("cornell-box.pbrt")))
    r = s.render(no_image=True, sensors=pathlib.Path(scene("cornell-box-sensors.txt")), spp=1)
    assert r.sensors.shape == (11,)
    r = s.render(**SMALL)
    r.save(tmp_path / "p.exr")
    assert np.array_equal(bpm.read_exr(tmp_path / "p.exr"), r.image)


def test_a_scene_is_read_once_and_rendered_with_overrides(tmp_path):
    path = tmp_path / "office.pbrt"
    for name in ("office-downlight.pbrt",):
        shutil.copy(scene(name), path)
    shutil.copytree(scene("luminaires"), tmp_path / "luminaires")
    s = bpm.Scene(str(path))
    path.write_text("this is no longer a scene\n")  # rendering again does not read it again
    assert [l["type"] for l in s.lights] == ["goniometric", "goniometric"]
    base = s.render(integrator="path", **SMALL)
    s.set_light(0, "float scale", 2.0)
    s.set_light(1, "float scale", 2.0)
    twice = s.render(integrator="path", **SMALL)
    # Light is linear in the lights' scale: the same paths, every value doubled.
    np.testing.assert_allclose(twice.image, 2 * base.image, rtol=1e-5, atol=1e-7)
    s.translate_light(0, (0, -1.0, 0))
    moved = s.render(integrator="path", **SMALL)
    assert not np.allclose(moved.image, twice.image)
    s.look_at((2, 1.5, -1.0), (2, 0.5, 1.5), (0, 1, 0))
    s.set_camera("float fov", 40)
    looked = s.render(integrator="path", **SMALL)
    assert not np.allclose(looked.image, moved.image)
    assert looked.stats["overrides"] == [
        "set_light(0, 'float scale', 2.0)", "set_light(1, 'float scale', 2.0)",
        "translate_light(0, [0.0, -1.0, 0.0])",
        "look_at([2.0, 1.5, -1.0], [2.0, 0.5, 1.5], [0.0, 1.0, 0.0])",
        "set_camera('float fov', 40)"]
    assert "overrides" not in base.stats
    with pytest.raises(IndexError):
        s.set_light(2, "float scale", 1.0)
    with pytest.raises(bpm.Error, match="TYPE NAME"):
        s.set_light(0, "scale", 1.0)
    with pytest.raises(bpm.Error, match="numbers"):
        s.set_light(0, "float scale", "two")


def test_named_material_override():
    s = bpm.Scene(scene("cornell-box.pbrt"))
    assert "white" in s.materials
    base = s.render(**SMALL)
    s.set_material("red", "rgb reflectance", [0.05, 0.05, 0.65])
    blue = s.render(**SMALL)
    # Red and blue trade places on the left wall.
    assert blue.image[..., 2].mean() > base.image[..., 2].mean()
    assert blue.image[..., 0].mean() < base.image[..., 0].mean()
    with pytest.raises(KeyError, match="white"):
        s.set_material("nosuch", "float eta", 1.5)


def test_progress_is_called_from_the_calling_thread():
    calls = []

    def progress(p):
        calls.append((threading.get_ident(), p["passes"], p["delta"]))

    r = bpm.render(scene("cornell-box.pbrt"), resolution=(32, 24), spp=20, progress=progress)
    assert calls, "the callback was never called"
    assert all(ident == threading.get_ident() for ident, _, _ in calls)
    assert calls[-1][1] == 20 and r.stop_reason == "samples"


def test_a_callback_stops_the_render_or_raises():
    r = bpm.render(scene("cornell-box.pbrt"), resolution=(32, 24), spp=100000,
                   progress=lambda p: p["passes"] < 3)
    assert r.stop_reason == "interrupted"
    assert 3 <= r.stats["result"]["passes"] < 100000 and r.image.mean() > 0

    def fails(p):
        raise ValueError("from the callback")

    with pytest.raises(ValueError, match="from the callback"):
        bpm.render(scene("cornell-box.pbrt"), resolution=(32, 24), spp=100000, progress=fails)
    # numpy's False stops it too
    r = bpm.render(scene("cornell-box.pbrt"), resolution=(32, 24), spp=100000,
                   progress=lambda p: np.bool_(p["passes"] < 3))
    assert r.stop_reason == "interrupted"


def test_ctrl_c_inside_the_callback_returns_the_result_so_far():
    def interrupted(p):
        if p["passes"] >= 2:
            raise KeyboardInterrupt

    r = bpm.render(scene("cornell-box.pbrt"), resolution=(32, 24), spp=100000,
                   progress=interrupted)
    assert r.stop_reason == "interrupted" and r.stats["result"]["passes"] >= 2


def test_renders_take_turns_and_a_scene_does_not_change_under_one():
    s = bpm.Scene(scene("cornell-box.pbrt"))
    # A callback can neither start a render nor change the scene being rendered.
    with pytest.raises(bpm.Error, match="callback cannot start another"):
        s.render(resolution=(32, 24), spp=50, progress=lambda p: bpm.render(s, **SMALL))
    with pytest.raises(bpm.Error, match="being rendered"):
        s.render(resolution=(32, 24), spp=50,
                 progress=lambda p: s.set_material("white", "rgb reflectance", [0.5, 0.5, 0.5]))
    # A render on another thread waits for this one, and neither stops the other.
    other = {}
    thread = threading.Thread(target=lambda: other.update(
        r=bpm.render(scene("cornell-box.pbrt"), resolution=(32, 24), time=1)))
    thread.start()
    mine = bpm.render(scene("cornell-box.pbrt"), resolution=(32, 24), spp=100000,
                      progress=lambda p: p["passes"] < 5)
    thread.join()
    assert mine.stop_reason == "interrupted"
    assert other["r"].stop_reason == "time"


def test_ctrl_c_returns_the_result_so_far():
    timer = threading.Timer(1.0, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    t = time.monotonic()
    r = bpm.render(scene("cornell-box.pbrt"), resolution=(32, 24), time=120)
    timer.join()
    assert time.monotonic() - t < 60
    assert r.stop_reason == "interrupted"
    assert r.stats["result"]["passes"] >= 1 and r.image.mean() > 0
    # The next render is not interrupted.
    assert bpm.render(scene("cornell-box.pbrt"), **SMALL).stop_reason == "samples"


def test_the_gil_is_released_while_rendering():
    counts = [0]
    running = threading.Event()

    def count():
        while not running.is_set():
            counts[0] += 1

    worker = threading.Thread(target=count)
    worker.start()
    try:
        r = bpm.render(scene("cornell-box.pbrt"), resolution=(64, 48), time=1.5)
    finally:
        running.set()
        worker.join()
    assert r.stop_reason == "time"
    # With the GIL held through the render the counter would stand still for 1.5 s; Python counts
    # millions a second.
    assert counts[0] > 100000
