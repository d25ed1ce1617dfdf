"""`pathlab view` in a real browser: headless Chromium, driven through ChromeDriver (Debian's
`chromium` and `chromium-driver`), against the built-in Cornell box.

    PATHLAB=target/release/pathlab python3 -m pytest crates/view/tests/browser

`.ci/run` installs what it needs and runs it. With PATHLAB_SCREENSHOTS=DIR the screenshots go
to DIR, otherwise to a temporary folder; PATHLAB_VIEW_SIZE sets the image's size (64). The
README's pictures are made so:

    PATHLAB_VIEW_SIZE=256 PATHLAB_SCREENSHOTS=docs/view python3 -m pytest crates/view/tests/browser

What it checks, as a student would see it: the canvas shows the box (not blank, and as bright
as `pathlab render` draws the same settings); switching the direct-lighting strategy from
uniform hemisphere sampling to light sampling lowers the error the page reports; a clicked
pixel's 95% interval holds the pixel's value from a long render; the page logs no JavaScript
error."""
import json
import math
import os
import re
import subprocess
import tempfile
import time

import pytest
from PIL import Image
from selenium import webdriver
from selenium.webdriver.chrome.service import Service
from selenium.webdriver.common.action_chains import ActionChains
from selenium.webdriver.common.by import By
from selenium.webdriver.common.keys import Keys
from selenium.webdriver.support.ui import Select

PATHLAB = os.environ.get("PATHLAB", "target/release/pathlab")
CHROMIUM = os.environ.get("CHROMIUM", "/usr/bin/chromium")
CHROMEDRIVER = os.environ.get("CHROMEDRIVER", "/usr/bin/chromedriver")
SIZE = int(os.environ.get("PATHLAB_VIEW_SIZE", "64"))
# Rec. 709 luminance, the weights of the page's pixel statistics.
LUMINANCE = (0.2126, 0.7152, 0.0722)


@pytest.fixture(scope="module")
def shots():
    folder = os.environ.get("PATHLAB_SCREENSHOTS") or tempfile.mkdtemp(prefix="pathlab-view-")
    os.makedirs(folder, exist_ok=True)
    return folder


@pytest.fixture(scope="module")
def server():
    proc = subprocess.Popen(
        [PATHLAB, "view", "--port", "0", "-r", str(SIZE), str(SIZE)],
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
    )
    line = proc.stdout.readline()
    match = re.search(r"http://[\d.]+:\d+/", line)
    assert match, f"no address in {line!r}"
    yield match.group(0)
    proc.terminate()
    assert proc.wait(timeout=10) is not None


@pytest.fixture(scope="module")
def page(server):
    options = webdriver.ChromeOptions()
    options.binary_location = CHROMIUM
    for flag in (
        "--headless=new",
        "--no-sandbox",
        "--disable-gpu",
        "--disable-dev-shm-usage",
        "--disable-background-networking",
        "--disable-component-update",
        "--disable-sync",
        "--no-first-run",
        "--window-size=1200,1150",
    ):
        options.add_argument(flag)
    options.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    driver = webdriver.Chrome(service=Service(CHROMEDRIVER), options=options)
    driver.get(server)
    yield driver
    driver.quit()


def status(driver):
    """The status panel's numbers: samples per pixel, relative error, image generation."""
    text = driver.find_element(By.ID, "status").text
    spp = re.search(r"(\d+) samples per pixel", text)
    err = re.search(r"estimated relative error ([\d.]+) %", text)
    gen = re.search(r"image (\d+)", text)
    if not (spp and err and gen):
        return None
    return int(spp.group(1)), float(err.group(1)) / 100, int(gen.group(1))


def wait_for(driver, want, what, timeout=60):
    """The status once `want(status)` holds (failing after `timeout` seconds)."""
    end = time.time() + timeout
    while time.time() < end:
        s = status(driver)
        if s and want(s):
            return s
        time.sleep(0.05)
    pytest.fail(f"timed out waiting for {what}; status: {status(driver)}")


def canvas_mean(driver):
    """Mean of the canvas's R, G, B bytes."""
    return driver.execute_script(
        """
        const c = document.getElementById("image");
        const d = c.getContext("2d").getImageData(0, 0, c.width, c.height).data;
        let s = 0;
        for (let i = 0; i < d.length; i += 4) s += d[i] + d[i + 1] + d[i + 2];
        return s / (3 * d.length / 4);
        """
    )


def render(args, out):
    """Runs `pathlab render` at the page's size; its standard output."""
    cmd = [PATHLAB, "render", "-r", str(SIZE), str(SIZE), "-q", "-o", out] + args
    return subprocess.run(cmd, check=True, capture_output=True, text=True).stdout


# A pixel of the floor, lit directly.
FLOOR = (SIZE * 20 // 64, SIZE * 44 // 64)


def click_pixel(driver, x, y):
    """Clicks the image's pixel (x, y): its centre, from the element's centre (the offsets
    Selenium takes), inside the canvas's border."""
    canvas = driver.find_element(By.ID, "image")
    box = driver.execute_script(
        "const c = arguments[0], r = c.getBoundingClientRect();"
        "return [r.width, r.height, c.clientLeft, c.clientTop, c.clientWidth, c.clientHeight];",
        canvas)
    dx = box[2] + (x + 0.5) * box[4] / SIZE - box[0] / 2
    dy = box[3] + (y + 0.5) * box[5] / SIZE - box[1] / 2
    ActionChains(driver).move_to_element_with_offset(canvas, round(dx), round(dy)).click().perform()


def js_errors(driver):
    return [e for e in driver.get_log("browser") if e["level"] == "SEVERE"]


def test_the_canvas_shows_the_box_as_bright_as_a_render_of_the_same_settings(page, shots, tmp_path):
    s = wait_for(page, lambda s: s[0] >= 64, "64 samples per pixel")
    page.save_screenshot(os.path.join(shots, "view-path.png"))
    shown = canvas_mean(page)
    assert shown > 20, f"the canvas is blank (mean byte {shown})"
    # The page's starting controls are the scene's: the path tracer at its depth, its sampler.
    controls = page.execute_script("return stats.controls")
    out = str(tmp_path / "same.png")
    render(["-s", "256", "--sampler", controls["sampler"]] +
           (["-m", str(controls["max_depth"])] if controls["max_depth"] < 1000 else []), out)
    img = Image.open(out).convert("RGB")
    reference = sum(img.tobytes()) / (3 * SIZE * SIZE)
    assert abs(shown - reference) < 0.05 * reference, (
        f"canvas mean byte {shown:.2f} at {s[0]} spp against {reference:.2f} from pathlab render"
    )
    assert not js_errors(page)


def test_light_sampling_lowers_the_error_of_hemisphere_sampling(page, shots):
    Select(page.find_element(By.ID, "integrator")).select_by_value("direct")
    Select(page.find_element(By.ID, "direct")).select_by_value("hemisphere")
    wait_for(page, lambda s: page.execute_script(
        "return stats.controls.integrator === 'direct' && stats.controls.direct === 'hemisphere'"), "hemisphere")
    gen = status(page)[2]
    hemi = wait_for(page, lambda s: s[2] == gen and s[0] >= 16, "16 spp of hemisphere sampling")
    page.save_screenshot(os.path.join(shots, "view-hemisphere.png"))
    Select(page.find_element(By.ID, "direct")).select_by_value("light")
    light = wait_for(page, lambda s: s[2] > gen and s[0] >= hemi[0], "light sampling at as many spp")
    page.save_screenshot(os.path.join(shots, "view-light.png"))
    # Errors at one sample per pixel (they fall as 1/sqrt(spp)).
    e_hemi, e_light = hemi[1] * math.sqrt(hemi[0]), light[1] * math.sqrt(light[0])
    assert e_light < 0.75 * e_hemi, f"light {e_light:.3f} against hemisphere {e_hemi:.3f}"
    assert not js_errors(page)


def test_a_clicked_pixels_interval_holds_its_value(page, shots, tmp_path):
    # Direct lighting by light sampling (left on by the test before, or set here).
    Select(page.find_element(By.ID, "integrator")).select_by_value("direct")
    Select(page.find_element(By.ID, "direct")).select_by_value("light")
    x, y = FLOOR
    click_pixel(page, x, y)
    end = time.time() + 60
    text = ""
    while time.time() < end:
        text = page.find_element(By.ID, "pixel_text").text
        m = re.match(r"(\d+) samples, mean ([\d.e+-]+), 95% CI \[([\d.e+-]+), ([\d.e+-]+)\]", text)
        if m and int(m.group(1)) >= 256:
            break
        time.sleep(0.05)
    else:
        pytest.fail(f"no inspector reading with 256 samples: {text!r}")
    # The pixel the page took (Selenium's offsets are whole CSS pixels from the element's
    # centre, so the click may land on a neighbour).
    where = re.fullmatch(r"\((\d+), (\d+)\)", page.find_element(By.ID, "where").text)
    assert where, page.find_element(By.ID, "where").text
    px, py = int(where.group(1)), int(where.group(2))
    assert abs(px - x) <= 1 and abs(py - y) <= 1, f"clicked ({x}, {y}), the page took ({px}, {py})"
    x, y = px, py
    hist = page.find_element(By.ID, "hist_text").text
    assert re.match(r"histogram of the luminance of the first \d+ samples", hist), hist
    page.save_screenshot(os.path.join(shots, "view-inspector.png"))
    lo, hi = float(m.group(3)), float(m.group(4))
    # The pixel's value: the same estimator over 16384 samples, the pixel alone rendered (the
    # image's mean is then its value over the pixel count).
    controls = page.execute_script("return stats.controls")
    report = render(["--integrator", "direct", "--direct", "light", "--sampler", controls["sampler"],
                     "-s", "16384", "--crop", str(x), str(y), str(x + 1), str(y + 1), "--json"],
                    str(tmp_path / "long.exr"))
    rgb = [c * SIZE * SIZE for c in json.loads(report)["image_mean_rgb"]]
    value = sum(w * c for w, c in zip(LUMINANCE, rgb))
    assert lo <= value <= hi, f"pixel ({x}, {y}): {value} outside [{lo}, {hi}] ({text})"
    # The path tracer splits the pixel's light by bounce.
    Select(page.find_element(By.ID, "integrator")).select_by_value("path")
    end = time.time() + 60
    while page.find_element(By.ID, "bounces").get_attribute("hidden") is not None:
        assert time.time() < end, "no bounce split for the path tracer"
        time.sleep(0.05)
    wait_for(page, lambda s: s[0] >= 256, "256 spp of the path tracer")
    page.save_screenshot(os.path.join(shots, "view-bounces.png"))
    assert not js_errors(page)


def test_samples_at_a_clicked_point_are_drawn_with_their_estimates(page, shots):
    """The course's picture: N directions drawn at the point a pixel sees, by two strategies;
    light sampling brings light with more of them, and both estimates agree."""
    page.find_element(By.ID, "show_samples").click()
    estimates = {}
    for strategy in ("hemisphere", "light"):
        Select(page.find_element(By.ID, "strategy")).select_by_value(strategy)
        count = page.find_element(By.ID, "sample_count")
        count.clear()
        count.send_keys("256\n")
        click_pixel(page, *FLOOR)
        end = time.time() + 60
        while True:
            text = page.find_element(By.ID, "samples_text").text
            m = re.match(r"256 samples at \((\d+), (\d+)\): (\d+) bring light", text)
            shown = page.execute_script("return stats.sample_view && stats.sample_view.strategy")
            if m and shown == strategy:
                break
            assert time.time() < end, f"no samples drawn by {strategy}: {text!r}"
            time.sleep(0.05)
        est = re.search(r"estimate ([\d.e+-]+) ± ([\d.e+-]+)", text)
        assert est, text
        estimates[strategy] = (int(m.group(3)), float(est.group(1)), float(est.group(2)))
        # Lines are drawn over the image.
        drawn = page.execute_script(
            """const o = document.getElementById("overlay");
            const d = o.getContext("2d").getImageData(0, 0, o.width, o.height).data;
            let n = 0; for (let i = 3; i < d.length; i += 4) n += d[i] > 0; return n;""")
        assert drawn > 1000, f"{strategy}: {drawn} overlay pixels drawn"
        page.save_screenshot(os.path.join(shots, f"view-samples-{strategy}.png"))
    (lit_h, e_h, se_h), (lit_l, e_l, se_l) = estimates["hemisphere"], estimates["light"]
    assert lit_l > 4 * lit_h, estimates
    assert abs(e_h - e_l) < 4 * math.hypot(se_h, se_l), estimates
    assert not js_errors(page)


def test_dragging_orbits_and_shift_dragging_pans_the_camera(page):
    canvas = page.find_element(By.ID, "image")
    before = page.execute_script("return [stats.controls.orbit, stats.controls.pan]")
    ActionChains(page).move_to_element(canvas).click_and_hold().move_by_offset(40, 0) \
        .release().perform()
    ActionChains(page).key_down(Keys.SHIFT).move_to_element(canvas).click_and_hold() \
        .move_by_offset(0, 30).release().key_up(Keys.SHIFT).perform()
    end = time.time() + 30
    while True:
        orbit, pan = page.execute_script("return [stats.controls.orbit, stats.controls.pan]")
        if orbit[0] != before[0][0] and pan[1] != before[1][1]:
            break
        assert time.time() < end, f"orbit {orbit}, pan {pan} (before {before})"
        time.sleep(0.05)
    assert pan[0] == before[1][0], "a vertical shift-drag pans up or down only"
    assert not js_errors(page)
