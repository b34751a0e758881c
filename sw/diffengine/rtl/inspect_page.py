"""`diffengine inspect`: one frame as a self-contained HTML page (no server, no network).

    diffengine inspect STREAM [--chips N | --width W] [--engine model|rtl] [--carry-bug]
                      [--history LINES] -o page.html

The page shows the image; a scanline intensity graph (the source's Scanline Display,
§7.4.4) that follows the row under the mouse; and, for a clicked pixel, the commands of
that scanline that act on its column (with their stream index) and that PE's register
history over the line: A, B, C, D and the flags after every command that reached it,
from the structural (cycle) model, with the cycle numbers of the RTL harness and
`diffengine trace` (so a row can be looked up in an RTL trace or an FST).

Everything (image, pixel values, commands, register histories, script, style) is inlined.
Register histories of a wide frame are large (one row per command per column), so they
are embedded for the lines chosen with --history (default: all lines while the budget
allows, see HISTORY_BUDGET); the page says so for a line without one. A query string
`?x=X&y=Y` clicks pixel (X, Y) on load and `?hover=Y` moves the mouse over line Y (how the
headless-browser test drives the page, and a way to bookmark a pixel).
"""
from __future__ import annotations

import base64
import json
import sys
from pathlib import Path

import numpy as np

from .. import isa
from ..formats import asm, binfmt
from ..formats.frame import data_uri, grey, png
from ..model import functional, structural
from ..model.lines import covers, line_starts
from .harness import PE_PER_CHIP

HISTORY_BUDGET = 400_000  # history rows (command x covered column) embedded by default
FLAG_LETTERS = "ABCdlm"   # pA pB pC dis lock acc_mode (as `diffengine trace` prints them)


def _words(R: np.ndarray, r: int) -> np.ndarray:
    b = R[r].astype(np.int64)
    return sum(b[j] << (isa.BLOCK_BITS * j) for j in range(isa.BLOCKS))


def register_history(line_cmds, width: int, carry_bug: bool = False, cycle0: int = 0
                     ) -> dict[int, list[list]]:
    """Per PE, [cycle, stream offset k, A, B, C, D, flags] after every command k of the
    line that acts on that PE, from structural.Array run on this line alone (a Refresh
    leaves every register cleared, so a line does not depend on the lines before it).

    Command k's last instruction enters PE 0 in step L_k; its stage j reaches PE p in step
    L_k + p + j and the accumulator writes D's last block one step after stage 2, so its
    effect on PE p is complete after step L_k + p + 3. `cycle` is given in the RTL
    harness's numbering: cycle0 (the cycle the line's first instruction is on the array
    input) + that step + p // 9 (one register per chip boundary, docs/array.md).
    """
    cmds = [c for c in line_cmds if c.op != "REFRESH"]
    slots, last = [], []
    for c in cmds:
        slots += isa.slots(c)
        last.append(len(slots) - 1)
    K = len(cmds)
    hist: dict[int, list[list]] = {}
    if not K:
        return hist
    cov = np.array([[covers(c, p) for p in range(width)] for c in cmds], dtype=bool)
    L = np.array(last)
    arr = structural.Array(width, carry_bug)
    for step in range(len(slots) + width + 4):
        arr.step(*(slots[step] if step < len(slots) else (isa.NOP, 0)))
        p = step - L - 3
        ok = (p >= 0) & (p < width)
        ks = np.flatnonzero(ok)
        if not len(ks):
            continue
        ks = ks[cov[ks, p[ks]]]
        if not len(ks):
            continue
        pes = p[ks]
        R = arr.R[:, :, pes]
        A, B, C, D = (_words(R, r) for r in (1, 2, 3, 4))
        fl = [arr.P[1, pes], arr.P[2, pes], arr.P[3, pes], arr.dis[pes], arr.lock[pes],
              arr.acc_mode[pes]]
        for i, (k, pe) in enumerate(zip(ks.tolist(), pes.tolist())):
            flags = "".join(ch if f[i] else "." for ch, f in zip(FLAG_LETTERS, fl))
            hist.setdefault(pe, []).append(
                [cycle0 + step + 1 + pe // PE_PER_CHIP, k, int(A[i]), int(B[i]), int(C[i]),
                 int(D[i]), flags])
    return hist


def _line_cycles(commands, n_pe: int) -> list[int]:
    """Cycle (harness numbering) at which each line's first instruction is on the input."""
    from .trace import Timing
    t = Timing.of(isa.serialise(commands), n_pe // PE_PER_CHIP or 1) if n_pe % PE_PER_CHIP == 0 \
        else None
    if t is None:
        return []
    return [0] + [c + 1 for c in t.refresh_at[:-1]]


def parse_lines(spec: str | None, n_lines: int) -> list[int] | None:
    if spec is None:
        return None
    if spec == "all":
        return list(range(n_lines))
    out = set()
    for item in spec.split(","):
        lo, _, hi = item.partition("-")
        a, b = int(lo), int(hi or lo)
        out.update(range(max(0, a), min(n_lines - 1, b) + 1))
    return sorted(out)


def page_data(commands, frame: np.ndarray, name: str, history_lines: list[int] | None,
              carry_bug: bool = False, engine: str = "model", chips: int | None = None) -> dict:
    lines = [ln for ln in isa.split_lines(commands) if ln[-1].op == "REFRESH"]
    starts = line_starts(commands)
    h, w = frame.shape
    if history_lines is None:  # as many lines as the budget allows, from the top
        history_lines, used = [], 0
        for y, ln in enumerate(lines[:h]):
            used += sum(min(c.dx, w) if c.op != "REFRESH" else 0 for c in ln) + len(ln)
            if used > HISTORY_BUDGET:
                break
            history_lines.append(y)
    cyc = _line_cycles(commands, w)
    out_lines = []
    for y, ln in enumerate(lines[:h]):
        entry = {"start": starts[y],
                 "cmds": [[starts[y] + i, asm.format_command(c), c.op, c.x, c.dx]
                          for i, c in enumerate(ln)]}
        if y in history_lines:
            hist = register_history(ln, w, carry_bug, cyc[y] if cyc else 0)
            entry["hist"] = {str(p): [[r[0], starts[y] + r[1], *r[2:]] for r in rows]
                             for p, rows in hist.items()}
        out_lines.append(entry)
    g, top = grey(frame)
    return {"name": name, "width": w, "height": h, "engine": engine, "chips": chips,
            "carry_bug": carry_bug, "cycles": "rtl" if cyc else "line",
            "pixels": base64.b64encode(frame.astype("<u2").tobytes()).decode(),
            "png": data_uri(png(g)), "max": top, "lines": out_lines,
            "history_lines": history_lines}


_HTML = r"""<!doctype html>
<html><head><meta charset="utf-8"><title>diffengine inspect: __TITLE__</title>
<style>
body{font:13px/1.35 system-ui,sans-serif;margin:12px;color:#222}
#wrap{display:flex;gap:16px;align-items:flex-start;flex-wrap:wrap}
canvas{image-rendering:pixelated;border:1px solid #888;cursor:crosshair}
#graph{border:1px solid #bbb;background:#fcfcfc}
table{border-collapse:collapse;font:12px ui-monospace,monospace}
td,th{border:1px solid #ddd;padding:1px 5px;text-align:right}td.l,th.l{text-align:left}
#hover{color:#555;min-height:1.3em}.note{color:#a40}
</style></head><body>
<h2>__TITLE__</h2>
<div id="meta"></div>
<div id="wrap">
 <div><div style="position:relative;line-height:0"><canvas id="img"></canvas>
  <div id="mark" style="position:absolute;display:none;outline:2px solid #e53935;pointer-events:none"></div></div>
  <div id="hover"></div>
  <label>display <select id="scale"><option value="max">scaled to frame max</option>
  <option value="12">12-bit full range</option></select></label></div>
 <div><svg id="graph" width="640" height="220" data-line=""></svg></div>
</div>
<h3 id="sel" data-x="" data-y="" data-pixel="">click a pixel</h3>
<div id="detail"><h4>commands acting on this column</h4>
<table id="cmds"><thead><tr><th>stream index</th><th class="l">command</th></tr></thead><tbody></tbody></table>
<h4>register history of this PE over the line</h4><div id="histnote"></div>
<table id="hist"><thead><tr><th>cycle</th><th>after cmd</th><th>A</th><th>B</th><th>C</th><th>D</th>
<th>flags</th><th>pixel of D</th></tr></thead><tbody></tbody></table></div>
<script id="data" type="application/json">__DATA__</script>
<script>
"use strict";
const S = JSON.parse(document.getElementById("data").textContent);
const W = S.width, H = S.height;
const raw = Uint8Array.from(atob(S.pixels), c => c.charCodeAt(0));
const dv = new DataView(raw.buffer);
const pix = (x, y) => dv.getUint16(2 * (y * W + x), true);
const zx = Math.max(1, Math.min(16, Math.floor(1000 / W)));
const zy = Math.max(1, Math.min(16, Math.floor(640 / H)));
const cv = document.getElementById("img");
cv.width = W; cv.height = H; cv.style.width = (W * zx) + "px"; cv.style.height = (H * zy) + "px";
function paint() {
  const ctx = cv.getContext("2d"), im = ctx.createImageData(W, H);
  const top = document.getElementById("scale").value === "max" ? Math.max(1, S.max) : 4095;
  for (let y = 0; y < H; y++) for (let x = 0; x < W; x++) {
    const v = Math.min(255, Math.round(pix(x, y) * 255 / top)), i = 4 * (y * W + x);
    im.data[i] = im.data[i + 1] = im.data[i + 2] = v; im.data[i + 3] = 255;
  }
  ctx.putImageData(im, 0, 0);
}
document.getElementById("scale").onchange = paint;
paint();
document.getElementById("meta").textContent =
  `${W} x ${H} pixels (12-bit), ${S.engine === "rtl" ? "Verilated RTL (" + S.chips + " chips)" : "golden model"}` +
  `${S.carry_bug ? ", carry bug" : ""}; register history for ${S.history_lines.length} of ${H} lines` +
  ` (structural model, cycle numbers ${S.cycles === "rtl" ? "as in the RTL harness / diffengine trace" : "from the line start"})`;
const hex = v => (Math.floor(v / 16777216) % 4096).toString(16).padStart(3, "0") + "." +
                 (v % 16777216).toString(16).padStart(6, "0");
function covers(op, x, dx, col) {
  if (["EVAL", "EVAL0", "DIS", "SETI", "SETDI", "SETDDI"].includes(op)) return x <= col && col < x + dx;
  if (op.startsWith("SETP")) { const st = dx ? dx : 4096; return col >= x && (col - x) % st === 0; }
  return op === "ACCMODE" || op === "REFRESH";
}
function where(ev) {
  const r = cv.getBoundingClientRect();
  const x = Math.floor((ev.clientX - r.left) / r.width * W), y = Math.floor((ev.clientY - r.top) / r.height * H);
  return [Math.max(0, Math.min(W - 1, x)), Math.max(0, Math.min(H - 1, y))];
}
const NS = "http://www.w3.org/2000/svg";
function graph(y, mark) {
  const g = document.getElementById("graph"), gw = 640, gh = 220, m = 28;
  g.innerHTML = ""; g.setAttribute("data-line", y);
  let top = 1; for (let x = 0; x < W; x++) top = Math.max(top, pix(x, y));
  const X = x => m + (x + 0.5) * (gw - m - 6) / W, Y = v => gh - 18 - v * (gh - 36) / top;
  let pts = [];
  for (let x = 0; x < W; x++) pts.push(`${X(x - 0.5).toFixed(1)},${Y(pix(x, y)).toFixed(1)}`, `${X(x + 0.5).toFixed(1)},${Y(pix(x, y)).toFixed(1)}`);
  const pl = document.createElementNS(NS, "polyline");
  pl.setAttribute("points", pts.join(" ")); pl.setAttribute("fill", "none"); pl.setAttribute("stroke", "#1565c0");
  pl.setAttribute("data-values", Array.from({length: W}, (_, x) => pix(x, y)).join(","));
  g.appendChild(pl);
  const t = (txt, x, yy, a) => { const e = document.createElementNS(NS, "text"); e.textContent = txt;
    e.setAttribute("x", x); e.setAttribute("y", yy); e.setAttribute("font-size", "11");
    if (a) e.setAttribute("text-anchor", a); g.appendChild(e); };
  t(`scanline ${y}`, gw / 2, 12, "middle"); t(String(top), 2, 22); t("0", 2, gh - 18);
  t("column 0", m, gh - 4); t(String(W - 1), gw - 6, gh - 4, "end");
  if (mark !== undefined) { const l = document.createElementNS(NS, "line");
    l.setAttribute("x1", X(mark)); l.setAttribute("x2", X(mark)); l.setAttribute("y1", 16); l.setAttribute("y2", gh - 18);
    l.setAttribute("stroke", "#c62828"); g.appendChild(l); }
}
let selected = null;
cv.addEventListener("mousemove", ev => {
  const [x, y] = where(ev);
  document.getElementById("hover").textContent = `line ${y}, column ${x}: ${pix(x, y)}`;
  graph(y, selected && selected[1] === y ? selected[0] : x);
});
function row(tb, cells, attrs) {
  const tr = document.createElement("tr");
  for (const [k, v] of Object.entries(attrs || {})) tr.setAttribute(k, v);
  cells.forEach((c, i) => { const td = document.createElement("td"); td.textContent = c;
    if (i === 1 && tb.parentNode.id === "cmds") td.className = "l"; tr.appendChild(td); });
  tb.appendChild(tr);
}
cv.addEventListener("click", ev => {
  const [x, y] = where(ev); selected = [x, y];
  const mk = document.getElementById("mark"), r = cv.getBoundingClientRect();
  Object.assign(mk.style, {display: "block", left: (x * r.width / W) + "px", top: (y * r.height / H) + "px",
                           width: Math.max(2, r.width / W) + "px", height: Math.max(2, r.height / H) + "px"});
  const sel = document.getElementById("sel");
  sel.textContent = `line ${y}, column ${x} (PE ${x}, chip ${Math.floor(x / 9)}): pixel ${pix(x, y)}`;
  sel.dataset.x = x; sel.dataset.y = y; sel.dataset.pixel = pix(x, y);
  const ln = S.lines[y], cb = document.querySelector("#cmds tbody"), hb = document.querySelector("#hist tbody");
  cb.innerHTML = ""; hb.innerHTML = "";
  for (const [k, text, op, cx, dx] of ln.cmds) if (covers(op, cx, dx, x)) row(cb, [k, text], {"data-k": k});
  const note = document.getElementById("histnote");
  if (!ln.hist) { note.className = "note";
    note.textContent = `no register history embedded for line ${y}: re-run with --history ${y}`; }
  else { note.className = ""; const rows = ln.hist[String(x)] || [];
    note.textContent = `${rows.length} command(s) reached PE ${x} on line ${y}`;
    for (const [c, k, A, B, C, D, f] of rows)
      row(hb, [c, k, hex(A), hex(B), hex(C), hex(D), f, Math.floor(D / 16777216) % 4096],
          {"data-cycle": c, "data-k": k, "data-a": A, "data-b": B, "data-c": C, "data-d": D, "data-flags": f}); }
  graph(y, x);
});
function fire(type, x, y) {
  const r = cv.getBoundingClientRect();
  cv.dispatchEvent(new MouseEvent(type, {bubbles: true, clientX: r.left + (x + 0.5) * r.width / W,
                                          clientY: r.top + (y + 0.5) * r.height / H}));
}
const q = new URLSearchParams(location.search);
graph(0);
if (q.has("hover")) fire("mousemove", 0, +q.get("hover"));
if (q.has("x") && q.has("y")) fire("click", +q.get("x"), +q.get("y"));
</script></body></html>
"""


def write_page(path: Path, data: dict) -> None:
    title = data["name"].replace("<", "&lt;").replace("&", "&amp;")
    blob = json.dumps(data, separators=(",", ":")).replace("</", "<\\/")
    Path(path).write_text(_HTML.replace("__TITLE__", title).replace("__DATA__", blob))


def configure(ap) -> None:
    """The arguments of this subcommand (the `diffengine` tree calls this)."""
    ap.add_argument("stream", help=".cmd text, .de48 or .de32")
    ap.add_argument("-o", "--output", required=True, help="the HTML page to write")
    g = ap.add_mutually_exclusive_group()
    g.add_argument("--chips", type=int, help="array of N 9-PE chips (width 9N)")
    g.add_argument("--width", type=int, help="columns, model engine only (default 640)")
    ap.add_argument("--engine", choices=("model", "rtl"), default="model",
                    help="frame from the golden model (default) or the Verilated RTL (needs --chips)")
    ap.add_argument("--carry-bug", action="store_true", help="the §7.7 fault (model and RTL)")
    ap.add_argument("--history", metavar="LINES",
                    help="lines with a register history: all, or e.g. 0-15,40 (default: "
                         f"from the top while under {HISTORY_BUDGET} rows)")
    ap.set_defaults(func=command)


def command(a) -> int:
    try:
        data = Path(a.stream).read_bytes()
        commands, _ = binfmt.load_commands(data, a.stream)
    except (OSError, ValueError) as e:
        print(f"diffengine inspect: {e}", file=sys.stderr)
        return 1
    width = 9 * a.chips if a.chips else (a.width or 640)
    if not 1 <= width <= isa.ADDR_MAX + 1:
        print(f"diffengine inspect: width {width} outside 1..4096", file=sys.stderr)
        return 2
    lines = [ln for ln in isa.split_lines(commands) if ln[-1].op == "REFRESH"]
    if not lines:
        print(f"diffengine inspect: {a.stream}: no complete scanline (no Refresh)", file=sys.stderr)
        return 1
    commands = [c for ln in lines for c in ln]
    if a.engine == "rtl":
        if not a.chips:
            print("diffengine inspect: --engine rtl needs --chips", file=sys.stderr)
            return 2
        from . import harness
        frame, _ = harness.run(commands, a.chips, a.carry_bug)
    else:
        frame = functional.render(commands, width, carry_bug=a.carry_bug)
    try:
        hist = parse_lines(a.history, len(lines))
    except ValueError:
        print(f"diffengine inspect: --history {a.history!r}: want all or A-B,C", file=sys.stderr)
        return 2
    d = page_data(commands, frame, Path(a.stream).name, hist, a.carry_bug, a.engine, a.chips)
    write_page(Path(a.output), d)
    print(f"{a.output}: {frame.shape[1]} x {frame.shape[0]}, register history for "
          f"{len(d['history_lines'])} line(s)", file=sys.stderr)
    return 0
