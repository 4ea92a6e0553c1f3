#!/usr/bin/python3
"""End-to-end test of octiso-view in headless Chromium (issue 20), ctest `ViewerEndToEnd`.

Starts octiso-view on a synthetic volume, opens the page with Selenium, moves the isovalue slider
with the keyboard and orbits with a mouse drag on the image, waits for the full frame of that
input, and checks that the frame the page shows is, pixel for pixel, the image octiso-render
writes for the command the page offers ("copy command"): the raw RGBA frame the page received on
loopback, then the same view asked again as PNG (the encoding used from another host; decoded by
a small decoder below), and each time the page's canvas read back as it is on screen. Then the
shadows toggle, once: the settled frame (the light kit with shadow rays) must equal octiso-render's
image for the command the page then offers, which carries --shadows; and "save image" must download
a PNG of exactly those pixels.

    tests/view/e2e_view.py TOOLS_DIR

Exit status 0 pass, 1 fail, 77 skip (chromium, chromedriver or python3-selenium missing); with
OCTISO_REQUIRE_ALL=1 a missing piece fails instead (tests/test_util/skip.h, the same rule)."""
import base64
import os
import select
import shlex
import shutil
import struct
import subprocess
import sys
import tempfile
import zlib

SKIP = 77


def give_up(what):
    if os.environ.get("OCTISO_REQUIRE_ALL", "") not in ("", "0"):
        print(f"e2e_view: {what} (OCTISO_REQUIRE_ALL is set: a skip fails)")
        sys.exit(1)
    print(f"e2e_view: skipped: {what}")
    sys.exit(SKIP)


def decode_png(data):
    """8-bit RGB or RGBA, non-interlaced PNG -> (width, height, bytes of RGB rows). Enough for what
    OpenImageIO and Chromium write here; anything else is an error, not a guess."""
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        raise ValueError("not a PNG")
    pos, idat, header = 8, b"", None
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        pos += 12 + length
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
        elif kind == b"IEND":
            break
    width, height, depth, colour, _, _, interlace = header
    if depth != 8 or colour not in (2, 6) or interlace != 0:
        raise ValueError(f"unsupported PNG (depth {depth}, colour type {colour}, interlace {interlace})")
    bpp = 3 if colour == 2 else 4
    raw, stride = zlib.decompress(idat), width * bpp
    out, prev = bytearray(), bytearray(stride)
    for y in range(height):
        filt, line = raw[y * (stride + 1)], bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - bpp] if i >= bpp else 0
            b, c = prev[i], prev[i - bpp] if i >= bpp else 0
            if filt == 1:
                line[i] = (line[i] + a) & 255
            elif filt == 2:
                line[i] = (line[i] + b) & 255
            elif filt == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif filt == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
            elif filt != 0:
                raise ValueError(f"bad PNG filter {filt}")
        out += line if bpp == 3 else bytes(v for j, v in enumerate(line) if j % 4 != 3)
        prev = line
    return width, height, bytes(out)


def main():
    tools = sys.argv[1]
    try:
        from selenium import webdriver
        from selenium.webdriver.chrome.service import Service
        from selenium.webdriver.common.action_chains import ActionChains
        from selenium.webdriver.common.by import By
        from selenium.webdriver.common.keys import Keys
        from selenium.webdriver.support.ui import WebDriverWait
    except ImportError:
        give_up("python3-selenium is not installed")
    chromium, driver_path = shutil.which("chromium"), shutil.which("chromedriver")
    if not chromium or not driver_path:
        give_up("chromium or chromium-driver is not installed")

    work = tempfile.mkdtemp(prefix="octiso_e2e_view_")
    viewer = driver = None
    try:
        oct_path = os.path.join(work, "ml.oct")
        subprocess.run([f"{tools}/octiso-convert", "--synthetic", "marschner-lobb:41", "-o", oct_path],
                       check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        viewer = subprocess.Popen([f"{tools}/octiso-view", oct_path, "--port", "0", "--threads", "2"],
                                  stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        ready, _, _ = select.select([viewer.stdout], [], [], 20)
        if not ready:
            raise AssertionError("octiso-view printed no URL")
        line = viewer.stdout.readline()
        url = line.split(" at ")[-1].strip()
        assert url.startswith("http://127.0.0.1:"), line

        options = webdriver.ChromeOptions()
        options.binary_location = chromium
        for flag in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
                     "--window-size=800,600", "--force-device-scale-factor=1", "--force-color-profile=srgb"):
            options.add_argument(flag)
        driver = webdriver.Chrome(service=Service(executable_path=driver_path), options=options)
        driver.set_script_timeout(90)
        driver.get(url)
        wait = WebDriverWait(driver, 90)   # a bound, not a measurement: the ASan build renders slowly
        settled = lambda d: d.execute_script("return window.octiso.settled && window.octiso.lastFrame !== null")
        wait.until(settled)
        first = driver.execute_script("return window.octiso.lastFrame.command")

        # Isovalue: five steps right with the keyboard, as a user would nudge it.
        iso = driver.find_element(By.ID, "iso")
        iso.click()
        iso_text = driver.find_element(By.ID, "iso-text")
        iso_before = iso_text.text
        iso.send_keys(Keys.ARROW_RIGHT * 5)
        iso_after = iso_text.text   # what the user reads beside the slider
        assert iso_after != iso_before, "the slider did not move"
        # Orbit: a drag on the image (its centre is clear of the panel at 800x600).
        image = driver.find_element(By.ID, "frame")
        ActionChains(driver).move_to_element(image).click_and_hold().move_by_offset(60, 15) \
            .move_by_offset(40, -30).release().perform()
        wait.until(lambda d: settled(d) and d.execute_script("return window.octiso.lastFrame.command") != first)

        def shown_frame():
            """The newest frame as received (raw RGBA bytes, or the PNG) and the canvas on screen."""
            return driver.execute_async_script("""
                const done = arguments[arguments.length - 1];
                const f = window.octiso.lastFrame;
                const canvas = document.getElementById('frame');
                const px = Array.from(canvas.getContext('2d').getImageData(0, 0, canvas.width, canvas.height).data);
                const result = {command: f.command, iso: f.iso, full: f.full, width: f.width, height: f.height,
                                encoding: f.encoding, canvas: px, natural: [canvas.width, canvas.height],
                                view: [window.innerWidth, window.innerHeight], errors: window.octiso.errors};
                if (f.encoding === 'rgba') { result.rgba = Array.from(f.bytes); done(result); return; }
                const reader = new FileReader();
                reader.onload = () => { result.png = reader.result.split(',')[1]; done(result); };
                reader.readAsDataURL(f.blob);""")

        def rgb_of_rgba(values, what):
            assert all(v == 255 for v in values[3::4]), f"{what}: not opaque"
            return bytes(v for j, v in enumerate(values) if j % 4 != 3)

        def check(shown, expected_encoding, ref=None):
            """Asserts the frame is the full one of the current input, shown pixel for pixel as
            received; returns octiso-render's image for the offered command (run once, then reused)."""
            assert shown["errors"] == 0, "the page showed an error"
            assert shown["encoding"] == expected_encoding, (shown["encoding"], expected_encoding)
            assert shown["full"], "the settled frame is the full-resolution one"
            assert [shown["width"], shown["height"]] == shown["view"], (shown["width"], shown["height"], shown["view"])
            assert shown["natural"] == shown["view"], (shown["natural"], shown["view"])
            assert shown["iso"] == iso_after, (shown["iso"], iso_after)
            command = shown["command"]
            assert f" --iso {iso_after} " in command, command
            if ref is None:
                # The command the page offers, run as given (only the output name replaced).
                args = shlex.split(command)
                assert args[0] == "octiso-render" and args[1] == oct_path, args
                out = os.path.join(work, "reference.png")
                args = [f"{tools}/octiso-render"] + args[1:-1] + [out]
                subprocess.run(args, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
                ref = (command,) + decode_png(open(out, "rb").read())
            assert command == ref[0], (command, ref[0])
            ref_w, ref_h, ref_rgb = ref[1:]
            if shown["encoding"] == "rgba":
                got_w, got_h, got = shown["width"], shown["height"], rgb_of_rgba(shown["rgba"], "received frame")
            else:
                got_w, got_h, got = decode_png(base64.b64decode(shown["png"]))
            assert (got_w, got_h) == (ref_w, ref_h) == tuple(shown["view"]), ((got_w, got_h), (ref_w, ref_h))
            assert len(got) == len(ref_rgb), (len(got), len(ref_rgb))
            differing = sum(1 for i in range(0, len(ref_rgb), 3) if ref_rgb[i:i + 3] != got[i:i + 3])
            assert differing == 0, f"{differing} of {ref_w * ref_h} pixels differ from octiso-render's image ({shown['encoding']})"
            # What is on screen: the page's canvas has the same pixels.
            canvas = rgb_of_rgba(shown["canvas"], "canvas")
            differing = sum(1 for i in range(0, len(ref_rgb), 3) if ref_rgb[i:i + 3] != canvas[i:i + 3])
            assert differing == 0, f"{differing} pixels of the displayed image differ from octiso-render's image ({shown['encoding']})"
            return ref

        # On loopback the page asks for raw RGBA frames; then the same view once more as PNG (the
        # encoding it uses from another host), which must show the same pixels.
        ref = check(shown_frame(), "rgba")
        seq = driver.execute_script("""
            window.octiso.encoding = 'png';
            document.getElementById('iso').dispatchEvent(new Event('change'));
            return window.octiso.lastFrame.seq;""")
        wait.until(lambda d: settled(d) and d.execute_script("return window.octiso.lastFrame.seq") > seq)
        check(shown_frame(), "png", ref)
        # Shadows: one click on the toggle; the full frame that settles is the light kit with
        # shadow rays, and the offered command (with --shadows) must write exactly those pixels.
        seq = driver.execute_script("window.octiso.encoding = 'rgba'; return window.octiso.lastFrame.seq;")
        driver.find_element(By.ID, "shadows").click()
        wait.until(lambda d: settled(d) and d.execute_script("return window.octiso.lastFrame.seq") > seq)
        shadowed = shown_frame()
        assert " --shadows " in shadowed["command"] and "--shading" not in shadowed["command"], shadowed["command"]
        shadow_ref = check(shadowed, "rgba")
        assert shadow_ref[3] != ref[3], "the shadows toggle did not change the frame"
        # Save image: the PNG the page downloads holds the shown frame's pixels (the shadowed one),
        # named after its isovalue.
        driver.find_element(By.ID, "save").click()
        wait.until(lambda d: d.execute_script("return window.octiso.lastSaved !== null"))
        saved = driver.execute_async_script("""
            const done = arguments[arguments.length - 1];
            const s = window.octiso.lastSaved;
            const reader = new FileReader();
            reader.onload = () => done({name: s.name, png: reader.result.split(',')[1]});
            reader.readAsDataURL(s.blob);""")
        assert saved["name"].startswith(f"octiso_iso{iso_after}_") and saved["name"].endswith("_shadows.png"), saved["name"]
        saved_w, saved_h, saved_rgb = decode_png(base64.b64decode(saved["png"]))
        assert (saved_w, saved_h) == (shadow_ref[1], shadow_ref[2]), ((saved_w, saved_h), shadow_ref[1:3])
        differing = sum(1 for i in range(0, len(saved_rgb), 3) if saved_rgb[i:i + 3] != shadow_ref[3][i:i + 3])
        assert differing == 0, f"{differing} pixels of the saved image differ from octiso-render's"
        command, ref_w, ref_h, ref = ref
        background = ref[0:3]
        hit = sum(1 for i in range(0, len(ref), 3) if ref[i:i + 3] != background)
        assert hit > ref_w * ref_h // 20, f"only {hit} pixels show the surface: a trivial frame proves little"
        print(f"e2e_view: {ref_w}x{ref_h} frame at iso {iso_after} after an orbit equals octiso-render's "
              f"({hit} surface pixels): {command}")
        print(f"e2e_view: with shadows too: {shadow_ref[0]}")
        return 0
    finally:
        if driver is not None:
            driver.quit()
        if viewer is not None:
            viewer.terminate()
            try:
                viewer.wait(10)
            except subprocess.TimeoutExpired:
                viewer.kill()
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
