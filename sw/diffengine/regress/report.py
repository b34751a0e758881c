"""Reports of a run: the verdict of a case, the terminal table, JUnit XML and the
self-contained HTML report."""
from __future__ import annotations

import html
import os
from pathlib import Path
from xml.etree import ElementTree as ET

import numpy as np

from .. import REPO
from ..formats.frame import data_uri, grey, png
from ..rtl.harness import PE_PER_CHIP
from .cases import Case


def heatmap(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """|a - b| as RGB: black = equal, dark red .. yellow = log2 of the difference."""
    if a.shape != b.shape:
        h, w = max(a.shape[0], b.shape[0]), max(a.shape[1], b.shape[1])
        out = np.zeros((h, w, 3), np.uint8)
        out[..., 2] = 160  # shape mismatch: blue everywhere
        return out
    d = np.abs(a.astype(np.int32) - b.astype(np.int32))
    t = np.where(d > 0, 0.25 + 0.75 * np.log2(d + 1) / 12.0, 0.0).clip(0, 1)
    rgb = np.zeros(d.shape + (3,), np.uint8)
    rgb[..., 0] = np.where(d > 0, 96 + 159 * np.minimum(1, t * 2), 0)
    rgb[..., 1] = np.where(d > 0, 255 * np.maximum(0, t * 2 - 1), 0)
    return rgb


# ---- reports ---------------------------------------------------------------------------


def verdict(case: Case, r: dict) -> str:
    """PASS, XFAIL (failed as expected), FAIL, XPASS (should have failed), ERROR, N/A."""
    s = r["status"]
    if s == "unavailable":
        return "N/A"
    if s == "error":
        return "ERROR"
    if case.bug:
        return "XFAIL" if s == "fail" and r.get("bug_model_matches", True) else (
            "XPASS" if s == "pass" else "FAIL")
    return "PASS" if s == "pass" else "FAIL"


GOOD = {"PASS", "XFAIL", "N/A"}


def summary_table(cases: list[Case], results: dict[str, dict]) -> str:
    rows = [("case", "chips", "build", "lines", "cmds", "result", "s", "detail")]
    for c in cases:
        r = results[c.name]
        rows.append((c.name, str(c.chips), "bug" if c.bug else "ok", str(r["n_lines"]),
                     str(r["n_commands"]), verdict(c, r), f"{r['seconds']:.1f}",
                     r["message"][:70]))
    w = [max(len(row[i]) for row in rows) for i in range(len(rows[0]))]
    out = ["  ".join(v.ljust(w[i]) for i, v in enumerate(row)) for row in rows]
    out.insert(1, "  ".join("-" * x for x in w))
    counts: dict[str, int] = {}
    for c in cases:
        v = verdict(c, results[c.name])
        counts[v] = counts.get(v, 0) + 1
    out.append(", ".join(f"{n} {k}" for k, n in sorted(counts.items())))
    return "\n".join(out)


def junit(cases: list[Case], results: dict[str, dict], tier: str, seconds: float,
          suite_name: str | None = None) -> bytes:
    suite = ET.Element("testsuite", name=suite_name or f"sim-regress-{tier}",
                       tests=str(len(cases)),
                       time=f"{seconds:.3f}")
    nfail = nerr = nskip = 0
    for c in cases:
        r = results[c.name]
        v = verdict(c, r)
        tc = ET.SubElement(suite, "testcase", classname=f"sim.{tier}.{c.kind}", name=c.name,
                           time=f"{r['seconds']:.3f}")
        detail = "\n".join([r["message"], *r["reasons"],
                            *(f"  cmd {k}: {t}" for k, t in r.get("touching", []))])
        if v == "FAIL" or v == "XPASS":
            nfail += 1
            msg = r["message"] if v == "FAIL" else "expected to fail on the carry-bug build but passed"
            ET.SubElement(tc, "failure", message=msg, type=v).text = detail
        elif v == "ERROR":
            nerr += 1
            ET.SubElement(tc, "error", message=r["message"]).text = detail
        elif v == "N/A":
            nskip += 1
            ET.SubElement(tc, "skipped", message=r["message"])
        else:
            ET.SubElement(tc, "system-out").text = f"{v}: {detail}"
    suite.set("failures", str(nfail))
    suite.set("errors", str(nerr))
    suite.set("skipped", str(nskip))
    return ET.tostring(suite, encoding="utf-8", xml_declaration=True)


_CSS = """
body{font:14px/1.4 system-ui,sans-serif;margin:1.5em;color:#222}
table{border-collapse:collapse}td,th{border:1px solid #ccc;padding:2px 6px;text-align:left}
.PASS,.XFAIL{background:#dfd}.FAIL,.XPASS,.ERROR{background:#fcc}.N\\/A{background:#eee}
.imgs{display:flex;gap:12px;flex-wrap:wrap}.imgs figure{margin:0}
.imgs img{image-rendering:pixelated;border:1px solid #888;min-width:240px}
figcaption{font-size:12px;color:#555}pre{background:#f6f6f6;padding:6px;overflow:auto}
section{border-top:2px solid #ddd;margin-top:1.2em;padding-top:.4em}
"""


def _img(frame, caption: str, scale_hint: int) -> str:
    if frame is None:
        return ""
    if frame.ndim == 2:
        g, top = grey(frame)
        caption += f" (white = {top})"
        data = png(g)
    else:
        data = png(frame)
    h, w = frame.shape[:2]
    k = max(1, min(8, scale_hint // max(1, w)))
    ky = min(64, max(k, -(-48 // max(1, h))))  # a one-line frame still gets 48 px
    return (f'<figure><img src="{data_uri(data)}" width="{w * k}" height="{h * ky}" '
            f'alt="{html.escape(caption)}"><figcaption>{html.escape(caption)}</figcaption></figure>')


def line_svg(rtl: np.ndarray, ref: np.ndarray, y: int, x: int) -> str:
    """The bad scanline, RTL (red) over the reference (blue), first bad column marked."""
    w, gw, gh, m = rtl.shape[1], 640, 160, 30
    top = max(1, int(max(rtl[y].max(), ref[y].max())))
    X = lambda c: m + (c + 0.5) * (gw - m - 6) / w  # noqa: E731
    Y = lambda v: gh - 16 - int(v) * (gh - 30) / top  # noqa: E731

    def poly(row, colour, width):
        pts = " ".join(f"{X(c - 0.5):.1f},{Y(v):.1f} {X(c + 0.5):.1f},{Y(v):.1f}"
                       for c, v in enumerate(row.tolist()))
        return (f'<polyline points="{pts}" fill="none" stroke="{colour}" '
                f'stroke-width="{width}"/>')

    return (f'<svg width="{gw}" height="{gh}" style="border:1px solid #ccc">'
            + poly(ref[y], "#1565c0", 3) + poly(rtl[y], "#e53935", 1.2)
            + f'<line x1="{X(x):.1f}" x2="{X(x):.1f}" y1="10" y2="{gh - 16}" stroke="#999" '
            f'stroke-dasharray="3,3"/><text x="{gw / 2}" y="11" font-size="11" '
            f'text-anchor="middle">scanline {y}: reference (blue), RTL (red), column {x} '
            f'dashed</text><text x="2" y="22" font-size="10">{top}</text>'
            f'<text x="2" y="{gh - 16}" font-size="10">0</text></svg>')


def html_report(cases: list[Case], results: dict[str, dict], tier: str, seconds: float,
                case_dirs: dict[str, Path] | None = None, out: Path | None = None,
                note: str = "") -> str:
    """The self-contained report. By default a case's files are linked as cases/<name>/
    next to the report; a merged report (shards) passes `case_dirs` (name -> the case's
    folder in its shard) and `out` (the report's folder) to link them where they are."""
    e = html.escape

    def href(name: str) -> str:
        if not case_dirs or name not in case_dirs:
            return f"cases/{name}"
        return Path(os.path.relpath(case_dirs[name], out or Path.cwd())).as_posix()

    def shown(name: str) -> str:  # the folder as a person types it, for the gtkwave hint
        if not case_dirs or name not in case_dirs:
            return f"sim/out/cases/{name}"
        d = Path(case_dirs[name]).resolve()
        return d.relative_to(REPO).as_posix() if d.is_relative_to(REPO) else str(d)

    rows = []
    for c in cases:
        r = results[c.name]
        v = verdict(c, r)
        rows.append(f'<tr class="{v}"><td><a href="#{e(c.name)}">{e(c.name)}</a></td>'
                    f"<td>{c.kind}</td><td>{c.chips}</td><td>{'carry bug' if c.bug else 'correct'}"
                    f"</td><td>{c.expect}</td><td>{v}</td><td>{r['n_lines']}</td>"
                    f"<td>{r['n_diff']}</td><td>{r['seconds']:.1f}</td></tr>")
    secs = []
    # unexpected results first, then the analysed expected failure, then the rest
    order = sorted(cases, key=lambda c: (verdict(c, results[c.name]) in GOOD,
                                         "trace" not in results[c.name]))
    for c in order:
        r = results[c.name]
        v = verdict(c, r)
        parts = [f'<section id="{e(c.name)}"><h3>{e(c.name)} <span class="{v}">{v}</span></h3>',
                 f"<p>{e(c.source)} &middot; {c.chips} chip(s) = {c.width} columns &middot; "
                 f"{'carry-bug build, expected to fail' if c.bug else 'correct build'} &middot; "
                 f"<a href=\"{e(href(c.name))}/stream.cmd\">stream.cmd</a> &middot; "
                 f"{e(r['message'])}</p>"]
        if r["reasons"]:
            parts.append("<ul>" + "".join(f"<li>{e(t)}</li>" for t in r["reasons"]) + "</ul>")
        if r["rtl"] is not None:
            imgs = [_img(r["rtl"], "RTL frame", 480), _img(r["ref"], "reference", 480),
                    _img(heatmap(r["rtl"], r["ref"]), "|RTL - reference| (log)", 480)]
            parts.append('<div class="imgs">' + "".join(imgs) + "</div>")
        if r.get("first") and r["rtl"] is not None:
            y, x = r["first"]
            parts.append(f"<h4>First differing pixel: line {y}, column {x} (PE {x}, chip "
                         f"{x // PE_PER_CHIP}): RTL {int(r['rtl'][y, x])}, reference "
                         f"{int(r['ref'][y, x])}</h4><p>Commands of line {y} acting on column "
                         f"{x} (stream index: command)</p><pre>"
                         + e("\n".join(f"{k:6d}: {t}" for k, t in r.get("touching", [])))
                         + "</pre>" + line_svg(r["rtl"], r["ref"], y, x))
            if r.get("trace"):
                parts.append("<p>Where the RTL and the structural model part "
                             "(<code>diffengine trace --compare</code>):</p><pre>"
                             + e(r["trace"]) + "</pre>")
            if r.get("waves"):
                parts.append("<p>Waves of the bad line: " + ", ".join(
                    f'<a href="{e(href(c.name))}/{e(w)}">{e(w)}</a>' for w in r["waves"])
                    + f" (open: <code>gtkwave {e(shown(c.name))}/"
                    f"{e(r['waves'][-1])}</code>)</p>")
        if r["harness"]:
            parts.append(f"<p><small>{e(r['harness'])}</small></p>")
        secs.append("".join(parts) + "</section>")
    counts = summary_table(cases, results).splitlines()[-1]
    return (f"<!doctype html><html><head><meta charset=\"utf-8\"><title>sim regression: {tier}"
            f"</title><style>{_CSS}</style></head><body><h1>RTL regression, tier {tier}</h1>"
            f"<p>{len(cases)} cases in {seconds:.1f} s: {e(counts)}."
            f"{' ' + e(note) if note else ''}"
            " Every frame comes from "
            "the Verilated array (sim/harness) and is compared bit for bit with the golden "
            "model (sw/diffengine/model/functional.py) or a stored reference frame. "
            "XFAIL = a carry-bug build that failed, as it must.</p><table><tr><th>case</th>"
            "<th>kind</th><th>chips</th><th>build</th><th>expect</th><th>result</th>"
            "<th>lines</th><th>pixels differing</th><th>s</th></tr>" + "".join(rows)
            + "</table>" + "".join(secs) + "</body></html>")
