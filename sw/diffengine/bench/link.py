"""Host side of the board's UART link (issue 18 item 3): how fast fpga/ulx3s/de32_load.py
drives the loader protocol, against the pure-Python loader model behind a pty (no board
here), so the tool is shown not to be what limits a 3 Mbaud load (300,000 bytes/s).
Baseline in the same run: the same stop-and-wait packets through the same pty to a
device thread that only counts the bytes and answers 'K' (no parsing, no host tool);
then the host tool against that device, then the host tool against the model.
Also the budget of a teapot frame at 3 Mbaud from `make demo`'s streams (calculated).
"""
from __future__ import annotations

import os
import pty
import random
import select
import sys
import threading
import time

from .. import REPO
from . import record
from . import render as doc

ULX = REPO / "fpga" / "ulx3s"
LINE_BPS = 300_000          # 3 Mbaud 8N1


class _Null:
    def write(self, s):
        pass

    def flush(self):
        pass

    def isatty(self):
        return False


def _echo_device(fd: int, sizes: list[int]) -> threading.Thread:
    def run():
        for n in sizes:
            got = 0
            while got < n:
                select.select([fd], [], [])
                got += len(os.read(fd, n - got))
            os.write(fd, b"K")
    t = threading.Thread(target=run, daemon=True)
    t.start()
    return t


def _echo_run(dl, pkts, fn) -> float:
    """Seconds fn(port) takes against the echo device behind a fresh pty."""
    master, slave = pty.openpty()
    port = dl.Port(os.ttyname(slave))
    th = _echo_device(master, [len(p) for p in pkts])
    t = time.perf_counter()
    fn(port)
    dt = time.perf_counter() - t
    th.join(2)
    for fd in (port.fd, master, slave):
        os.close(fd)
    return dt


def measure(words: int, per_packet: int, seed: int = 1) -> dict:
    sys.path.insert(0, str(ULX))
    import de32_load as dl
    from loader_model import Device, LoaderModel
    rng = random.Random(seed)
    frames = [[([rng.randrange(1 << 32) for _ in range(words)], 2, False)] * 3]
    pkts, _ = dl.plan_packets(frames, 0, per_packet, 0, 0, True, None)
    nbytes = sum(len(p) for p in pkts)

    record.OUT.mkdir(parents=True, exist_ok=True)
    state = str(record.OUT / "link.state.json")

    def raw(port):
        for p in pkts:
            port.write(p)
            assert port.read(1, 2.0) == b"K"

    def tool(port):
        st = dl.State(state, dl.plan_hash(pkts), len(pkts))
        dl.run_plan(dl.Loader(port), pkts, st, 0, stream=_Null())

    # Baseline: raw stop-and-wait through the pty, answered without parsing; then the
    # host tool (Loader, run_plan, state file) against the same echo device.
    base_s, echo_s = (_echo_run(dl, pkts, fn) for fn in (raw, tool))

    # The host tool and the loader model (the model parses every byte in Python).
    master, slave = pty.openpty()
    model = LoaderModel(fs_depth=max(1024, words))
    dev = Device(master, model)
    port = dl.Port(os.ttyname(slave))
    st = dl.State(state, dl.plan_hash(pkts), len(pkts))
    t = time.perf_counter()
    dl.run_plan(dl.Loader(port), pkts, st, 0, stream=_Null())
    tool_s = time.perf_counter() - t
    dev.stop()
    os.close(port.fd)
    os.close(slave)
    assert model.fs[0][:words] == frames[0][0][0], "the model did not receive the words"
    return {"words_per_colour": words, "packet_words": per_packet, "packets": len(pkts),
            "bytes": nbytes, "baseline_s": base_s, "echo_s": echo_s, "tool_s": tool_s,
            "baseline_kBps": nbytes / base_s / 1e3, "echo_kBps": nbytes / echo_s / 1e3,
            "tool_kBps": nbytes / tool_s / 1e3}


def teapot_budget() -> dict | None:
    d = REPO / "out" / "demo_cmd"
    if not all((d / f"{c}.de48").exists() for c in "rgb"):
        return None
    n = [((d / f"{c}.de48").stat().st_size - 8) // 6 for c in "rgb"]
    pk = sum(-(-k // 256) for k in n)
    wire = (4 * sum(n) + 7 * pk) / LINE_BPS
    return {"words": n, "bytes": 4 * sum(n), "packets": pk, "wire_s": wire,
            "with_1ms_s": wire + pk * 1e-3, "with_16ms_s": wire + pk * 16e-3,
            "at_115200_s": 4 * sum(n) / 11_520}


def configure(ap) -> None:
    """The arguments of `diffengine bench link`."""
    ap.add_argument("--words", type=int, default=16384, help="words per colour (16384)")
    ap.add_argument("--packet-words", default="24,256", help="packet sizes (24,256)")
    record.add_write(ap)
    ap.set_defaults(func=command)


def command(a) -> int:
    run = record.Run("link")
    rows = []
    for pw in (int(x) for x in a.packet_words.split(",")):
        run.log(f"{a.words} words x 3 colours in {pw}-word packets through a pty")
        rows.append(measure(a.words, pw))
        r = rows[-1]
        run.log(f"  raw pty {r['baseline_kBps']:.0f} kB/s, tool {r['echo_kBps']:.0f} kB/s, "
                f"tool + model {r['tool_kBps']:.0f} kB/s")
    rec = run.save({"rows": rows, "teapot": teapot_budget(), "cpus": os.cpu_count()}, a.write)
    if a.write:
        return doc.write(["link"])
    print(render(rec))
    return 0


def render(rec: dict) -> str:
    """The "UART link: host tool" section of docs/performance.md."""
    d = rec["data"]
    out = [f"`{rec['command']}` ({rec['date']}, revision {rec['revision']}, load average "
           f"{rec['load_before']} before / {rec['load_after']} after on {d['cpus']} cores; "
           "wall-clock, host tool and model in one process):", "",
           "| packet words | packets | bytes | raw pty stop-and-wait (baseline) kB/s | "
           "de32_load, device answers without parsing kB/s | de32_load + loader model kB/s | "
           "3 Mbaud line kB/s |",
           "|---|---|---|---|---|---|---|"]
    for r in d["rows"]:
        out.append(f"| {r['packet_words']} | {r['packets']} | {r['bytes']:,} | "
                   f"{r['baseline_kBps']:,.0f} | {r['echo_kBps']:,.0f} | {r['tool_kBps']:,.0f} | "
                   f"{LINE_BPS / 1e3:.0f} |")
    t = d.get("teapot")
    if t:
        out += ["", f"Teapot frame (`make demo`, words R/G/B {t['words']}): {t['bytes']:,} bytes "
                f"in {t['packets']:,} packets of 256 words: {t['wire_s']:.2f} s on the wire at "
                f"3 Mbaud; with a 1 ms USB turnaround per packet {t['with_1ms_s']:.1f} s, with "
                f"the FTDI default 16 ms {t['with_16ms_s']:.1f} s; at 115,200 baud "
                f"{t['at_115200_s']:.0f} s (calculated, docs/board.md §3.1)."]
    return "\n".join(out)
