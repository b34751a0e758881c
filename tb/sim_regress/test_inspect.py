"""`diffengine inspect` in headless Chromium (Debian package `chromium`): the page is
loaded with a query string that clicks a pixel (`?x=X&y=Y`) or moves the mouse over a
line (`?hover=Y`), Chromium dumps the DOM, and the test asserts what the page shows
against values computed here: the pixel (golden model), the commands acting on that
column (stream indices), and the PE's register history (its last row against the
functional model's final line state, every row against `diffengine trace --engine model`
at the cycle the page names). Chromium is installed once if missing (root), like
scripts/ensure_fst.sh does for GTKWave (both through scripts/ensure_system.sh);
without it the test fails and says why."""
from __future__ import annotations

import os
import random
import re
import shutil
import subprocess
import sys
from html.parser import HTMLParser
from pathlib import Path

import numpy as np
import pytest

from diffengine.formats import asm
from diffengine.cli import tree as cli
from diffengine.model import functional
from diffengine import isa
from diffengine.regress import randgen
from diffengine.rtl import trace

REPO = Path(__file__).resolve().parents[2]
CHIPS = 2
WIDTH = 9 * CHIPS


def ensure_chromium() -> str:
    exe = shutil.which("chromium")
    if exe:
        return exe
    # scripts/ensure_system.sh: the project's one lock around apt-get (pytest-xdist workers
    # and the other ensure scripts wait for each other); without root or sudo it says what
    # to install and fails.
    res = subprocess.run([str(REPO / "scripts" / "ensure_system.sh"), "chromium"],
                         capture_output=True, text=True)
    if res.returncode:
        pytest.fail(f"headless Chromium is needed for the inspector test: "
                    f"{res.stderr.strip()[-800:]}")
    exe = shutil.which("chromium")
    if not exe:
        pytest.fail("chromium installed but not on PATH")
    return exe


def dump_dom(page: Path, query: str) -> str:
    res = subprocess.run([ensure_chromium(), "--headless", "--no-sandbox", "--disable-gpu",
                          "--no-first-run", "--dump-dom", page.as_uri() + query],
                         capture_output=True, text=True, timeout=120)
    assert res.returncode == 0, res.stderr[-800:]
    return res.stdout


class Rows(HTMLParser):
    """Collects the attributes of #sel, #graph, its polyline and the rows of #cmds/#hist."""

    def __init__(self):
        super().__init__()
        self.table = None
        self.sel = self.graph = self.poly = None
        self.rows = {"cmds": [], "hist": []}

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if tag == "table" and a.get("id") in self.rows:
            self.table = a["id"]
        elif tag == "tr" and self.table and "data-k" in a:
            self.rows[self.table].append(a)
        elif a.get("id") == "sel":
            self.sel = a
        elif a.get("id") == "graph":
            self.graph = a
        elif tag == "polyline":
            self.poly = a

    def handle_endtag(self, tag):
        if tag == "table":
            self.table = None


def parse(dom: str) -> Rows:
    p = Rows()
    p.feed(dom)
    return p


@pytest.fixture(scope="module")
def page(tmp_path_factory):
    seed = int(os.environ.get("SEED", random.randrange(1 << 31)))
    print(f"SEED={seed} (replay: SEED={seed})", file=sys.stderr)
    cmds = randgen.stream(seed, 160, WIDTH, (4, 16))
    d = tmp_path_factory.mktemp("inspect")
    src = d / "stream.cmd"
    src.write_text("\n".join(asm.format_command(c) for c in cmds) + "\n")
    out = d / "page.html"
    assert cli.main(["inspect", str(src), "--chips", str(CHIPS), "--engine", "rtl",
                     "-o", str(out)]) == 0
    return seed, asm.parse_file(src), out


def _covers(c, col):
    if c.op in ("EVAL", "EVAL0", "DIS", "SETI", "SETDI", "SETDDI"):
        return c.x <= col < c.x + c.dx
    if c.op.startswith("SETP"):
        return col >= c.x and (col - c.x) % (c.dx or 4096) == 0
    return c.op in ("ACCMODE", "REFRESH")


def test_page_is_self_contained(page):
    text = page[2].read_text()
    refs = re.findall(r'(?:src|href)\s*=\s*"([^"]*)"', text)
    assert all(r.startswith(("data:", "#")) for r in refs), refs
    assert not re.search(r"https?://(?!www\.w3\.org/2000/svg)", text)
    assert "<script src" not in text and "<link" not in text


def test_click_shows_commands_and_registers(page):
    seed, cmds, out = page
    rng = random.Random(seed)
    lines = isa.split_lines(cmds)
    frame = functional.render(cmds, WIDTH)
    # a pixel some Eval acts on (else the history would only hold Set/Dis rows)
    cands = [(y, x) for y, ln in enumerate(lines) for x in range(WIDTH)
             if any(c.op == "EVAL" and _covers(c, x) for c in ln)]
    y, x = rng.choice(cands)
    p = parse(dump_dom(out, f"?x={x}&y={y}"))
    assert p.sel is not None and (p.sel["data-x"], p.sel["data-y"]) == (str(x), str(y))
    assert int(p.sel["data-pixel"]) == int(frame[y, x])
    start = sum(len(ln) for ln in lines[:y])
    want = [start + i for i, c in enumerate(lines[y]) if _covers(c, x)]
    assert [int(r["data-k"]) for r in p.rows["cmds"]] == want
    # register history: the final row is the line's architectural state at column x
    hist = p.rows["hist"]
    assert hist, f"no register history for line {y} column {x}"
    assert [int(r["data-k"]) for r in hist] == [k for k in want
                                               if lines[y][k - start].op != "REFRESH"]
    _, st = functional.run_line(lines[y], WIDTH)
    last = hist[-1]
    assert [int(last[f"data-{r}"]) for r in "abcd"] == [int(st.A[x]), int(st.B[x]),
                                                       int(st.C[x]), int(st.D[x])]
    assert isa.pixel_of(int(last["data-d"])) == int(frame[y, x])
    # every row equals the structural model's trace row at the cycle the page names,
    # except where the line's Refresh reaches the PE before the command's last block
    slots = isa.serialise(cmds)
    t = trace.Timing.of(slots, CHIPS)
    lo, hi = t.line_window(y)
    rows = {int(r.split(",")[0]): r.split(",")
            for r in trace.model_trace(slots, CHIPS, False, [x], lo, hi).rows}
    refresh_slot = len(isa.serialise(lines[y][:-1]))
    checked = 0
    for r in hist:
        k = int(r["data-k"]) - start
        end = len(isa.serialise(lines[y][:k + 1]))
        if refresh_slot - end < 3:
            continue
        tr = rows[int(r["data-cycle"])]
        assert [int(v, 16) for v in tr[4:8]] == [int(r[f"data-{n}"]) for n in "abcd"], \
            f"cycle {r['data-cycle']}: page {r} trace {tr}"
        checked += 1
    print(f"line {y} column {x}: {len(want)} commands, {len(hist)} history rows, "
          f"{checked} checked against the trace", file=sys.stderr)


def test_hover_draws_the_scanline(page):
    seed, cmds, out = page
    frame = functional.render(cmds, WIDTH)
    y = random.Random(seed + 1).randrange(frame.shape[0])
    p = parse(dump_dom(out, f"?hover={y}"))
    assert p.graph["data-line"] == str(y)
    assert [int(v) for v in p.poly["data-values"].split(",")] == frame[y].tolist()
    assert len(p.poly["points"].split()) == 2 * WIDTH
