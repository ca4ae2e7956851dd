"""The 3-D avatar adaptor (client/morphs.js) and its example page /avatar3d, in Debian's
headless Chromium against a real `lipclock serve`."""

from __future__ import annotations

import pytest
from browser_util import FACE_ARTIFACTS, HAVE_CHROMIUM

pytestmark = pytest.mark.skipif(not HAVE_CHROMIUM, reason="Debian chromium missing")

# a stand-in client with one utterance: p (closed) then aa (open), at 16 kHz
FAKE = """
  const M = await import("/client/morphs.js");
  const table = M.parseMorphTable(await (await fetch("/tables/morphs.tsv")).text());
  const start = { phones: [{ phone: "P", start: 0, end: 1600 },
                           { phone: "AA1", start: 1600, end: 4800 }],
                  visemes: [{ viseme: "closed", phone: "P", start: 0, end: 1600 },
                            { viseme: "open", phone: "AA1", start: 1600, end: 4800 }] };
  const fake = { utt: { sr: 16000, start }, mouth: null,
                 mouthAt(s) { return s === null ? null : this.mouth; }, currentSample: () => null };
  const adaptor = new M.MorphAdaptor(fake, { table });
  const at = (sample, mouth) => { fake.mouth = mouth; return adaptor.weightsAt(sample); };
"""


def open_page(browser, url):
    page = browser.new_page(viewport={"width": 1000, "height": 700})
    errors: list[str] = []
    page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
    page.on("pageerror", lambda e: errors.append(str(e)))
    page.goto(url)
    return page, errors


def test_mouth_states_map_to_the_expected_morphs(server, browser):
    page, errors = open_page(browser, server + "/avatar3d")
    w = page.evaluate("async () => {" + FAKE + """
        return {
          closed: at(800, { lipGap: 0, width: 48, jaw: 3 }),    // mid /p/, "closed"'s measures
          open: at(3200, { lipGap: 16, width: 54, jaw: 15 }),   // mid /aa/, "open"'s
          rounded: at(3200, { lipGap: 2, width: 36, jaw: 8 }),
          spread: at(3200, { lipGap: 6, width: 60, jaw: 6 }),
          boundary: at(1600, { lipGap: 8, width: 51, jaw: 9 }),   // p -> aa cross-fade
          idle: at(null, null),
        };
    }""")
    closed, open_ = w["closed"], w["open"]
    assert closed["viseme_PP"] == 1 and closed["viseme_aa"] == 0
    assert closed["jawOpen"] < 0.15 and closed["mouthClose"] > 0.9
    assert closed["mouthPressLeft"] > 0.9 and closed["mouthPressRight"] > 0.9
    assert open_["viseme_aa"] == 1 and open_["viseme_PP"] == 0
    assert open_["jawOpen"] > 0.9 and open_["mouthClose"] == 0 and open_["mouthPucker"] == 0
    assert w["rounded"]["mouthPucker"] > 0.7 and w["rounded"]["mouthSmileLeft"] == 0
    assert w["spread"]["mouthStretchLeft"] > 0.7 and w["spread"]["mouthPucker"] == 0
    b = w["boundary"]
    assert 0.3 < b["viseme_PP"] < 0.7 and abs(b["viseme_PP"] + b["viseme_aa"] - 1) < 1e-9
    assert w["idle"]["viseme_sil"] == 1 and max(w["idle"].values()) == 1
    assert all(v == 0 for k, v in w["idle"].items() if k != "viseme_sil")
    assert not errors, errors
    page.close()


def test_the_phone_row_overrides_its_class(server, browser):
    # s and t share the class "alveolar" and arrive as one viseme event; Oculus keeps SS and DD
    page, _ = open_page(browser, server + "/avatar3d")
    got = page.evaluate("async () => {" + FAKE + """
        start.phones = [{ phone: "S", start: 0, end: 1600 },
                        { phone: "T", start: 1600, end: 3200 }];
        start.visemes = [{ viseme: "alveolar", phone: "S", start: 0, end: 3200 }];
        return [at(800, null).viseme_SS, at(2400, null).viseme_DD];
    }""")
    assert got == [1, 1]
    page.close()


def test_a_bad_table_line_names_the_file_and_line(server, browser):
    page, _ = open_page(browser, server + "/avatar3d")
    msgs = page.evaluate("""async () => {
        const M = await import("/client/morphs.js");
        const err = (text) => { try { M.parseMorphTable(text, "my.tsv"); return null; }
                                catch (e) { return e.message; } };
        return [err("# c\\nrest\\tviseme_sil\\nclosed\\tviseme_XX\\n"),
                err("rest\\tviseme_sil\\n\\nclosed viseme_PP\\n"),
                err("rest\\tviseme_sil\\nrest\\tviseme_PP\\n")];
    }""")
    assert msgs[0].startswith("my.tsv:3: unknown morph target \"viseme_XX\"")
    assert msgs[1].startswith("my.tsv:3: expected 2 tab-separated columns")
    assert msgs[2].startswith("my.tsv:2: \"rest\" is given twice")
    page.close()


# the drawn frame has the jaw well down and the lips apart: keep it on screen for the screenshot
# An open vowel on screen: jaw down and lips apart. (Jaw alone is not enough: closing into
# the /m/ of "map" the lips meet while the jaw is still low, and a busy machine that draws
# few frames once held such a frame, lips 0.06 apart.)
HOLD_OPEN = """() => { const d = window.avatarDebug;
  if (d.drawn && d.drawn.jawOpen > 0.6 && d.drawn.mouthClose === 0
      && d.drawn.mouthLowerDownLeft > 0.3) {
    d.hold = true; d.held = d.weights; return true; }
  return false; }"""

# the adaptor over the whole utterance the page received, every 5 ms (frame-rate independent)
SWEEP = """() => { const d = window.avatarDebug, u = window.lipclockClient.utt;
  const grid = [];
  for (let s = 0; s < u.endSample; s += Math.round(u.sr / 200)) {
    grid.push({ sample: s, ...d.adaptor.weightsAt(s) });
  }
  return { phones: u.start.phones, endSample: u.endSample, sr: u.sr, grid }; }"""


def test_avatar_page_talks_with_the_morphs(server, browser):
    page, errors = open_page(browser, server + "/avatar3d?channel=avatar3d-test")
    page.wait_for_function("document.getElementById('status').textContent === 'connected'")
    page.wait_for_function("window.avatarDebug && window.avatarDebug.frames > 2")
    assert page.evaluate("window.avatarDebug.webgl"), "the head was not drawn"
    page.fill("#text", "Bob bought a big map, papa.")
    # A busy machine may draw only a few frames a second, none of them on an open vowel:
    # then say it again (the checks below do not depend on the frame rate).
    for _ in range(5):
        prev = page.evaluate("window.lipclockClient.utt ? window.lipclockClient.utt.id : null")
        page.click("#speak")
        page.wait_for_function("(prev) => { const u = window.lipclockClient.utt; "
                               "return u && u.id !== prev; }", arg=prev, timeout=30000)
        page.wait_for_function(f"({HOLD_OPEN})() || window.lipclockClient.utt.doneFired",
                               timeout=30000)
        if page.evaluate("window.avatarDebug.hold"):
            break
    else:
        pytest.fail("no drawn frame had the mouth open in five utterances")
    FACE_ARTIFACTS.mkdir(parents=True, exist_ok=True)
    page.screenshot(path=str(FACE_ARTIFACTS / "avatar3d.png"))
    held = page.evaluate("window.avatarDebug.held")   # both sets, of the frame on screen
    page.evaluate("window.avatarDebug.hold = false")
    # mid-speech, the jaw down and the lips apart
    assert held["viseme_sil"] < 1
    assert held["jawOpen"] > 0.6 and held["mouthClose"] == 0 and held["mouthLowerDownLeft"] > 0.3
    page.wait_for_function("window.lipclockClient.utt && window.lipclockClient.utt.doneFired",
                           timeout=30000)
    page.wait_for_function("window.avatarDebug.weights.viseme_sil === 1")
    trace = page.evaluate("window.avatarDebug.trace")   # what the live loop computed per frame
    influences = page.evaluate("""() => window.avatarDebug.meshes.map((m) =>
        [Math.min(...m.morphTargetInfluences), Math.max(...m.morphTargetInfluences)])""")
    final = page.evaluate("window.avatarDebug.weights")
    sweep = page.evaluate(SWEEP)
    grid, sr = sweep["grid"], sweep["sr"]

    assert trace and len(grid) > 200
    assert set(trace[0]) == set(grid[0]) and len(grid[0]) == 1 + 15 + 16
    assert all(0 <= v <= 1 for f in trace + grid for k, v in f.items() if k != "sample")
    assert all(0 <= lo and hi <= 1 for lo, hi in influences)

    def middles(phones):   # the middle half of each phone of the set
        spans = [(p["start"], p["end"]) for p in sweep["phones"]
                 if p["phone"].rstrip("012") in phones]
        assert spans, phones
        return [[f for f in grid if a + (b - a) / 4 <= f["sample"] < b - (b - a) / 4]
                for a, b in spans]

    open_jaw = [max(f["jawOpen"] for f in frames) for frames in middles({"AA"})]
    for frames in middles({"AA"}):            # the open vowels: aa and the jaw down
        assert max(f["viseme_aa"] for f in frames) == 1 and max(f["viseme_PP"] for f in frames) == 0
    assert min(open_jaw) > 0.6
    bilabial_jaw = []
    for frames in middles({"P", "B", "M"}):   # every bilabial: PP, the lips shut and pressed
        assert max(f["viseme_PP"] for f in frames) == 1 and max(f["viseme_aa"] for f in frames) < 1
        assert max(f["mouthClose"] for f in frames) > 0.9
        assert max(f["mouthPressLeft"] for f in frames) > 0.9
        bilabial_jaw.append(min(f["jawOpen"] for f in frames))
    # the jaw rises for each bilabial (between open vowels it need not shut: the lips do),
    # and after a pause it is nearly shut
    assert max(bilabial_jaw) < max(open_jaw) - 0.2 and min(bilabial_jaw) < 0.15
    # at the end of the audio the viseme is silence and the lips at rest; the jaw is on its
    # way back (the final pause is short), and after the end every weight is at rest
    tail = [f for f in grid if f["sample"] >= sweep["endSample"] - 0.02 * sr]
    assert tail and all(f["viseme_sil"] == 1 for f in tail)
    assert all(f["jawOpen"] < 0.3 for f in tail)
    assert all(v < 0.1 for f in tail for k, v in f.items() if k.startswith("mouth"))
    assert final["viseme_sil"] == 1 and all(v == 0 for k, v in final.items() if k != "viseme_sil")
    assert not errors, errors
    page.close()
