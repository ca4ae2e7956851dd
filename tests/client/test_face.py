"""The face renderer (client/face.js) in real headless Chromium: every look loads clean and
opens its mouth while speaking (screenshots go to test-artifacts/), the drawn lip gap
follows speech, muscles move the mouth corners, bad looks warn, and canvas 2-D stands in
when WebGL is missing."""

from __future__ import annotations

import base64

import pytest
from browser_util import FACE_ARTIFACTS, HAVE_CHROMIUM, lip_gaps_while_speaking

pytestmark = pytest.mark.skipif(not HAVE_CHROMIUM, reason="Debian chromium missing")
LOOKS = ["wireframe", "shaded", "textured"]

NO_WEBGL = """
// a browser without WebGL: every webgl context request fails
const real = HTMLCanvasElement.prototype.getContext;
HTMLCanvasElement.prototype.getContext = function (kind, ...rest) {
  return /webgl/i.test(kind) ? null : real.call(this, kind, ...rest);
};
"""

# Keep the canvas of the first frame drawn with the mouth open wider than `min` mm
# (read in the same animation frame the face was drawn, so it is that frame).
CAPTURE_OPEN = """(min) => {
  window.openShot = null; window.maxGap = 0;
  const watch = () => {
    const g = window.lipclockDebug.lipGap;
    window.maxGap = Math.max(window.maxGap, g);
    if (g > min && !window.openShot)
      window.openShot = document.getElementById('face').toDataURL('image/png');
    requestAnimationFrame(watch);
  };
  requestAnimationFrame(watch);
}"""


def open_page(browser, url, init_script=None):
    page = browser.new_page(viewport={"width": 1000, "height": 700})
    page.errors = []
    page.warnings = []
    page.on("console", lambda m: (page.errors if m.type == "error" else page.warnings
                                  if m.type == "warning" else []).append(m.text))
    page.on("pageerror", lambda e: page.errors.append(str(e)))
    if init_script:
        page.add_init_script(init_script)
    page.goto(url + "/")
    page.wait_for_function("window.lipclockFace !== undefined &&"
                           " document.getElementById('status').textContent === 'connected'",
                           timeout=15000)
    return page


def speak_and_capture(page, name: str, text: str = "Wow, I am so happy to see you all.") -> float:
    page.evaluate(CAPTURE_OPEN, 6.0)
    page.fill("#text", text)
    page.click("#speak")
    page.wait_for_function("window.openShot !== null", timeout=15000)
    FACE_ARTIFACTS.mkdir(exist_ok=True)
    png = base64.b64decode(page.evaluate("window.openShot").split(",", 1)[1])
    (FACE_ARTIFACTS / f"{name}.png").write_bytes(png)
    return page.evaluate("window.maxGap")


def wait_until_silent(page):
    page.wait_for_function("window.lipclockDebug.audioSample === 0", timeout=15000)
    page.wait_for_timeout(100)


@pytest.mark.parametrize("look", LOOKS)
def test_each_look_loads_clean_and_opens_its_mouth_while_speaking(server, browser, look):
    page = open_page(browser, server)
    page.select_option("#look", look)
    assert page.evaluate("window.lipclockDebug.look") == look
    assert page.evaluate("window.lipclockDebug.backend") == "webgl"
    assert page.evaluate("window.lipclockFace.looks") == LOOKS
    peak = speak_and_capture(page, f"face-{look}")
    assert peak > 2.0  # the drawn mouth opened
    assert page.evaluate("window.lipclockDebug.drawMs") > 0
    wait_until_silent(page)
    assert page.evaluate("window.lipclockDebug.lipGap") < 0.2  # and closed again after
    assert not page.errors, page.errors
    page.close()


def test_the_drawn_lip_gap_follows_speech_and_returns_to_rest(server, browser):
    page = open_page(browser, server)
    page.evaluate(CAPTURE_OPEN, 100.0)   # only tracks the peak
    page.click("#speak")
    gaps = lip_gaps_while_speaking(page, 40, 25)
    assert max(gaps) > 2.0 and min(gaps) < max(gaps)  # it opens and moves
    wait_until_silent(page)
    assert page.evaluate("window.lipclockDebug.lipGap") == pytest.approx(0, abs=0.05)
    page.close()


def node_positions(page) -> dict[str, tuple[float, float]]:
    page.evaluate("new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r)))")
    names = page.evaluate("window.lipclockFace.nodeNames")
    return dict(zip(names, map(tuple, page.evaluate("window.lipclockFace.nodePositions()")),
                    strict=True))


def test_smile_lifts_and_widens_the_corners_and_frown_drops_them(server, browser):
    page = open_page(browser, server)
    rest = node_positions(page)
    page.evaluate("window.lipclockFace.setExpression({smile: 1})")
    smile = node_positions(page)
    for side, out in (("corner_l", -1), ("corner_r", 1)):
        assert smile[side][1] - rest[side][1] > 2.0                # up
        assert (smile[side][0] - rest[side][0]) * out > 2.0        # and out
    page.evaluate("window.lipclockFace.setExpression({smile: 0, frown: 1})")
    frown = node_positions(page)
    assert all(frown[c][1] < rest[c][1] - 2.0 for c in ("corner_l", "corner_r"))
    page.evaluate("window.lipclockFace.setExpression({frown: 7, smile: -1})")   # clamped
    assert page.evaluate("window.lipclockFace.expression") == {"smile": 0, "brow": 0, "frown": 1}
    page.evaluate("window.lipclockFace.setExpression({brow: 1})")  # other keys unchanged
    assert page.evaluate("window.lipclockFace.expression")["frown"] == 1
    assert not page.errors, page.errors
    page.close()


def test_an_unknown_look_warns_once_and_keeps_the_current_look(server, browser):
    page = open_page(browser, server)
    page.evaluate("window.lipclockFace.setLook('shaded')")
    page.evaluate("window.lipclockFace.setLook('bogus'); window.lipclockFace.setLook('bogus')")
    assert page.evaluate("window.lipclockFace.look") == "shaded"
    assert sum("bogus" in w for w in page.warnings) == 1
    assert not page.errors, page.errors
    page.close()


def test_without_webgl_every_look_draws_in_canvas_2d(server, browser):
    page = open_page(browser, server, NO_WEBGL)
    assert page.evaluate("window.lipclockDebug.backend") == "canvas2d"
    for look in LOOKS:
        page.select_option("#look", look)
        peak = speak_and_capture(page, f"face-canvas2d-{look}", "Hello, how are you?")
        assert peak > 2.0
        # something face-coloured is drawn where the cheek is, not just the background
        r, g, b = page.evaluate("""() => {
            const c = document.getElementById('face');
            const d = c.getContext('2d').getImageData(c.width * 0.62, c.height * 0.45, 1, 1).data;
            return [d[0], d[1], d[2]]; }""")
        assert (r, g, b) != (32, 37, 43)
        wait_until_silent(page)
    assert not page.errors, page.errors
    page.close()


BLINKS = """async () => {
  // a second face on its own canvas, a seeded random source and a synthetic clock:
  // 60 s of frames at 60 Hz, recording how shut the eyes were drawn on each
  const { createFace } = await import('/client/face.js');
  const canvas = document.createElement('canvas');
  canvas.style.cssText = 'width:300px;height:300px;position:fixed;left:0;top:0';
  document.body.appendChild(canvas);
  let seed = 12345;
  const random = () => {
    seed = (seed * 1103515245 + 12345) % 2147483648;
    return seed / 2147483648;
  };
  const face = await createFace(canvas, { look: 'shaded', random });
  const blink = [];
  let open = null, shut = null;
  for (let t = 0; t < 60000; t += 1000 / 60) {
    const b = face.draw(null, t).blink;
    blink.push(b);
    if (b === 0 && open === null) open = canvas.toDataURL();
    if (b > 0.9 && shut === null) shut = canvas.toDataURL();
  }
  canvas.remove();
  return { blink, differ: open !== null && shut !== null && open !== shut };
}"""


def test_eyes_blink_at_random_natural_intervals(server, browser):
    page = open_page(browser, server)
    got = page.evaluate(BLINKS)
    b = got["blink"]
    assert min(b) == 0 and max(b) > 0.9 and all(0 <= v <= 1 for v in b)
    shut = [i for i in range(1, len(b)) if b[i] > 0.5 >= b[i - 1]]   # frames a blink shuts
    assert 6 <= len(shut) <= 30, len(shut)   # people blink every 2-8 s at rest
    gaps_s = [(j - i) / 60 for i, j in zip(shut, shut[1:], strict=False)]
    assert all(1.5 <= g <= 8.5 for g in gaps_s), gaps_s
    assert len({round(g, 1) for g in gaps_s}) > len(gaps_s) // 2   # not a fixed period
    lengths = []                                                   # each one is brief
    for i in shut:
        k = i
        while k < len(b) and b[k] > 0:
            k += 1
        lengths.append((k - i) / 60)
    assert all(length < 0.3 for length in lengths), lengths
    assert got["differ"], "the drawn eyes look the same shut as open"
    assert not page.errors, page.errors
    page.close()
