"""Face render cost (issue #6): CPU time of ``face.draw()`` per look, in headless Chromium.

Chromium runs with the browser tests' flags (``--disable-gpu``), so WebGL is SwiftShader,
the software rasteriser. The face is drawn on its own 680x700 canvas, once per animation
frame, from real mouth frames (a spoken sentence's marks, cycled), for FRAMES frames per
look, then again with WebGL removed (the canvas 2-D fallback). Prints median and p95 of
the ``ms`` that ``draw()`` returns (goal < 4 ms) and the median frame interval.

``draw()``'s time is the CPU side: it includes the rig and issuing GL calls, not the
rasteriser finishing them (that runs in the GPU process, overlapped with the next frame).
The "+finish" columns measure a second run's draw() followed by gl.finish(), i.e. CPU plus
the software rasteriser's time for the frame; they are not part of the goal.

Run: ``.venv/bin/python bench/bench_face_render.py``
"""

from __future__ import annotations

import json
import statistics
import urllib.request

from serverutil import CHROMIUM, percentile, running_server
from serverutil import CHROMIUM_ARGS as ARGS

FRAMES = 400
NO_WEBGL = """
const real = HTMLCanvasElement.prototype.getContext;
HTMLCanvasElement.prototype.getContext = function (kind, ...rest) {
  return /webgl/i.test(kind) ? null : real.call(this, kind, ...rest);
};
"""

MEASURE = """async ({look, frames, names, n}) => {
  const { createFace } = await import('/client/face.js');
  const c = document.createElement('canvas');
  c.style.cssText = 'width:680px;height:700px;display:block';
  document.body.append(c);
  const face = await createFace(c, { look });
  const ms = [], gaps = [], fin = [];
  const gl = face.backend === 'webgl' ? c.getContext('webgl') : null;   // the face's own context
  let last = null;
  const intervals = [];
  await new Promise((done) => {
    let k = 0;
    const tick = (now) => {
      if (last !== null) intervals.push(now - last);
      last = now;
      const mouth = { names, nodes: frames[k % frames.length], lipGap: 0, sample: k };
      const d = face.draw(mouth, now);
      ms.push(d.ms); gaps.push(d.lipGap);
      if (gl) { const t = performance.now(); gl.finish(); fin.push(d.ms + performance.now() - t); }
      if (++k < n) requestAnimationFrame(tick); else done();
    };
    requestAnimationFrame(tick);
  });
  c.remove();
  return { backend: face.backend, ms: ms.slice(20), fin: fin.slice(20), intervals,
           maxGap: Math.max(...gaps) };
}"""


def main() -> None:
    from playwright.sync_api import sync_playwright

    with running_server() as (host, _), sync_playwright() as p:
        url = f"http://{host}"
        req = urllib.request.Request(url + "/speak", method="POST",
                                     data=json.dumps({"text": "Hello! I am lipclock. My mouth "
                                                      "moves on the audio clock."}).encode(),
                                     headers={"Content-Type": "application/json"})
        body = json.load(urllib.request.urlopen(req))
        marks = json.load(urllib.request.urlopen(body["marks_url"]))
        frames, names = marks["mouth"]["frames"], marks["mouth"]["nodes"]
        browser = p.chromium.launch(executable_path=CHROMIUM, args=ARGS)
        print(f"face.draw() CPU ms over {FRAMES - 20} frames (680x700 canvas, "
              f"headless Chromium, SwiftShader); goal < 4 ms")
        print(f"{'backend':9} {'look':10} {'median':>7} {'p95':>7} {'max':>7} {'frame ms':>9}"
              f" {'+finish median':>15} {'p95':>6}")
        for init in (None, NO_WEBGL):
            page = browser.new_page(viewport={"width": 800, "height": 800})
            if init:
                page.add_init_script(init)
            page.goto(url + "/healthz")
            for look in ("wireframe", "shaded", "textured"):
                r = page.evaluate(MEASURE, {"look": look, "frames": frames, "names": names,
                                            "n": FRAMES})
                ms = r["ms"]
                print(f"{r['backend']:9} {look:10} {statistics.median(ms):7.2f} "
                      f"{percentile(ms, 95):7.2f} {max(ms):7.2f} "
                      f"{statistics.median(r['intervals']):9.1f}", end="")
                fin = r["fin"]
                print(f" {statistics.median(fin):15.2f} {percentile(fin, 95):6.2f}" if fin else "")
            page.close()
        browser.close()


if __name__ == "__main__":
    main()
