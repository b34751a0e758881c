"""The viewer (make view, docs/viewer.md) in a real browser: headless Chromium (Debian's
chromium + chromium-driver) driven by Selenium. Loads the page on the CAD animation scene,
clicks a known part and reads its id, drags it and checks that the frame shown equals a
full re-render of the moved scene (a from-scratch `yproc anim --full` frame of the same
offset through the golden model), changes its opacity, sends malformed messages and sees
the error while the page keeps working, and keeps a screenshot for docs/viewer.md.
"""
from __future__ import annotations

import base64
import io
import os
import shutil
import subprocess
import threading
import time
from pathlib import Path

import numpy as np
import pytest

from diffengine import REPO
from diffengine.host import yproc
from diffengine.pipeline.anim import lines_of_de48, render_lines

SCENE = REPO / "sw/scenes/anim/anim.scene"
# the screenshot: out/viewer/viewer.png on every run; DE_VIEWER_SHOT=docs also refreshes
# docs/img/viewer.png, the picture of docs/viewer.md (so make test leaves docs/ alone)
SHOT = REPO / "out/viewer/viewer.png"
DOC_SHOT = REPO / "docs/img/viewer.png"
SLIDER = 3                       # obj 3 of anim.scene: the slider block (material "slider")


def _driver():
    from selenium import webdriver
    chrome = shutil.which("chromium") or "/usr/bin/chromium"
    drv = shutil.which("chromedriver") or "/usr/bin/chromedriver"
    if not (Path(chrome).exists() and Path(drv).exists()):
        subprocess.run([str(REPO / "scripts/ensure_system.sh"), "chromium", "chromium-driver"], check=True)
    opts = webdriver.ChromeOptions()
    opts.binary_location = chrome
    for a in ("--headless=new", "--no-sandbox", "--disable-dev-shm-usage", "--disable-gpu",
              "--window-size=1060,760"):
        opts.add_argument(a)
    from selenium.webdriver.chrome.service import Service
    return webdriver.Chrome(service=Service(drv), options=opts)


def _start(budget_ms: float) -> int:
    """A viewer on a free port in a daemon thread; its port."""
    from diffengine.viewer import server as vs
    port = {}
    ready = threading.Event()

    def run():
        vs.serve(SCENE, port=0, budget_ms=budget_ms,
                 ready=lambda p: (port.setdefault("p", p), ready.set()))

    threading.Thread(target=run, daemon=True).start()
    assert ready.wait(120), "the viewer did not start listening"
    return port["p"]


@pytest.fixture(scope="module")
def server():
    """Never coarse (budget 1e9): every frame is full quality, comparable bit for bit."""
    yield _start(1e9)


@pytest.fixture(scope="module")
def browser(server):
    d = _driver()
    d.set_script_timeout(120)
    d.get(f"http://127.0.0.1:{server}/")
    yield d
    d.quit()


def wait(d, cond, what, timeout=120):
    t0 = time.time()
    while time.time() - t0 < timeout:
        v = d.execute_script(cond)
        if v:
            return v
        time.sleep(0.1)
    raise AssertionError(f"timed out waiting for {what}")


def canvas(d) -> np.ndarray:
    """The frame canvas as (H, W, 3) uint8."""
    from PIL import Image
    url = d.execute_script("return document.getElementById('frame').toDataURL('image/png');")
    img = Image.open(io.BytesIO(base64.b64decode(url.split(",", 1)[1]))).convert("RGB")
    return np.asarray(img)


def text(d, id_):
    return d.execute_script(f"return document.getElementById('{id_}').textContent;")


def full_render(tmp: Path, moves: dict, opacity: dict | None = None) -> np.ndarray:
    """Frame 1 of a two-frame animation that moves objects to their offsets, rendered
    from scratch (`yproc anim --full`: hsr_scene_build + every line) through the golden
    model; 8-bit (>> 4) like the page."""
    lines = [f"scene {SCENE}", "frames 2"]
    lines += [f"move {o} {d[0]!r} {d[1]!r} {d[2]!r} from 0 to 1" for o, d in moves.items()]
    lines += [f"opacity {m} {a!r} from 0 to 1" for m, a in (opacity or {}).items()]
    anim = tmp / "check.anim"
    anim.write_text("\n".join(lines) + "\n")
    out = tmp / "anim_out"
    subprocess.run([str(yproc.build()), "anim", str(anim), "-o", str(out), "--full"], check=True,
                   capture_output=True)
    W = 640
    img = np.stack([render_lines(lines_of_de48(out / "frame001" / f"{c}.de48"), W) for c in "rgb"], -1)
    return (img >> 4).astype(np.uint8)


def test_viewer_in_browser(browser, server, tmp_path):
    d = browser
    from selenium.webdriver.common.action_chains import ActionChains
    from selenium.webdriver.common.by import By
    # load: the first frame arrives whole
    wait(d, "return window.deState && window.deState.frames > 0;", "the first frame")
    first = canvas(d)
    assert first.shape == (480, 640, 3) and first.std() > 5, "the first frame is blank"
    # pick the slider block (known place in anim.scene), read its id back
    from diffengine.viewer.engine import Engine
    eng = Engine(SCENE, yproc.build())
    try:
        box = None
        for y in range(200, 330, 4):     # a pixel of the slider, found through the HSR pick
            for x in range(150, 500, 4):
                p = eng.pick(x + 0.5, y + 0.5)
                if p["face"] >= 0 and p["obj"] == SLIDER:
                    box = (x, y, p["face"])
                    break
            if box:
                break
    finally:
        eng.close()
    assert box, "no pixel of the slider found"
    x, y, face = box
    cv = d.find_element(By.ID, "frame")
    w, h = cv.size["width"], cv.size["height"]
    ActionChains(d).move_to_element_with_offset(cv, x - w / 2, y - h / 2).click().perform()
    wait(d, "return document.getElementById('pick-id').textContent !== '-';", "the pick reply")
    assert text(d, "pick-id") == str(face)
    assert text(d, "pick-material") == "slider"
    assert float(text(d, "pick-area")) > 10
    # drag it 40 px right, 25 px up, and let go
    n0 = d.execute_script("return window.deState.frames;")
    ActionChains(d).move_to_element_with_offset(cv, x - w / 2, y - h / 2).click_and_hold() \
        .move_by_offset(20, -12).move_by_offset(20, -13).release().perform()
    wait(d, f"return window.deState.frames > {n0} && !window.deState.waiting && "
            "window.deState.queue.length === 0 && document.getElementById('st-coarse').textContent === '0';",
         "the drag's frames")
    time.sleep(0.5)
    wait(d, "return !window.deState.waiting && window.deState.queue.length === 0;", "idle")
    off = _offsets(d)
    assert SLIDER in off and any(abs(v) > 1e-6 for v in off[SLIDER]), f"the slider did not move: {off}"
    shown = canvas(d)
    want = full_render(tmp_path, off)
    assert (shown != first).any(), "the drag changed nothing on the page"
    bad = np.argwhere((shown != want).any(-1))
    assert len(bad) == 0, (f"{len(bad)} pixels differ from the full re-render of the moved scene, "
                           f"first at (x, y) = {tuple(bad[0][::-1])}")
    # opacity of the picked part
    n1 = d.execute_script("return window.deState.frames;")
    d.execute_script("const s = document.getElementById('opacity'); s.value = 0.5;"
                     "s.dispatchEvent(new Event('change'));")
    wait(d, f"return window.deState.frames > {n1} && !window.deState.waiting;", "the opacity frame")
    semi = canvas(d)
    assert (semi != shown).any(), "opacity 0.5 changed no pixel"
    want = full_render(tmp_path, off, {"slider": 0.5})
    assert (semi == want).all(), "the opacity frame differs from the full re-render"
    # malformed messages: an error on the page, the page keeps working
    for bad_msg in ("{not json", '{"type": "drag", "dx": "left", "dy": 0}', '{"type": "warp"}',
                    '{"type": "pick", "x": 1e9, "y": 3}', "[1, 2]"):
        d.execute_script("window.deState.lastError = ''; window.deSendRaw(arguments[0]);", bad_msg)
        err = wait(d, "return window.deState.lastError;", f"the error for {bad_msg}")
        assert "malformed" in err, err
        assert text(d, "error") == err
    # still working: undo the opacity change, the frame goes back to the moved one
    n2 = d.execute_script("return window.deState.frames;")
    d.find_element(By.ID, "undo").click()
    wait(d, f"return window.deState.frames > {n2} && !window.deState.waiting;", "the undo frame")
    assert (canvas(d) == shown).all(), "undo did not restore the frame before the opacity change"
    assert text(d, "error") == "", "a good request after the errors did not clear the error"
    SHOT.parent.mkdir(parents=True, exist_ok=True)
    d.save_screenshot(str(SHOT))
    assert SHOT.stat().st_size > 10000
    if os.environ.get("DE_VIEWER_SHOT") == "docs":
        shutil.copyfile(SHOT, DOC_SHOT)


def _offsets(d) -> dict[int, tuple]:
    """The server's object offsets, asked through the page's own socket."""
    d.execute_script("window.deGot = null; const ws = new WebSocket(`ws://${location.host}/ws`);"
                     "ws.onmessage = (e) => { if (typeof e.data === 'string') {"
                     " const m = JSON.parse(e.data); if (m.type === 'state') { window.deGot = m; ws.close(); } } };"
                     "ws.onopen = () => ws.send(JSON.stringify({type: 'state'}));")
    m = wait(d, "return window.deGot;", "the state")
    return {int(k): tuple(v) for k, v in m["offsets"].items()}


def test_closed_tab_and_second_tab(server):
    """A closed tab leaves the server running; a new tab gets the frame."""
    d = _driver()
    try:
        d.get(f"http://127.0.0.1:{server}/")
        wait(d, "return window.deState && window.deState.frames > 0;", "the first frame")
    finally:
        d.quit()                     # the tab goes away mid-session
    d = _driver()
    try:
        d.get(f"http://127.0.0.1:{server}/")
        wait(d, "return window.deState && window.deState.frames > 0;", "the frame after a closed tab")
    finally:
        d.quit()


def test_binds_to_loopback_only(server):
    import socket
    with socket.create_connection(("127.0.0.1", server), timeout=5):
        pass
    others = [a[4][0] for a in socket.getaddrinfo(socket.gethostname(), None, socket.AF_INET)
              if not a[4][0].startswith("127.")]
    for addr in others:
        with pytest.raises(OSError):
            socket.create_connection((addr, server), timeout=2).close()


def test_page_shows_coarse_frames_and_their_refinement():
    """Item 6 on the page: with a zero budget the drag frames are coarse (the legend turns
    amber), and on release the coarse lines are refined (the legend says so)."""
    from selenium.webdriver.common.action_chains import ActionChains
    from selenium.webdriver.common.by import By
    port = _start(0.0)
    d = _driver()
    try:
        d.get(f"http://127.0.0.1:{port}/")
        wait(d, "return window.deState && window.deState.frames > 0;", "the first frame")
        cv = d.find_element(By.ID, "frame")
        w, h = cv.size["width"], cv.size["height"]
        x, y = 460, 230          # the slider block of anim.scene
        ActionChains(d).move_to_element_with_offset(cv, x - w / 2, y - h / 2).click_and_hold() \
            .move_by_offset(15, 0).move_by_offset(15, 0).release().perform()
        wait(d, "return window.deState.coarseSeen > 0;", "a coarse frame")
        wait(d, "return document.getElementById('degraded').textContent.startsWith('refined');",
             "the refinement at rest")
        assert text(d, "st-coarse") == "0"
        assert d.execute_script("return document.getElementById('degraded').className;") == "off"
    finally:
        d.quit()
