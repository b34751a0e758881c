"""`diffengine view` (make view): the interactive viewer on 127.0.0.1 (docs/viewer.md).

The page (viewer/page.html) talks to this server over one WebSocket (/ws): JSON requests
from the page, JSON replies and binary frame updates back. Frame update (binary message):
u16 y0, u16 rows, u16 width (big-endian), then rows x width x 3 bytes of 8-bit RGB (the
12-bit golden-model pixels >> 4, the DAC window w = 4) for the band y0 .. y0+rows-1.

Requests ({"type": ...}): pick {x, y}; drag {dx, dy, dz} (pixels from the gesture's
start); drag_end; rest; opacity {value}; light {x, y} (direction in the image plane);
options {aa, shading}; undo; redo; rtl {on}; state. A malformed one is answered with
{"type": "error", "error": "..."} and the connection stays open.
"""
from __future__ import annotations

import asyncio
import json
import math
import struct
import threading
import time
from pathlib import Path

import numpy as np

from .. import REPO, fail
from .engine import SHADINGS, Engine, EngineError

PAGE = Path(__file__).with_name("page.html")
HOST = "127.0.0.1"

COMMAND_HELP = """Opens a web page on http://127.0.0.1:PORT/ showing SCENE rendered through the
incremental pipeline (HSR -> y-processor -> golden model), with picking, dragging, opacity,
light, AA/shading toggles, undo/redo, per-frame statistics and an optional RTL check
(docs/viewer.md). Binds to 127.0.0.1 only. Ctrl-C stops it.

    diffengine view [--scene sw/scenes/cad/cad.scene] [--port 8765] [--budget-ms 50]
                    [--model auto|fast|numpy]
"""


class BadRequest(ValueError):
    pass


def _num(msg: dict, key: str, lo: float = -1e6, hi: float = 1e6) -> float:
    v = msg.get(key)
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) or not lo <= v <= hi:
        raise BadRequest(f"'{key}' must be a number in [{lo:g}, {hi:g}], got {v!r}")
    return float(v)


class Session:
    """The scene and what one page is doing with it (one at a time: a new tab takes over;
    a closed tab leaves the scene as it was)."""

    def __init__(self, engine: Engine):
        self.e = engine
        self.picked: dict | None = None
        self.drag_start = (0.0, 0.0, 0.0)
        self.dragging = False
        self.rtl_on = False
        self.rtl_busy = False
        self.rtl_results: dict[int, bool] = {}
        self.lock = threading.Lock()      # the engine is used from the executor thread only

    # ---- requests -> (json replies, frame) ------------------------------------------------
    def handle(self, msg: dict) -> tuple[list[dict], object]:
        if not isinstance(msg, dict) or not isinstance(msg.get("type"), str):
            raise BadRequest("a request is a JSON object with a string 'type'")
        t = msg["type"]
        e = self.e
        t0 = time.perf_counter()
        out: list[dict] = []
        fr = None
        if t == "state":
            fr_rows = list(range(e.H))
            out.append(self.state_msg())
            return out, (fr_rows, None, t0)
        if t == "pick":
            x, y = _num(msg, "x", 0, e.W - 1e-9), _num(msg, "y", 0, e.H - 1e-9)
            p = e.pick(x, y)
            if p["face"] < 0:
                self.picked = None
                out.append({"type": "picked", "id": -1})
            else:
                self.picked = p
                obj = p["obj"]
                self.drag_start = e.state.offsets.get(obj, (0.0, 0.0, 0.0))
                mat = e.mats.index(p["material"])
                out.append({"type": "picked", "id": p["face"], "obj": obj, "name": f"obj {obj}",
                            "material": p["material"], "visible_area": p["visible_area"],
                            "box": p["box"], "opacity": e.state.opacity.get(mat, 1.0)})
            return out, None
        if t == "drag":
            if not self.picked:
                raise BadRequest("drag needs a picked part (click one first)")
            dx, dy = _num(msg, "dx"), _num(msg, "dy")
            dz = _num(msg, "dz") if "dz" in msg else 0.0
            if not self.dragging:
                e.checkpoint()
                self.dragging = True
            obj = self.picked["obj"]
            e.move(obj, e.drag_offset(obj, self.drag_start, dx, dy, dz))
            fr = e.frame(coarse=None)
        elif t == "drag_end":
            self.dragging = False
            if self.picked:
                self.drag_start = e.state.offsets.get(self.picked["obj"], (0.0, 0.0, 0.0))
            fr = e.rest()
        elif t == "rest":
            fr = e.rest()
        elif t == "opacity":
            if not self.picked:
                raise BadRequest("opacity needs a picked part (click one first)")
            a = _num(msg, "value", 0.0, 1.0)
            e.checkpoint()
            e.set_opacity(e.mats.index(self.picked["material"]), a)
            fr = e.frame(coarse=False)
        elif t == "light":
            x, y = _num(msg, "x", -1, 1), _num(msg, "y", -1, 1)
            v = e.info["view"]
            z = math.sqrt(max(0.0, 1 - x * x - y * y)) + 0.05
            d = x * np.asarray(v["u"]) + y * np.asarray(v["v"]) + z * np.asarray(v["w"])
            e.checkpoint()
            e.set_light(0, d)
            fr = e.frame(coarse=False)
        elif t == "options":
            aa, sh = msg.get("aa"), msg.get("shading")
            if not isinstance(aa, bool) or sh not in SHADINGS:
                raise BadRequest(f"options needs 'aa' true/false and 'shading' one of {', '.join(SHADINGS)}")
            e.checkpoint()
            e.set_options(aa, sh)
            fr = e.frame(coarse=False)
        elif t in ("undo", "redo"):
            done = e.undo() if t == "undo" else e.redo()
            if not done:
                out.append({"type": "info", "info": f"nothing to {t}"})
                return out, None
            fr = e.frame(coarse=False)
        elif t == "rtl":
            if not isinstance(msg.get("on"), bool):
                raise BadRequest("rtl needs 'on' true/false")
            self.rtl_on = msg["on"]
            out.append({"type": "rtl", "on": self.rtl_on, "status": "on" if self.rtl_on else "off"})
            return out, None
        else:
            raise BadRequest(f"unknown request type {t!r} (pick, drag, drag_end, rest, opacity, "
                             "light, options, undo, redo, rtl, state)")
        if fr is None:
            out.append(self.state_msg())
            return out, None
        return out, (fr.rows, fr.stats, t0)

    def state_msg(self) -> dict:
        e = self.e
        return {"type": "state", "width": e.W, "height": e.H, "scene": str(e.scene),
                "aa": e.state.aa, "shading": e.state.shading, "can_undo": bool(e.undo_stack),
                "can_redo": bool(e.redo_stack), "coarse_lines": e.coarse_lines,
                "offsets": {str(k): v for k, v in e.state.offsets.items()},
                "opacity": {e.mats[k]: v for k, v in e.state.opacity.items()},
                "budget_ms": e.budget_ms}

    def band(self, rows: list[int]) -> bytes | None:
        """The binary frame update covering rows (None if no row changed)."""
        if not rows:
            return None
        y0, y1 = min(rows), max(rows) + 1
        e = self.e
        px = (e.image[y0:y1] >> 4).astype(np.uint8)
        return struct.pack(">HHH", y0, y1 - y0, e.W) + px.tobytes()


# ---- the RTL check (background) ----------------------------------------------------------

def rtl_check(streams: list, golden: np.ndarray, cfg=None, mode: int = 0) -> tuple[bool, str]:
    """The streams through the Verilated display controller (default: the demo's 3 x 72
    chips, 640x480), its last frame against the golden model's; (matched, summary)."""
    from ..rtl import dc_harness
    frames, st = dc_harness.run(streams, cfg or dc_harness.Config(), mode=mode)
    got = frames[-1]
    diff = got != golden
    if diff.any():
        y, x, c = np.argwhere(diff)[0]
        return False, (f"{int(diff.any(-1).sum())} pixels differ, first at ({x}, {y}) {'RGB'[c]}: "
                       f"RTL {int(got[y, x, c])}, golden {int(golden[y, x, c])}")
    return True, f"bit-identical ({st.get('seconds', 0):.1f} s)"


# ---- aiohttp ------------------------------------------------------------------------------

def make_app(engine: Engine):
    from aiohttp import WSMsgType, web

    sess = Session(engine)
    loop_exec = None   # default thread pool; the session lock keeps engine use serial

    async def index(_req):
        return web.FileResponse(PAGE)

    async def ws_handler(req):
        ws = web.WebSocketResponse(max_msg_size=1 << 16, heartbeat=30)
        await ws.prepare(req)
        loop = asyncio.get_running_loop()

        def run(msg):
            with sess.lock:
                replies, fr = sess.handle(msg)
                t_enc = time.perf_counter()
                blob = None
                stats = None
                if fr is not None:
                    rows, stats, t0 = fr
                    blob = sess.band(rows)
                    if stats is not None:
                        stats = dict(stats, encode_ms=(time.perf_counter() - t_enc) * 1e3,
                                     total_ms=(time.perf_counter() - t0) * 1e3,
                                     rows=len(rows), band=[min(rows), max(rows) + 1] if rows else None)
                        replies.append({"type": "frame", **stats})
                        replies.append(sess.state_msg())
                return replies, blob, (stats if stats and not stats["coarse"] else None)

        async def check_rtl(frame_no):
            sess.rtl_busy = True
            with sess.lock:
                streams, gold = sess.e.streams(), sess.e.image.copy()
            try:
                ok, why = await loop.run_in_executor(loop_exec, rtl_check, streams, gold)
            except Exception as ex:   # the harness build or run failed: say so on the page
                ok, why = False, f"RTL check failed: {ex}"
            sess.rtl_results[frame_no] = ok
            sess.rtl_busy = False
            if not ws.closed:
                await ws.send_json({"type": "rtl", "on": sess.rtl_on, "frame": frame_no,
                                    "match": ok, "status": why})

        async for m in ws:
            if m.type != WSMsgType.TEXT:
                if m.type == WSMsgType.BINARY:
                    await ws.send_json({"type": "error", "error": "binary messages are not accepted"})
                continue
            try:
                msg = json.loads(m.data)
            except ValueError as ex:
                await ws.send_json({"type": "error", "error": f"malformed message (not JSON: {ex})"})
                continue
            try:
                replies, blob, full = await loop.run_in_executor(loop_exec, run, msg)
            except BadRequest as ex:
                await ws.send_json({"type": "error", "error": f"malformed message: {ex}"})
                continue
            except EngineError as ex:        # yproc serve refused or died: say so, go on
                await ws.send_json({"type": "error", "error": f"request failed: {ex}"})
                continue
            if blob is not None:
                await ws.send_bytes(blob)
            for r in replies:
                await ws.send_json(r)
            await ws.send_json({"type": "done", "request": msg.get("type")})
            if full is not None and sess.rtl_on and not sess.rtl_busy:
                asyncio.ensure_future(check_rtl(full["frame"]))
        return ws

    app = web.Application()
    app.router.add_get("/", index)
    app.router.add_get("/ws", ws_handler)
    return app


def serve(scene, port: int = 8765, budget_ms: float = 50.0, ready=None, model: str = "auto") -> None:
    """Run the viewer until interrupted (ready(port) is called once it listens)."""
    from aiohttp import web

    from ..host import yproc
    engine = Engine(scene, yproc.build(), budget_ms=budget_ms, model=model)
    app = make_app(engine)

    async def main():
        runner = web.AppRunner(app)
        await runner.setup()
        site = web.TCPSite(runner, HOST, port)
        await site.start()
        real = site._server.sockets[0].getsockname()[1]
        print(f"view: {engine.scene} ({engine.W}x{engine.H}, {engine.info['faces']} faces, "
              f"{engine.model} golden model) on "
              f"http://{HOST}:{real}/  (Ctrl-C stops)", flush=True)
        if ready:
            ready(real)
        try:
            while True:
                await asyncio.sleep(3600)
        finally:
            await runner.cleanup()

    if threading.current_thread() is threading.main_thread():   # kill = Ctrl-C: clean up
        import signal

        def stop(*_):
            raise KeyboardInterrupt
        signal.signal(signal.SIGTERM, stop)
    try:
        asyncio.run(main())
    except KeyboardInterrupt:
        pass
    finally:
        engine.close()


def configure(ap) -> None:
    ap.epilog = COMMAND_HELP
    ap.add_argument("--scene", default=str(REPO / "sw/scenes/cad/cad.scene"),
                    help="scene file (default: the CAD scene; also sw/scenes/teapot/teapot_box.scene)")
    ap.add_argument("--port", type=int, default=8765, help="TCP port on 127.0.0.1 (0: any free one)")
    ap.add_argument("--budget-ms", type=float, default=50.0,
                    help="frame budget: a drag frame costing more is rendered coarse first")
    ap.add_argument("--model", choices=("auto", "fast", "numpy"), default="auto",
                    help="golden model for the pixels: the C one (diffengine.model.fast) when "
                    "the tree has it (auto), or the numpy reference")
    ap.set_defaults(func=command)


def command(a) -> int:
    if not Path(a.scene).is_file():
        return fail("view", f"{a.scene}: no such scene file")
    try:
        serve(a.scene, a.port, a.budget_ms, model=a.model)
    except EngineError as ex:
        return fail("view", ex)
    except OSError as ex:
        return fail("view", f"cannot listen on {HOST}:{a.port}: {ex}")
    return 0
