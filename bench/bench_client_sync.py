"""Audio/mouth sync and render cost in a real browser (issue 6).

Starts `lipclock serve`, opens the page at "/" in Debian's chromium (headless, software
rendering), installs the page's sync probe (client/syncprobe.js) and speaks a few
sentences. On every animation frame the probe records the sample the mouth was drawn for
and the context time heard at that frame; an AudioWorklet tap records the audio that
really flowed. bench/clientsync.py matches the two (see its docstring). Then the same
again with the page and its WebSocket behind a proxy that delays every packet by
50 ms +/- 30 ms (order kept).

Goals: |median lag| <= 5 ms and p95 |lag| <= 20 ms; face render < 4 ms per frame.

    .venv/bin/python bench/bench_client_sync.py [--sentences 4] [--no-jitter]
"""

from __future__ import annotations

import argparse
import statistics
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from clientsync import analyse  # noqa: E402
from serverutil import CHROMIUM, CHROMIUM_ARGS, jitter_proxy_thread, running_server  # noqa: E402

ARGS = [*CHROMIUM_ARGS, "--autoplay-policy=no-user-gesture-required"]

SENTENCES = [
    "The quick brown fox jumps over the lazy dog.",
    "Please call Stella and ask her to bring these things with her from the store.",
    "My mouth moves on the audio clock, one frame at a time.",
    "Bob bought a big map of Boston, and Peter packed plenty of paper.",
    "When the sunlight strikes raindrops in the air, they act as a prism.",
    "We were away a year ago, and you are welcome to join us.",
]


def measure(browser, url: str, sentences: list[str], look: str | None = None) -> dict:
    """Speak the sentences on a fresh page at url; return the probe's snapshot."""
    page = browser.new_page(viewport={"width": 1000, "height": 700})
    errors: list[str] = []
    page.on("pageerror", lambda e: errors.append(str(e)))
    page.goto(url + "/")
    page.wait_for_function("window.lipclockClient && window.lipclockClient.ws &&"
                           " window.lipclockClient.ws.readyState === 1", timeout=20000)
    if look:
        page.select_option("#look", look)
    page.evaluate("""async () => {
        const { installSyncProbe } = await import('/client/syncprobe.js');
        window.syncProbe = await installSyncProbe(window.lipclockClient);
    }""")
    for text in sentences:
        page.evaluate("""(text) => new Promise((resolve) => {
            const c = window.lipclockClient;
            const done = () => { c.removeEventListener('utterance-end', done); resolve(); };
            c.addEventListener('utterance-end', done);
            c.speak(text);
        })""", text)
        page.wait_for_timeout(200)
    snap = page.evaluate("window.syncProbe.snapshot()")
    snap["stats"] = page.evaluate("window.lipclockClient.stats")
    snap["rtt_ms"] = page.evaluate("""async () => {   // what the proxy adds, seen by the page
        const t = [];
        for (let i = 0; i < 7; i++) {
            const t0 = performance.now();
            await (await fetch('/healthz', { cache: 'no-store' })).text();
            t.push(performance.now() - t0);
        }
        return t.sort((a, b) => a - b)[3];
    }""")
    page.close()
    if errors:
        raise RuntimeError(f"page errors: {errors}")
    return snap


def render_ms(snapshot: dict) -> list[float]:
    return [f[4] for f in snapshot["frames"] if f[4] is not None]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--sentences", type=int, default=4)
    ap.add_argument("--no-jitter", action="store_true", help="skip the jitter-proxy run")
    ap.add_argument("--looks", default="", help="comma-separated looks to time (page #look)")
    args = ap.parse_args()
    from playwright.sync_api import sync_playwright

    sentences = SENTENCES[:args.sentences]
    rows = []
    with running_server() as (addr, _proc), sync_playwright() as p:
        browser = p.chromium.launch(executable_path=CHROMIUM, args=ARGS)
        url = f"http://{addr}"
        conditions = [("direct (loopback)", None)]
        if not args.no_jitter:
            conditions.append(("proxy 50 +/- 30 ms", (0.020, 0.080)))
        for name, jitter in conditions:
            if jitter is None:
                snap = measure(browser, url, sentences)
            else:
                port = int(addr.rsplit(":", 1)[1])
                with jitter_proxy_thread(port, *jitter) as pport:
                    snap = measure(browser, f"http://127.0.0.1:{pport}", sentences)
            res = analyse(snap, url)
            rows.append((name, res, snap))
        looks = [lk for lk in args.looks.split(",") if lk]
        look_rows = [(lk, render_ms(measure(browser, url, sentences[:1], lk))) for lk in looks]
        browser.close()

    print(f"{'condition':<22} {'frames':>6} {'median lag ms':>14} {'p95 |lag| ms':>13} "
          f"{'max |lag| ms':>13}  {'drawn-gap lead ms':>18}  {'chunk slack ms':>17}  "
          f"late  http rtt  match corr")
    for name, res, snap in rows:
        if not len(res.lags_ms):
            print(f"{name:<22} no frames matched the tapped audio: {res.matched}")
            continue
        s = res.summary()
        corr = ", ".join(f"{c:.2f}" for c in res.matched.values())
        geo = ", ".join(f"{g:+.1f}" for g in res.geometry_ms.values())
        st = snap["stats"]
        slack = f"{min(st['slackMs'])}/{statistics.median(st['slackMs']):.0f}"
        print(f"{name:<22} {s['frames']:>6.0f} {s['median_ms']:>14.2f} {s['p95_abs_ms']:>13.2f} "
              f"{s['max_abs_ms']:>13.2f}  {geo:>18}  {slack:>17}  {st['lateChunks']:>4}  "
              f"{snap['rtt_ms']:>5.0f} ms  {corr}")
    print("goal: |median| <= 5 ms, p95 |lag| <= 20 ms (one 60 Hz frame is 16.7 ms)")
    print("lag: drawn sample minus the sample heard at that frame (tapped audio); drawn-gap "
          "lead: the shift of the utterance's lip-gap track that best explains the drawn "
          "lip gap, per utterance (geometry only); chunk slack: how early audio chunks "
          "arrived before their play time, min/median; late: chunks that arrived too late")
    for name, ms in [(rows[0][0] + " (page look)", render_ms(rows[0][2])), *look_rows]:
        if ms:
            ms.sort()
            print(f"render {name}: median {statistics.median(ms):.2f} ms, "
                  f"p95 {ms[int(0.95 * (len(ms) - 1))]:.2f} ms over {len(ms)} frames (goal < 4 ms)")


if __name__ == "__main__":
    main()
