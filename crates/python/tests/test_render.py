"""Scenes loaded and rendered from Python: the image against Mitsuba 3's reference, parameters,
AOVs, determinism, the GIL, Ctrl-C, and the errors bad arguments raise."""

import os
import signal
import threading
import time
from pathlib import Path

import numpy as np
import pytest

import pathlab


def reference_mean(data, depth="inf"):
    """The reference image's mean and its standard error, per channel (Mitsuba 3, 4096 spp)."""
    mean = pathlab.read(data / "cornell-box" / f"mean-maxdepth-{depth}.exr")
    stderr = pathlab.read(data / "cornell-box" / f"stderr-maxdepth-{depth}.exr")
    n = mean.shape[0] * mean.shape[1]
    se = np.sqrt((stderr.astype(np.float64) ** 2).sum(axis=(0, 1))) / n
    return mean.astype(np.float64).mean(axis=(0, 1)), se


def test_the_built_in_box_matches_the_reference_within_4_standard_errors(data):
    scene = pathlab.load("cornell-box")
    out = pathlab.render(scene, spp=64, seed=3, sampler="independent", aovs=("variance", "samples"))
    image = out["image"]
    assert isinstance(image, np.ndarray) and isinstance(image, pathlab.Image)
    assert image.shape == (256, 256, 3) and image.dtype == np.float32
    assert out["variance"].shape == (256, 256, 3)
    assert out["samples"].shape == (256, 256) and np.all(out["samples"] == 64)
    # One output may be named alone.
    assert set(pathlab.render(scene, spp=1, resolution=(4, 4), aovs="samples")) == {"image", "samples"}
    n = 256 * 256
    ours = image.astype(np.float64).mean(axis=(0, 1))
    ours_se = np.sqrt(out["variance"].astype(np.float64).sum(axis=(0, 1))) / n
    ref, ref_se = reference_mean(data)
    z = (ours - ref) / np.sqrt(ours_se**2 + ref_se**2)
    assert np.all(np.abs(z) < 4), (ours, ref, z)
    # The test has power: a box 2% darker is told apart.
    z_dark = (0.98 * ours - ref) / np.sqrt(ours_se**2 + ref_se**2)
    assert np.any(np.abs(z_dark) > 4), z_dark


def test_the_same_seed_gives_the_same_image_for_any_thread_count():
    scene = pathlab.load("cornell-box")
    one = pathlab.render(scene, spp=4, seed=7, resolution=(48, 40), threads=1)
    two = pathlab.render(scene, spp=4, seed=7, resolution=(48, 40), threads=2)
    assert one.shape == (40, 48, 3)
    assert np.array_equal(one, two)
    other = pathlab.render(scene, spp=4, seed=8, resolution=(48, 40), threads=2)
    assert not np.array_equal(one, other)


def test_a_mitsuba_file_takes_parameters(data):
    path = data / "cornell-box" / "scene.xml"
    scene = pathlab.load(str(path), resx=64, resy=32, spp=8, max_depth=3)
    assert scene.resolution == (64, 32)
    assert scene.spp == 8
    image = pathlab.render(scene, seed=1)
    assert image.shape == (32, 64, 3)
    # max_depth=3 in Mitsuba's convention is two bounces here: the image is darker than the
    # unbounded one, and equals a render asked for max_depth=2 to the bit.
    full = pathlab.render(pathlab.load(str(path), resx=64, resy=32), spp=8, seed=1)
    assert image.mean() < full.mean()
    assert np.array_equal(image, pathlab.render(scene, seed=1, max_depth=2))


def test_a_files_crop_window_is_the_part_rendered(tmp_path):
    # pbrt-v4's cropwindow [x0 x1 y0 y1] as fractions: the middle half of the top half.
    path = tmp_path / "crop.pbrt"
    path.write_text(
        'LookAt 0 0 5  0 0 0  0 1 0\n'
        'Camera "perspective"\n'
        'Film "rgb" "integer xresolution" 40 "integer yresolution" 20'
        ' "float cropwindow" [ 0.25 0.75 0 0.5 ]\n'
        "WorldBegin\n"
        'LightSource "infinite" "rgb L" [ 1 1 1 ]\n'
        'Shape "sphere"\n'
    )
    image = pathlab.render(pathlab.load(str(path)), spp=4, seed=1)
    assert image.shape == (20, 40, 3)
    inside = np.zeros(image.shape[:2], dtype=bool)
    inside[0:10, 10:30] = True
    assert (image[inside] > 0).all()
    assert (image[~inside] == 0).all()


def test_parameters_a_format_cannot_use_are_warned_about():
    with pytest.warns(UserWarning, match="parameter 'resx' is not used"):
        pathlab.load("cornell-box", resx=64)


def test_scene_attributes_change_what_is_rendered():
    scene = pathlab.load("cornell-box")
    info = scene.info()
    assert info["triangles"] == 36 and info["lights"] == {"emissive mesh": 1}
    assert info["resolution"] == (256, 256)
    scene.resolution = (20, 10)
    assert pathlab.render(scene, spp=1).shape == (10, 20, 3)
    before = pathlab.render(scene, spp=2, seed=1)
    camera = scene.camera
    scene.camera = {"fov": camera["fov"] / 2}
    assert scene.camera["fov"] == pytest.approx(camera["fov"] / 2)
    assert not np.array_equal(before, pathlab.render(scene, spp=2, seed=1))
    scene.camera = {"fov": camera["fov"]}
    assert np.array_equal(before, pathlab.render(scene, spp=2, seed=1))


def test_bounce_outputs_add_up_to_the_image():
    scene = pathlab.load("cornell-box")
    keys = [f"bounce:{k}" for k in range(4)]
    out = pathlab.render(scene, spp=4, seed=2, max_depth=3, resolution=(32, 32), aovs=keys)
    total = sum(out[k].astype(np.float64) for k in keys)
    assert np.allclose(total, out["image"], rtol=1e-5, atol=1e-6)
    assert out["bounce:0"].mean() > 0 and out["bounce:2"].mean() > 0


def test_direct_lighting_strategies_differ_in_variance_not_in_mean():
    scene = pathlab.load("cornell-box")
    stats = {}
    for strategy in ("hemisphere", "cosine", "light"):
        out = pathlab.render(scene, spp=16, seed=5, integrator="direct", direct=strategy,
                             sampler="independent", resolution=(64, 64), aovs=("variance",))
        n = 64 * 64
        stats[strategy] = (out["image"].astype(np.float64).mean(),
                           np.sqrt(out["variance"].astype(np.float64).sum() / 3) / n,
                           out["variance"].mean())
    (m_h, se_h, v_h), (m_l, se_l, v_l) = stats["hemisphere"], stats["light"]
    assert abs(m_h - m_l) < 4 * np.hypot(se_h, se_l), stats
    assert v_l < v_h / 4, stats


def test_the_path_tracers_ways_of_finding_light_differ_in_variance_not_in_mean():
    scene = pathlab.load("cornell-box")
    stats = {}
    for lighting in ("mis", "bsdf", "light"):
        out = pathlab.render(scene, spp=16, seed=7, max_depth=2, lighting=lighting,
                             sampler="independent", resolution=(48, 48), aovs=("variance",))
        n = 48 * 48
        stats[lighting] = (out["image"].astype(np.float64).mean(),
                           np.sqrt(out["variance"].astype(np.float64).sum() / 3) / n,
                           out["variance"].mean())
    m_mis, se_mis, v_mis = stats["mis"]
    for other in ("bsdf", "light"):
        m, se, _ = stats[other]
        assert abs(m - m_mis) < 4 * np.hypot(se, se_mis), stats
    # The box's light is small: BSDF sampling alone rarely finds it.
    assert stats["bsdf"][2] > 2 * v_mis, stats


def test_the_bidirectional_path_tracer_agrees_with_the_path_tracer():
    # Light traced to the lens lands on other pixels, so the standard error of the image mean
    # comes from independent renders (seeds).
    scene = pathlab.load("cornell-box")
    means = {}
    for integrator in ("path", "bdpt"):
        m = [pathlab.render(scene, spp=8, seed=s, integrator=integrator, sampler="independent",
                            resolution=(48, 48)).astype(np.float64).mean() for s in range(6)]
        means[integrator] = (np.mean(m), np.std(m, ddof=1) / np.sqrt(len(m)))
    (a, sa), (b, sb) = means["path"], means["bdpt"]
    assert abs(a - b) < 4 * np.hypot(sa, sb), means


def test_the_gil_is_released_while_rendering():
    scene = pathlab.load("cornell-box")
    ticks = []
    stop = threading.Event()

    def count():
        while not stop.is_set():
            ticks.append(1)
            time.sleep(0.001)

    t = threading.Thread(target=count)
    t.start()
    start = len(ticks)
    pathlab.render(scene, spp=64, resolution=(128, 128))
    stop.set()
    t.join()
    assert len(ticks) - start > 20


def test_ctrl_c_stops_a_render_within_a_second():
    scene = pathlab.load("cornell-box")
    sent = []

    def interrupt():
        sent.append(time.monotonic())
        os.kill(os.getpid(), signal.SIGINT)

    timer = threading.Timer(0.5, interrupt)
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        pathlab.render(scene, spp=1 << 20)
    stopped = time.monotonic()
    timer.join()
    assert sent and stopped - sent[0] < 1.0, stopped - sent[0]
    # The interpreter and the module go on working.
    assert pathlab.render(scene, spp=1, resolution=(8, 8)).shape == (8, 8, 3)


@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({"spp": -1}, "spp -1: must be a whole number"),
        ({"spp": 0}, "spp 0"),
        ({"integrator": "pathh"}, "unknown integrator 'pathh'"),
        ({"direct": "light"}, 'needs integrator="direct"'),
        ({"integrator": "direct", "direct": "lamp"}, "unknown direct-lighting strategy 'lamp'"),
        ({"sampler": "halton"}, "unknown sampler 'halton'"),
        ({"resolution": (0, 10)}, "resolution (0, 10)"),
        ({"max_depth": -2}, "max_depth -2"),
        ({"threads": -1}, "threads -1"),
        ({"aovs": ("depth",)}, "unknown output 'depth'"),
        ({"aovs": ("bounce:4",), "max_depth": 3}, "beyond the largest bounce 3"),
        ({"aovs": ("bounce:1",), "integrator": "direct"}, "needs the path tracer"),
        ({"lighting": "nee"}, "unknown lighting 'nee' (expected mis, bsdf or light)"),
        ({"lighting": "bsdf", "integrator": "direct"}, 'this render uses integrator="direct"'),
    ],
)
def test_bad_render_arguments_raise_value_errors(kwargs, message):
    scene = pathlab.load("cornell-box")
    with pytest.raises(ValueError) as e:
        pathlab.render(scene, **kwargs)
    assert message in str(e.value)


def test_scenes_that_cannot_be_read_raise_scene_errors(tmp_path):
    with pytest.raises(pathlab.SceneError, match="missing.xml"):
        pathlab.load(str(tmp_path / "missing.xml"))
    with pytest.raises(pathlab.SceneError, match="unknown built-in scene 'no-such-box'"):
        pathlab.load("no-such-box")
    bad = tmp_path / "bad.xml"
    bad.write_text('<scene version="3.0.0">\n  <shape type="sphere">\n</scene>\n')
    with pytest.raises(pathlab.SceneError, match="bad.xml:3"):
        pathlab.load(str(bad))
    scene = pathlab.load("cornell-box")
    with pytest.raises(ValueError, match="unknown key"):
        scene.camera = {"zoom": 2}
    with pytest.raises(ValueError, match="between 1 and 16384"):
        scene.resolution = (-4, 4)
    with pytest.raises(ValueError, match=r"camera\['fov'\] 200: must be an angle"):
        scene.camera = {"fov": 200.0}
    with pytest.raises(ValueError, match=r"camera\['lens_radius'\] -1: must be"):
        scene.camera = {"lens_radius": -1.0}
    with pytest.raises(ValueError, match=r"camera\['focal_distance'\] 0: must be"):
        scene.camera = {"focal_distance": 0.0}
    with pytest.raises(ValueError, match="exposure NaN: must be a finite"):
        pathlab.write(tmp_path / "x.png", np.zeros((2, 2, 3), dtype=np.float32), exposure=float("nan"))


def test_images_are_read_and_written(tmp_path):
    rng = np.random.default_rng(1)
    image = rng.random((6, 5, 3), dtype=np.float32) * 4
    pathlab.write(tmp_path / "a.exr", image)
    assert np.array_equal(pathlab.read(tmp_path / "a.exr"), image)
    grey = np.linspace(0, 1, 30).reshape(5, 6)
    pathlab.write(str(tmp_path / "g.png"), grey)
    back = pathlab.read(tmp_path / "g.png")
    assert back.shape == (5, 6, 3)
    assert np.allclose(back[..., 0], grey, atol=0.01)
    png = pathlab.Image._repr_png_(image.view(pathlab.Image))
    assert png[:8] == b"\x89PNG\r\n\x1a\n"
    # The course's tone map, as `pathlab render --tonemap cs184`: 0.5 becomes (√2 · 0.5)^(1/2.2)
    # in 8 bits, which reads back through the sRGB curve.
    half = np.full((2, 2), 0.5)
    pathlab.write(tmp_path / "c.png", half, tonemap="cs184")
    byte = round(255 * (np.sqrt(2) * 0.5) ** (1 / 2.2)) / 255
    srgb_decoded = ((byte + 0.055) / 1.055) ** 2.4
    assert np.allclose(pathlab.read(tmp_path / "c.png"), srgb_decoded, atol=1e-3)
    assert pathlab.png_bytes(half, tonemap="cs184") == (tmp_path / "c.png").read_bytes()
    with pytest.raises(ValueError, match="unknown tone map 'aces'"):
        pathlab.write(tmp_path / "c.png", half, tonemap="aces")
    with pytest.raises(ValueError, match="exposure inf"):
        pathlab.png_bytes(half, exposure=float("inf"))
    with pytest.raises(ValueError, match="unknown image format"):
        pathlab.write(tmp_path / "a.tiff", image)
    with pytest.raises(ValueError, match="shape"):
        pathlab.write(tmp_path / "a.exr", np.zeros((2, 2, 4)))
    with pytest.raises(OSError, match="nothing.exr"):
        pathlab.read(tmp_path / "nothing.exr")


def test_the_readme_example_runs(tmp_path, monkeypatch, capsys):
    readme = (Path(__file__).resolve().parents[3] / "README.md").read_text()
    section = readme[readme.index("## Python"):]
    code = section[section.index("```python\n") + 10:]
    code = code[:code.index("```")]
    monkeypatch.chdir(tmp_path)
    exec(compile(code, "README.md", "exec"), {})
    assert (tmp_path / "box.png").exists()
    assert "ChiSquareTest(" in capsys.readouterr().out


def test_an_image_is_an_array_that_reduces_to_numbers_and_shows_itself(data):
    image = pathlab.render(pathlab.load(data / "cornell-box" / "scene.xml", resx=8, resy=8), spp=1)
    assert isinstance(image, np.ndarray)
    mean = image.mean()
    assert not isinstance(mean, np.ndarray) and float(mean) > 0
    assert isinstance(image * 2, pathlab.Image)
    assert image._repr_png_()[:4] == b"\x89PNG"
    assert image[..., 0]._repr_png_()[:4] == b"\x89PNG"
    assert image[0, 0]._repr_png_() is None
    assert pathlab.load.__doc__.startswith("Load a scene")
