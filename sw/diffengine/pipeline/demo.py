"""The full pipeline behind `make demo` (docs/pipeline.md, "Demo pipeline"):

  scene + OBJ --yproc scan (HSR + scan conversion + shading, C)--> r/g/b.de48
     --> Verilated display_controller (sim/dc, 3 x NumChips chips)  --> RTL frame (PNG)
     --> golden model (diffengine.model.fast, the C model, all three colours; --model numpy:
         diffengine.model.functional, the numpy reference it is tested equal to) --> must equal the RTL
     --> numpy reference renderer (16x16 Phong, diffengine.model.reference) --> PSNR

`run()` does all of it and returns a report dict; `command()` is its command line (`diffengine demo`, make demo).
Screens other than 640x480 run the controller's test mode (mode 3) with a line of the
640x480 mode's length (HTotal = 800, so the same 798 usable slots per line) and a short
vertical blank; the array needs at least as many PEs (9 per chip) as the screen has
columns.
"""
from __future__ import annotations

import hashlib
import json
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from .. import REPO, isa
from ..formats import binfmt, frame
from ..host import yproc
from ..model import fast, functional, reference
from ..rtl import dc_harness

YPROC = yproc.YPROC
MIN_PSNR = 38.0
# Mode 0 (640x480, spec/video.toml): its line of 800 is a 799-slot window, 798 usable
# (docs/pipeline.md 1.1); test-mode screens keep its line length and its HFp / HSync.
_, (H_ACTIVE, H_FP, H_SYNC, _), (V_ACTIVE, *_), _, _ = isa.VIDEO_MODES[0]
H_TOTAL = sum(isa.VIDEO_MODES[0][1])


class PipelineError(RuntimeError):
    pass


class Progress:
    """Progress on stderr: a one-line bar on a terminal (or always with force=True);
    elsewhere (logs, CI) a plain line every 10 %. `None`-safe to call from callbacks."""

    def __init__(self, label: str, enabled: bool = True, force: bool = False):
        self.label = label
        self.tty = force or sys.stderr.isatty()
        self.on = enabled
        self.t0 = time.monotonic()
        self.last = 0.0
        self.step = 0

    def __call__(self, done: float, total: float) -> None:
        if not self.on or total <= 0:
            return
        now = time.monotonic()
        frac = min(1.0, done / total)
        el = now - self.t0
        eta = el / frac - el if frac > 0 else 0
        if not self.tty:
            if int(10 * frac) > self.step:
                self.step = int(10 * frac)
                print(f"  {self.label:<10} {100 * frac:5.1f} %  {el:7.1f} s  (eta {eta:7.1f} s)",
                      file=sys.stderr, flush=True)
            return
        if now - self.last < 0.2 and done < total:
            return
        self.last = now
        bar = "#" * int(30 * frac) + "." * (30 - int(30 * frac))
        print(f"\r  {self.label:<10} [{bar}] {100 * frac:5.1f} %  {el:6.1f} s"
              f"  (eta {eta:5.1f} s) ", end="", file=sys.stderr, flush=True)

    def close(self) -> None:
        if self.on and self.tty:
            print("\r" + " " * 79 + "\r", end="", file=sys.stderr, flush=True)


def _cpu() -> float:
    import resource

    r = resource.getrusage(resource.RUSAGE_SELF)
    c = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime + c.ru_utime + c.ru_stime


def screen_of(scene: Path) -> tuple[int, int]:
    sc = reference.Scene()
    for line in Path(scene).read_text().splitlines():
        tok = line.split("#", 1)[0].split()
        if tok[:1] == ["screen"] and len(tok) == 3:
            sc.width, sc.height = int(float(tok[1])), int(float(tok[2]))
    return sc.width, sc.height


def controller_setup(width: int, height: int, chips: int) -> tuple[int, tuple]:
    """(mode, test geometry) for a screen: mode 0 for 640x480, else test mode 3 with
    HTotal = 800 and VFp/VSync/VBp = 1/2/2."""
    if chips * 9 < width:
        raise PipelineError(f"{chips} chips = {chips * 9} PEs per colour cannot show "
                            f"{width} columns (need at least {-(-width // 9)} chips)")
    if (width, height) == (H_ACTIVE, V_ACTIVE):
        return 0, dc_harness.DEFAULT_TEST
    if width + H_FP + H_SYNC + 1 > H_TOTAL:
        raise PipelineError(f"screen width {width}: only 640x480 or widths up to "
                            f"{H_TOTAL - H_FP - H_SYNC - 1} (test mode) are supported")
    return 3, (width, H_FP, H_SYNC, H_TOTAL - width - H_FP - H_SYNC, height, 1, 2, 2)


def capacity(mode: int, test: tuple) -> int:
    """Command slots a line can really use in the controller: HTotal - 2 (not HTotal - 1,
    the window: the end-of-line marker must reach the buffer's head inside the window)."""
    htotal = sum(isa.VIDEO_MODES[mode][1]) if mode in isa.VIDEO_MODES else sum(test[:4])
    return htotal - 2


def build_yproc() -> Path:
    try:
        return yproc.build()
    except yproc.YprocError as e:
        raise PipelineError(str(e)) from None


def yproc_scan(scene: Path, outdir: Path, aa: bool = True, shading: str | None = None,
               extra: tuple[str, ...] = ()) -> dict:
    """Run `yproc scan`; returns its stats.json (plus 'seconds')."""
    exe = build_yproc()
    outdir.mkdir(parents=True, exist_ok=True)
    cmd = [str(exe), "scan", str(scene), "-o", str(outdir)]
    if not aa:
        cmd.append("--no-aa")
    if shading:
        cmd += ["--shading", shading]
    cmd += list(extra)
    t0 = time.monotonic()
    res = subprocess.run(cmd, capture_output=True, text=True)
    secs = time.monotonic() - t0
    if res.returncode:
        raise PipelineError(f"{' '.join(cmd)} failed ({res.returncode}):\n{res.stderr.strip()}")
    for c in "rgb":
        if not (outdir / f"{c}.de48").exists():
            raise PipelineError(f"yproc scan wrote no {outdir / (c + '.de48')}")
    st = {}
    if (outdir / "stats.json").exists():
        st = json.loads((outdir / "stats.json").read_text())
    st["seconds"] = secs
    return st


MODELS = ("fast", "numpy")


def golden(paths, width: int, height: int, carry_bug: bool = False,
           progress=None, model: str = "fast") -> np.ndarray:
    """The golden model frame (H, W, 3) uint16 from three .de48 streams: model "fast" is
    the C functional model (diffengine.model.fast, milliseconds), "numpy" the numpy
    reference (diffengine.model.functional) that sw/tests/test_fmodel.py proves it equal to."""
    if model == "fast":
        try:
            out = fast.render_frame(paths, width, height, carry_bug)
        except fast.FastModelError as e:
            raise PipelineError(str(e)) from None
        if progress:
            progress(1, 1)
        return out
    if model != "numpy":
        raise PipelineError(f"unknown golden model {model!r} (one of {', '.join(MODELS)})")
    out = np.zeros((height, width, 3), dtype=np.uint16)
    streams = []
    for p in paths:
        cmds, _ = binfmt.load_commands(Path(p).read_bytes(), str(p))
        streams.append(cmds)
    total = sum(len(c) for c in streams)
    done = 0
    for ch, cmds in enumerate(streams):
        lines = [[]]
        for c in cmds:                      # split into lines (keep their Refresh)
            lines[-1].append(c)
            if c.op == "REFRESH":
                lines.append([])
        lines = [ln for ln in lines if ln and ln[-1].op == "REFRESH"]
        if len(lines) > height:
            raise PipelineError(f"{paths[ch]}: {len(lines)} lines, the screen has {height}")
        for k in range(0, len(lines), 64):
            chunk = [c for ln in lines[k:k + 64] for c in ln]
            out[k:k + 64][:len(lines[k:k + 64]), :, ch] = functional.render(chunk, width,
                                                                            carry_bug)
            done += len(chunk)
            if progress:
                progress(done, total)
    return out


def _reference_cached(scene: Path, cache_dir: Path, samples: int = 16, progress=None):
    """The reference frame, cached under cache_dir by the scene's (and its OBJs' and their
    .mtl files') text and the renderer's source."""
    h = hashlib.sha256()
    h.update(Path(reference.__file__).read_bytes())
    h.update(str(samples).encode())
    text = scene.read_text()
    h.update(text.encode())
    for line in text.splitlines():
        tok = line.split("#", 1)[0].split()
        if tok[:1] == ["obj"] and len(tok) >= 2:
            p = Path(tok[1])
            p = p if p.is_absolute() else scene.parent / p
            if p.exists():
                data = p.read_bytes()
                h.update(data)
                for ln in data.decode("utf-8", "surrogateescape").split("\n"):
                    t = ln.split("#", 1)[0].split()
                    for m in t[1:] if t[:1] == ["mtllib"] else ():   # its .mtl files
                        q = p.parent / m
                        if q.is_file():
                            h.update(q.read_bytes())
    path = cache_dir / f".reference_{h.hexdigest()[:16]}.npy"
    if path.exists():
        return np.load(path), True
    img = reference.render_file(scene, samples=samples, progress=progress)
    cache_dir.mkdir(parents=True, exist_ok=True)
    np.save(path, img)
    return img, False


def run(scene, outdir, chips: int = 72, threads: int = 1, rtl: bool = True,
        aa: bool = True, shading: str | None = None, num_buf: int = 1,
        show_progress: bool = True, log=print, ref_samples: int = 16,
        png_name: str = "demo", model: str = "fast") -> dict:
    """The whole pipeline; returns the report (also written to OUTDIR/<png_name>_report.json).

    Raises PipelineError on a failed stage; the report's 'bit_identical' and 'psnr_db'
    say whether the RTL frame equals the golden model and how close it is to the
    reference (the caller decides what to do with PSNR < 38 dB)."""
    scene, outdir = Path(scene).resolve(), Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    W, H = screen_of(scene)
    mode, test = controller_setup(W, H, chips)
    rep: dict = {"scene": str(scene.relative_to(REPO) if scene.is_relative_to(REPO) else scene),
                 "screen": [W, H], "chips_per_colour": chips, "pes_per_colour": 9 * chips,
                 "mode": mode, "test_geometry": list(test) if mode == 3 else None,
                 "threads": threads, "anti_aliasing": aa, "shading": shading or "scene",
                 "stages": {}}
    stages, cpu = rep["stages"], rep.setdefault("stages_cpu", {})
    clock = [_cpu()]

    def stage(name, secs):
        # wall seconds, and CPU seconds of this process and its children since the last
        # stage (on a shared machine the CPU figure is the one that compares)
        now = _cpu()
        stages[name] = round(secs, 3)
        cpu[name] = round(now - clock[0], 3)
        clock[0] = now
        log(f"  {name:<28} {secs:8.2f} s  (cpu {cpu[name]:7.2f} s)")

    log(f"demo: {rep['scene']} at {W}x{H}, {chips} chips x 3 colours"
        + ("" if rtl else " (model only, --no-rtl)"))
    cmd_dir = outdir / f"{png_name}_cmd"
    t0 = time.monotonic()
    # A line of HTotal - 1 command slots is late: its marker reaches the buffer head only
    # at the Refresh slot (docs/pipeline.md, "Line capacity"), so yproc gets HTotal - 2.
    ys = yproc_scan(scene, cmd_dir, aa=aa, shading=shading,
                    extra=("--capacity", str(capacity(mode, test))))
    stage("yproc scan (HSR+scan+shade)", ys["seconds"])
    rep["yproc"] = ys
    paths = [cmd_dir / f"{c}.de48" for c in "rgb"]
    rep["instructions"] = {c: (p.stat().st_size - 8) // 6 for c, p in zip("RGB", paths)}

    pb = Progress("golden", show_progress)
    t = time.monotonic()
    gold = golden(paths, W, H, progress=pb, model=model)
    pb.close()
    stage(f"golden model ({'C, fmodel' if model == 'fast' else 'numpy'})", time.monotonic() - t)
    rep["golden_model"] = model

    if rtl:
        cfg = dc_harness.Config(chips=chips, num_buf=num_buf, threads=threads, test=test)
        t = time.monotonic()
        log(f"  RTL build: sim/build/{cfg.tag} (cached after the first time; cold, about "
            f"1 min on 2 cores: one chip model compiled once for all {3 * chips} chips, sim/fast)")
        _, rebuilt, bsecs = dc_harness.build(cfg)
        stage("RTL build" + (" (cold)" if rebuilt else " (cached)"), bsecs)
        rep["rtl_build"] = {"seconds": round(bsecs, 3), "rebuilt": rebuilt, "config": cfg.tag}
        pb = Progress("RTL", show_progress)
        t = time.monotonic()
        frames, st = dc_harness.run(paths, cfg, mode=mode, progress=pb)
        pb.close()
        stage("RTL display_controller", time.monotonic() - t)
        rtl_frame = frames[-1]
        rep["rtl"] = {k: st.get(k) for k in (
            "cycles", "seconds", "cycles_per_second", "cpu_seconds", "cycles_per_cpu_second",
            "frames", "h_total", "v_total", "sync", "align_err", "pix_collision", "threads")}
        rep["load_monitor"] = {c: {k: v for k, v in m.items() if k != "line_issued"}
                               for c, m in st["load_monitor"].items()}
        rep["commands_per_line"] = {c: m["line_issued"] for c, m in st["load_monitor"].items()}
        log(dc_harness.monitor_summary(st))
        diff = rtl_frame != gold
        rep["bit_identical"] = not diff.any()
        if diff.any():
            y, x, c = np.argwhere(diff)[0]
            rep["first_difference"] = {"x": int(x), "y": int(y), "channel": "RGB"[c],
                                       "rtl": int(rtl_frame[y, x, c]), "golden": int(gold[y, x, c]),
                                       "pixels": int(diff.any(-1).sum())}
        img = rtl_frame
    else:
        rep["bit_identical"] = None
        img = gold
    frame.write_png16(outdir / f"{png_name}.png", img, "diffengine demo")
    frame.write_png8(outdir / f"{png_name}_8bit.png", img, "diffengine demo")
    if rtl:
        frame.write_png16(outdir / f"{png_name}_golden.png", gold, "diffengine golden model")

    pb = Progress("reference", show_progress)
    t = time.monotonic()
    ref_img, cached = _reference_cached(scene, outdir, ref_samples, progress=pb)
    pb.close()
    stage("reference renderer" + (" (cached)" if cached else ""), time.monotonic() - t)
    frame.write_png16(outdir / f"{png_name}_reference.png",
                      np.clip(np.round(ref_img), 0, 4095).astype(np.uint16), "diffengine ref")
    rep["psnr_db"] = round(reference.psnr(gold, ref_img), 3)
    err = np.abs(gold.astype(np.float64) - ref_img)
    rep["error"] = {"max": round(float(err.max()), 2), "mean": round(float(err.mean()), 4),
                    "p99": round(float(np.percentile(err, 99)), 2)}
    # What an average hides: isolated wrong pixels and streaks on smooth surfaces.
    bad = reference.outliers(gold, ref_img)
    worst = err.max(axis=-1)
    rep["outliers"] = {
        "count": int(bad.sum()), "error_above": reference.OUTLIER_ERROR,
        "where_reference_spans_below": reference.OUTLIER_SMOOTH,
        "map": f"{png_name}_outliers.png",
        "first": [{"x": int(x), "y": int(y), "error": round(float(worst[y, x]), 1)}
                  for y, x in np.argwhere(bad)[:20]]}
    frame.write_rgb8(outdir / f"{png_name}_outliers.png", reference.outlier_map(gold, bad),
                     "diffengine outliers")
    rep["total_seconds"] = round(time.monotonic() - t0, 3)
    (outdir / f"{png_name}_report.json").write_text(json.dumps(rep, indent=1) + "\n")
    return rep


# ---- `diffengine demo` (make demo) ----------------------------------------------------

COMMAND_HELP = """OBJ -> HSR -> scan conversion + shading (yproc scan) -> r/g/b.de48 command streams ->
the Verilated full-colour display_controller (3 x CHIPS chips) -> out/demo.png (16-bit)
and out/demo_8bit.png; the same streams through the golden model (must be bit-identical
to the RTL frame); the numpy reference renderer (16x16 supersampled Phong) -> PSNR
(target >= 38 dB). Prints the time of each stage and the Load Monitor summary, writes
out/demo_report.json. Exit status 0 only if the RTL frame equals the golden model, the
PSNR reaches --min-psnr and there are no more than --max-outliers outlier pixels (an
error above 0.15 of full scale where the reference is smooth: isolated wrong pixels and
streaks that an average hides; out/demo_outliers.png marks them in red).

A smaller array (--chips) only makes sense with a smaller screen: the array needs at
least ceil(width / 9) chips per colour; screens other than 640x480 run the controller's
test mode with a 640x480-length line (798 usable command slots per line).
"""


def configure(ap) -> None:
    """The arguments of `diffengine demo` (make demo)."""
    ap.epilog = COMMAND_HELP
    ap.add_argument("--scene", default=str(REPO / "sw/scenes/teapot/teapot.scene"),
                    help="scene file (default: the Utah teapot at 640x480)")
    ap.add_argument("--out", default=str(REPO / "out"), help="output folder (default out/)")
    ap.add_argument("--chips", type=int, default=72,
                    help="chips (9 PEs each) per colour array; default 72 = 648 PEs for "
                         "640 columns. Fewer chips need a screen at most 9*CHIPS wide")
    ap.add_argument("--threads", type=int, default=1,
                    help="Verilator threads for the RTL model (separate cached build)")
    ap.add_argument("--no-rtl", action="store_true",
                    help="model only: skip the Verilated controller, demo.png from the golden model")
    ap.add_argument("--no-aa", action="store_true", help="yproc scan --no-aa (point sampling)")
    ap.add_argument("--shading", choices=["flat", "gouraud", "phong"],
                    help="yproc scan --shading (default: the scene's)")
    ap.add_argument("--num-buf", type=int, default=1,
                    help="y-processors (buffers per colour); lines are dealt round-robin")
    ap.add_argument("--model", choices=MODELS, default="fast",
                    help="golden model: fast = the C functional model (sw/fmodel, default), "
                         "numpy = the numpy reference it is tested equal to")
    ap.add_argument("--min-psnr", type=float, default=MIN_PSNR)
    ap.add_argument("--max-outliers", type=int, default=0,
                    help="fail above this many outlier pixels (error > 0.15 of full scale "
                         "where the reference is smooth; default 0)")
    ap.set_defaults(func=command)


def command(a) -> int:
    try:
        rep = run(a.scene, a.out, chips=a.chips, threads=a.threads,
                           rtl=not a.no_rtl, aa=not a.no_aa, shading=a.shading,
                           num_buf=a.num_buf, model=a.model)
    except (PipelineError, RuntimeError, OSError, ValueError) as e:
        print(f"demo: error: {e}", file=sys.stderr)
        return 1
    ok = True
    out = Path(a.out)
    print(f"  {'total':<28} {rep['total_seconds']:8.2f} s")
    if rep["bit_identical"] is not None:
        if rep["bit_identical"]:
            print("RTL frame == golden model frame, bit for bit")
        else:
            print(f"FAIL: RTL frame differs from the golden model: {rep['first_difference']}")
            ok = False
    good = rep["psnr_db"] >= a.min_psnr
    print(f"PSNR against the reference renderer: {rep['psnr_db']:.2f} dB "
          f"({'>=' if good else 'BELOW'} {a.min_psnr:g} dB target); |error| max "
          f"{rep['error']['max']}, mean {rep['error']['mean']} pixel units")
    ok &= good
    o = rep["outliers"]
    clean = o["count"] <= a.max_outliers
    print(f"outliers (error > {o['error_above']:g} of full scale where the reference is "
          f"smooth): {o['count']} ({'<=' if clean else 'ABOVE'} {a.max_outliers}); map: "
          f"{out / o['map']}")
    if not clean:
        print("  first: " + ", ".join(f"({p['x']},{p['y']}) {p['error']}" for p in o["first"][:8]))
    ok &= clean
    print(f"wrote {out / 'demo.png'} (16-bit), {out / 'demo_8bit.png'}, "
          f"{out / 'demo_reference.png'}, {out / 'demo_report.json'}")
    return 0 if ok else 1
