// Whole-board full-frame simulation (issue 18 item 4; docs/board-frames.md): the board
// core de_board_core with the timing-checking SDRAM model on its SDRAM pins
// (tb/board_top/tb_board_sdram.sv), Verilated, driven by this plain C++ harness (no
// Python in the clock loop).
//
// Clocks from one timebase, as the ULX3S PLL makes them from its 625 MHz VCO: pixel
// 25 MHz (VCO / 25), core 78.125 MHz (/ 8), SDRAM 125 MHz (/ 5). The harness steps a
// 1.25 GHz grid (0.8 ns, half the VCO period) on which every edge of the three falls.
//
// The SDRAM model starts from a preload image (+sdram_image=, docs/sdram-frames-spec.md
// §5, written by fpga/ulx3s/frame_pack.py), so the frame store is loaded without the 'X'
// writes; the harness is the host on the UART line (3 Mbaud 8N1, its own bit clock, not
// the board's): it sends the packets of a host file (the 'O' output window, the 'F'
// frame slots and the 'Q' sequence), each answered 'K' before the next, then watches
// the three TMDS streams, decodes them (DVI 1.0 §3.2.2: control tokens in blanking,
// transition-minimised data in DE) into frames and compares every pixel with the golden
// frames, and at the end reads the Load Monitors' late-line and dropped-word totals
// ('R'), the loader's status ('S') and the model's violation count.
//
//   Vtb_board_sdram +sdram_image=IMG.hex --host HOST.txt --golden G.rgb --frames N
//                   [--out FRAMES.rgb] [--stats S.json] [--max-frames M] [--mode 0]
//                   [--progress]
//
// HOST.txt: one packet a line, hex bytes (checksum included), '#' comments; each must
// be answered 'K'. G.rgb: K golden frames, VActive x HActive x (R, G, B) bytes each,
// the sequence's frames in order. The run ends N frames after the first frame that is
// not black (the sequence has started), or after M frames in all (default N + 8).
// Each frame is classified: black, golden k (every pixel equal), or neither (the
// golden frame with the fewest differing pixels, and how many). FRAMES.rgb: every frame
// from the first non-black one, same layout as G.rgb. Exit status: 0 every check
// passed, 1 a check failed (outputs still written), 2 usage / input error.
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <deque>
#include <memory>
#include <string>
#include <vector>

#include <unistd.h>

#include "Vtb_board_sdram.h"
#include "de_isa.h"
#include "verilated.h"
#include "verilated_syms.h"

namespace {

constexpr int kCh = 3;
// The 1.25 GHz grid: half-periods of the three clocks in 0.8 ns units.
constexpr uint64_t kUnitPs = 800;
constexpr uint64_t kHalfPix = 25, kHalfCore = 8, kHalfSd = 5;
constexpr double kBaud = 3e6;
constexpr double kBitPs = 1e12 / kBaud;

// DVI 1.0 control tokens, by (C1, C0).
constexpr uint16_t kCtrl[4] = {0x354, 0x0AB, 0x154, 0x2AB};

// One TMDS symbol -> {is control, value}: C for a control token, else the 8-bit data
// (DVI 1.0 §3.3.3's decoder: undo the inversion (bit 9), then the XOR / XNOR chain
// (bit 8)).
struct Sym {
  bool ctrl;
  int v;
};
Sym tmds_decode(uint32_t s) {
  for (int c = 0; c < 4; ++c)
    if (s == kCtrl[c]) return {true, c};
  uint32_t d = s & 0xFF;
  if (s & 0x200) d = ~d & 0xFF;
  uint32_t out = d & 1;
  for (int i = 1; i < 8; ++i) {
    uint32_t b = ((d >> i) ^ (d >> (i - 1))) & 1;
    if (!(s & 0x100)) b ^= 1;
    out |= b << i;
  }
  return {false, static_cast<int>(out)};
}

struct Geom {
  int ha, hfp, hs, hbp, va, vfp, vs, vbp;
  int hpol, vpol;
  int htotal() const { return ha + hfp + hs + hbp; }
  int vtotal() const { return va + vfp + vs + vbp; }
};

std::string hexs(const std::vector<uint8_t>& b) {
  std::string s;
  char t[4];
  for (uint8_t x : b) {
    std::snprintf(t, sizeof t, "%02x", x);
    s += t;
  }
  return s;
}

bool read_host(const char* path, std::vector<std::vector<uint8_t>>& pkts, std::string& err) {
  FILE* f = std::fopen(path, "r");
  if (!f) {
    err = std::string(path) + ": cannot open";
    return false;
  }
  char line[1 << 14];
  int n = 0;
  while (std::fgets(line, sizeof line, f)) {
    ++n;
    std::vector<uint8_t> p;
    int digits = 0, cur = 0;
    for (char* c = line; *c && *c != '#'; ++c) {
      int v = -1;
      if (*c >= '0' && *c <= '9') v = *c - '0';
      else if (*c >= 'a' && *c <= 'f') v = *c - 'a' + 10;
      else if (*c >= 'A' && *c <= 'F') v = *c - 'A' + 10;
      else if (*c == ' ' || *c == '\t' || *c == '\n' || *c == '\r') continue;
      if (v < 0) {
        err = std::string(path) + ":" + std::to_string(n) + ": not a hex digit '" + *c + "'";
        std::fclose(f);
        return false;
      }
      cur = cur << 4 | v;
      if (++digits % 2 == 0) {
        p.push_back(static_cast<uint8_t>(cur));
        cur = 0;
      }
    }
    if (digits % 2) {
      err = std::string(path) + ":" + std::to_string(n) + ": odd number of hex digits";
      std::fclose(f);
      return false;
    }
    if (!p.empty()) {
      unsigned sum = 0;
      for (uint8_t x : p) sum += x;
      if (sum & 0xFF) {
        err = std::string(path) + ":" + std::to_string(n) + ": checksum: the bytes sum to " +
              std::to_string(sum & 0xFF) + " mod 256, want 0";
        std::fclose(f);
        return false;
      }
      pkts.push_back(p);
    }
  }
  std::fclose(f);
  return true;
}

std::vector<uint8_t> with_chk(std::vector<uint8_t> b) {
  unsigned s = 0;
  for (uint8_t x : b) s += x;
  b.push_back(static_cast<uint8_t>(-s & 0xFF));
  return b;
}

// The host's UART: 8N1 at exactly kBaud on its own clock (ps), independent of the
// board's clocks, like the FT231X.
struct UartHost {
  // Transmit.
  std::deque<uint8_t> txq;
  bool tx_busy = false;
  double tx_start = 0;
  int tx_byte = 0;
  // Receive.
  bool rx_busy = false;
  double rx_start = 0;
  int rx_bit = 0, rx_val = 0;
  int prev_line = 1;
  std::vector<uint8_t> rx;
  uint64_t rx_ferr = 0;

  // Line level the host drives at time t (ps).
  int tx_level(double t) {
    if (!tx_busy) {
      if (txq.empty()) return 1;
      tx_busy = true;
      tx_start = t;
      tx_byte = txq.front();
      txq.pop_front();
    }
    const int bit = static_cast<int>((t - tx_start) / kBitPs);
    if (bit >= 10) {  // stop bit done: the next byte starts now
      tx_busy = false;
      return tx_level(t);
    }
    if (bit == 0) return 0;
    if (bit == 9) return 1;
    return (tx_byte >> (bit - 1)) & 1;
  }

  // The board's uart_tx_o seen at time t (ps): sample each bit in its middle.
  void rx_step(int line, double t) {
    if (!rx_busy) {
      if (prev_line == 1 && line == 0) {
        rx_busy = true;
        rx_start = t;
        rx_bit = 0;
        rx_val = 0;
      }
    } else {
      const double mid = rx_start + (rx_bit + 0.5) * kBitPs;
      if (t >= mid) {
        if (rx_bit == 0) {
          if (line != 0) rx_busy = false;  // a glitch, not a start bit
        } else if (rx_bit <= 8) {
          rx_val |= line << (rx_bit - 1);
        } else {
          if (line != 1) ++rx_ferr;
          rx.push_back(static_cast<uint8_t>(rx_val));
          rx_busy = false;
        }
        ++rx_bit;
      }
    }
    prev_line = line;
  }
};

// When a sticky flag first rose: pixel clock, frame being decoded, its line.
struct Rise {
  int64_t clock = -1, frame = -1, line = -1;
  bool update(bool level, uint64_t clk, size_t fr, int ln) {  // true at the first rise
    if (!level || clock >= 0) return false;
    clock = static_cast<int64_t>(clk);
    frame = static_cast<int64_t>(fr);
    line = ln;
    return true;
  }
  std::string json() const {
    return "[" + std::to_string(clock) + ", " + std::to_string(frame) + ", " +
           std::to_string(line) + "]";
  }
};

struct FrameInfo {
  int kind;          // -1 black, k >= 0 golden k, -2 neither
  int best;          // golden index with the fewest differing pixels
  uint64_t diff;     // pixels differing from golden `best`
  uint64_t cycle;    // pixel clock at which the frame's last line ended
  int first_x = -1, first_y = -1;
};

}  // namespace

int main(int argc, char** argv) {
  const char *host_path = nullptr, *golden_path = nullptr, *out_path = nullptr,
             *stats_path = nullptr;
  int want = 1, max_frames = -1, mode = 0;
  bool progress = false;
  for (int i = 1; i < argc; ++i) {
    auto arg = [&](const char* name) { return !std::strcmp(argv[i], name) && i + 1 < argc; };
    if (arg("--host")) host_path = argv[++i];
    else if (arg("--golden")) golden_path = argv[++i];
    else if (arg("--out")) out_path = argv[++i];
    else if (arg("--stats")) stats_path = argv[++i];
    else if (arg("--frames")) want = std::atoi(argv[++i]);
    else if (arg("--max-frames")) max_frames = std::atoi(argv[++i]);
    else if (arg("--mode")) mode = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--progress")) progress = true;
    else if (!std::strcmp(argv[i], "--help") || !std::strcmp(argv[i], "-h")) {
      std::printf(
          "usage: %s +sdram_image=IMG.hex --host HOST.txt --golden G.rgb --frames N\n"
          "          [--out FRAMES.rgb] [--stats S.json] [--max-frames M] [--mode 0..2] "
          "[--progress]\n"
          "The board core + SDRAM model (tb_board_sdram), preloaded; the host packets of\n"
          "HOST.txt sent over the UART (each answered 'K'); the TMDS streams decoded and\n"
          "compared with the golden frames (docs/board-frames.md). Exit 0 all checks passed,\n"
          "1 a check failed, 2 usage or input error.\n",
          argv[0]);
      return 0;
    } else if (argv[i][0] == '+') {
      // plusargs: the model reads them (+sdram_image=, +sdram_log=)
    } else {
      std::fprintf(stderr, "%s: unknown argument %s (--help)\n", argv[0], argv[i]);
      return 2;
    }
  }
  if (!host_path || !golden_path || want < 1 || mode < 0 || mode > 2) {
    std::fprintf(stderr, "%s: need --host, --golden, --frames >= 1, --mode 0..2 (--help)\n",
                 argv[0]);
    return 2;
  }
  if (max_frames < 0) max_frames = want + 8;
  const de_video_mode* m = de_video_mode_get(mode);
  const Geom g{m->h[0], m->h[1], m->h[2], m->h[3], m->v[0], m->v[1], m->v[2], m->v[3],
               m->hpol, m->vpol};
  const int HT = g.htotal(), VT = g.vtotal();
  const size_t fbytes = static_cast<size_t>(g.ha) * g.va * kCh;

  std::vector<std::vector<uint8_t>> pkts;
  std::string err;
  if (!read_host(host_path, pkts, err)) {
    std::fprintf(stderr, "%s\n", err.c_str());
    return 2;
  }
  std::vector<uint8_t> golden;
  {
    FILE* f = std::fopen(golden_path, "rb");
    if (!f) {
      std::fprintf(stderr, "%s: cannot open\n", golden_path);
      return 2;
    }
    uint8_t buf[1 << 16];
    size_t n;
    while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) golden.insert(golden.end(), buf, buf + n);
    std::fclose(f);
  }
  if (golden.empty() || golden.size() % fbytes) {
    std::fprintf(stderr, "%s: %zu bytes is not a whole number of %dx%dx3 frames\n", golden_path,
                 golden.size(), g.ha, g.va);
    return 2;
  }
  const int ngold = static_cast<int>(golden.size() / fbytes);

  auto ctx = std::make_unique<VerilatedContext>();
  ctx->commandArgs(argc, argv);
  auto top = std::make_unique<Vtb_board_sdram>(ctx.get());

  // ---------------------------------------------------------------- the clock grid
  uint64_t t = 0;  // 0.8 ns units
  uint64_t pix_cycles = 0, core_cycles = 0, sd_cycles = 0;
  UartHost uart;
  auto level = [](uint64_t tt, uint64_t half) { return static_cast<int>((tt / half) % 2 == 0); };
  // Advance to the next edge of any clock and evaluate; returns true on a pixel rising edge.
  auto step = [&]() -> bool {
    const uint64_t nx = std::min({(t / kHalfPix + 1) * kHalfPix, (t / kHalfCore + 1) * kHalfCore,
                                  (t / kHalfSd + 1) * kHalfSd});
    t = nx;
    const double ps = static_cast<double>(t * kUnitPs);
    top->uart_rx_i = uart.tx_level(ps);
    top->clk_i = level(t, kHalfPix);
    top->clk_core_i = level(t, kHalfCore);
    top->clk_sdram_i = level(t, kHalfSd);
    top->eval();
    uart.rx_step(top->uart_tx_o, ps);
    const bool pix_rise = t % (2 * kHalfPix) == 0;
    if (pix_rise) ++pix_cycles;
    if (t % (2 * kHalfCore) == 0) ++core_cycles;
    if (t % (2 * kHalfSd) == 0) ++sd_cycles;
    return pix_rise;
  };

  // The span arrays' sticky flags (board_public.vlt): every de_span_video scope's ovf_q
  // and late_q, in scope-name order (colour R, G, B: g_arr[0..2]).
  struct SpanFlags {
    std::string scope;
    const CData *ovf, *late;
    Rise ovf_at, late_at;
  };
  std::vector<SpanFlags> span;
  if (const VerilatedScopeNameMap* sm = ctx->scopeNameMap())
    for (const auto& it : *sm) {
      const VerilatedVar* o = it.second->varFind("ovf_q");
      const VerilatedVar* l = it.second->varFind("late_q");
      if (o && l)
        span.push_back({it.first, static_cast<const CData*>(o->datap()),
                        static_cast<const CData*>(l->datap()), {}, {}});
    }
  std::sort(span.begin(), span.end(),
            [](const SpanFlags& a, const SpanFlags& b) { return a.scope < b.scope; });

  top->rst_i = 1;
  top->mode_i = mode;
  top->uart_rx_i = 1;
  top->clk_i = top->clk_core_i = top->clk_sdram_i = 1;
  top->eval();
  while (pix_cycles < 16) step();
  top->rst_i = 0;

  // ---------------------------------------------------------------- host and video
  std::vector<std::string> errors;
  size_t pkt = 0;          // next packet
  bool waiting = false;    // for the reply of pkts[pkt - 1]
  uint64_t sent_at = 0;
  size_t rx_used = 0;
  const uint64_t reply_timeout = 20000;  // pixel clocks (0.8 ms)
  uint64_t host_done_at = 0;

  std::vector<uint8_t> cur(fbytes, 0);
  std::vector<uint8_t> saved;  // frames from the first non-black one
  std::vector<FrameInfo> frames;
  int row = 0, col = 0, lines_in_frame = 0;
  bool in_de = false, frame_open = false, prev_vs = false, prev_hs = false;
  uint64_t hs_rise = 0, de_runs_bad = 0, frame_lines_bad = 0, hs_period_bad = 0,
           hs_width_bad = 0, ctrl_bad = 0, disagree = 0, vs_count = 0, hs_count = 0;
  int first_live = -1;     // index in frames of the first non-black frame
  Rise led_first[8];
  const int sync_on_h = g.hpol ? 1 : 0, sync_on_v = g.vpol ? 1 : 0;

  auto t0 = std::chrono::steady_clock::now();
  const std::clock_t c0 = std::clock();
  auto t_prog = t0;
  const bool tty = isatty(2);
  const uint64_t frame_clocks = static_cast<uint64_t>(HT) * VT;

  auto finish_frame = [&]() {
    FrameInfo fi{-2, -1, ~0ull, pix_cycles};
    bool black = std::all_of(cur.begin(), cur.end(), [](uint8_t v) { return v == 0; });
    for (int k = 0; k < ngold; ++k) {
      const uint8_t* gk = &golden[k * fbytes];
      uint64_t d = 0;
      int fx = -1, fy = -1;
      for (size_t p = 0; p < fbytes; p += kCh)
        if (cur[p] != gk[p] || cur[p + 1] != gk[p + 1] || cur[p + 2] != gk[p + 2]) {
          if (!d) {
            fx = static_cast<int>(p / kCh % g.ha);
            fy = static_cast<int>(p / kCh / g.ha);
          }
          ++d;
        }
      if (d < fi.diff) {
        fi.diff = d;
        fi.best = k;
        fi.first_x = fx;
        fi.first_y = fy;
      }
    }
    fi.kind = fi.diff == 0 ? fi.best : (black ? -1 : -2);
    if (fi.kind != -1 && first_live < 0) first_live = static_cast<int>(frames.size());
    if (first_live >= 0) saved.insert(saved.end(), cur.begin(), cur.end());
    frames.push_back(fi);
    const double el = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (fi.kind >= 0)
      std::fprintf(stderr, "board_sim: frame %zu = golden frame %d, every pixel (%.0f s)\n",
                   frames.size() - 1, fi.kind, el);
    else if (fi.kind == -1)
      std::fprintf(stderr, "board_sim: frame %zu black (%.0f s)\n", frames.size() - 1, el);
    else
      std::fprintf(stderr,
                   "board_sim: frame %zu matches no golden frame: closest %d, %llu pixels differ, "
                   "first at x %d y %d (%.0f s)\n",
                   frames.size() - 1, fi.best, static_cast<unsigned long long>(fi.diff),
                   fi.first_x, fi.first_y, el);
    std::fill(cur.begin(), cur.end(), 0);
  };

  auto done = [&]() {
    if (static_cast<int>(frames.size()) >= max_frames) return true;
    return first_live >= 0 && static_cast<int>(frames.size()) - first_live >= want;
  };

  while (!done()) {
    if (!step()) continue;
    // Host: the next packet once the previous one is answered.
    if (waiting) {
      if (uart.rx.size() > rx_used) {
        const uint8_t r = uart.rx[rx_used++];
        if (r != 'K')
          errors.push_back("packet " + std::to_string(pkt - 1) + " (" + hexs(pkts[pkt - 1]) +
                           ") answered '" + std::string(1, static_cast<char>(r)) + "', want 'K'");
        waiting = false;
        if (pkt == pkts.size()) host_done_at = pix_cycles;
      } else if (pix_cycles - sent_at > reply_timeout) {
        errors.push_back("packet " + std::to_string(pkt - 1) + ": no reply");
        waiting = false;
        if (pkt == pkts.size()) host_done_at = pix_cycles;
      }
    } else if (pkt < pkts.size() && pix_cycles > 64) {
      for (uint8_t b : pkts[pkt]) uart.txq.push_back(b);
      ++pkt;
      waiting = true;
      sent_at = pix_cycles;
    }
    // Status LEDs: when each first lights (bit 6: a span array's late / overflow flag,
    // pix_collision; bit 5 align_err), as frame being decoded and its line.
    const uint32_t leds = top->led_o;
    for (int b = 0; b < 8; ++b)
      if (led_first[b].update(leds >> b & 1, pix_cycles, frames.size(), row))
        std::fprintf(stderr, "board_sim: LED %d lit at pixel clock %llu (frame %zu, line %d)\n", b,
                     static_cast<unsigned long long>(pix_cycles), frames.size(), row);
    for (auto& sf : span) {
      if (sf.ovf_at.update(*sf.ovf, pix_cycles, frames.size(), row))
        std::fprintf(stderr, "board_sim: %s: FIFO overflow (slots lost) at pixel clock %llu "
                     "(frame %zu, line %d)\n", sf.scope.c_str(),
                     static_cast<unsigned long long>(pix_cycles), frames.size(), row);
      if (sf.late_at.update(*sf.late, pix_cycles, frames.size(), row))
        std::fprintf(stderr, "board_sim: %s: late line at pixel clock %llu (frame %zu, line %d)\n",
                     sf.scope.c_str(), static_cast<unsigned long long>(pix_cycles), frames.size(),
                     row);
    }
    // Video: decode the three symbols registered at this edge.
    const uint32_t tm = top->tmds_o;
    Sym s[kCh];
    for (int c = 0; c < kCh; ++c) s[c] = tmds_decode((tm >> (10 * c)) & 0x3FF);
    if (s[0].ctrl != s[1].ctrl || s[0].ctrl != s[2].ctrl) {
      ++disagree;
      continue;
    }
    if (!s[0].ctrl) {  // DE: channel 2 red, 1 green, 0 blue
      if (!in_de) {
        in_de = true;
        col = 0;
      }
      if (frame_open && row < g.va && col < g.ha) {
        uint8_t* px = &cur[(static_cast<size_t>(row) * g.ha + col) * kCh];
        px[0] = static_cast<uint8_t>(s[2].v);
        px[1] = static_cast<uint8_t>(s[1].v);
        px[2] = static_cast<uint8_t>(s[0].v);
      }
      ++col;
      continue;
    }
    if (s[1].v != 0 || s[2].v != 0) ++ctrl_bad;  // C1/C0 only on blue
    if (in_de) {  // a DE run ends
      in_de = false;
      if (col != g.ha) ++de_runs_bad;
      if (frame_open) ++row;
      ++lines_in_frame;
    }
    const bool hs = (s[0].v & 1) == sync_on_h, vs = ((s[0].v >> 1) & 1) == sync_on_v;
    if (hs && !prev_hs) {
      if (hs_count && pix_cycles - hs_rise != static_cast<uint64_t>(HT)) ++hs_period_bad;
      hs_rise = pix_cycles;
      ++hs_count;
    }
    if (!hs && prev_hs && pix_cycles - hs_rise != static_cast<uint64_t>(g.hs)) ++hs_width_bad;
    if (vs && !prev_vs) {  // a frame ends (its active lines came before the pulse)
      ++vs_count;
      if (frame_open) {
        if (row != g.va) ++frame_lines_bad;
        finish_frame();
      }
      frame_open = true;  // the next active lines are a whole frame
      row = 0;
      lines_in_frame = 0;
    }
    prev_hs = hs;
    prev_vs = vs;
    if ((pix_cycles & 0x3FFF) == 0 && (progress || tty)) {
      auto now = std::chrono::steady_clock::now();
      if (std::chrono::duration<double>(now - t_prog).count() > (tty ? 1.0 : 10.0)) {
        t_prog = now;
        const double el = std::chrono::duration<double>(now - t0).count();
        std::fprintf(stderr,
                     "%sboard_sim: frame %zu line %d, %llu pixel clocks (%.2f frames) in %.0f s, "
                     "%.0f pixel clocks/s%s",
                     tty && !progress ? "\r" : "", frames.size(), row,
                     static_cast<unsigned long long>(pix_cycles),
                     static_cast<double>(pix_cycles) / frame_clocks, el, pix_cycles / el,
                     tty && !progress ? "   " : "\n");
      }
    }
  }
  if (tty && !progress) std::fprintf(stderr, "\n");
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double cpu = static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC;

  // ---------------------------------------------------------------- registers over the UART
  auto command = [&](std::vector<uint8_t> p, size_t n) -> std::vector<uint8_t> {
    const size_t start = uart.rx.size();
    for (uint8_t b : p) uart.txq.push_back(b);
    const uint64_t t_end = pix_cycles + reply_timeout + 2000;
    while (uart.rx.size() < start + n && pix_cycles < t_end) step();
    std::vector<uint8_t> r(uart.rx.begin() + static_cast<long>(start), uart.rx.end());
    if (r.size() < n) errors.push_back("command '" + std::string(1, static_cast<char>(p[0])) +
                                       "': " + std::to_string(r.size()) + " of " +
                                       std::to_string(n) + " reply bytes");
    return r;
  };
  auto reg = [&](uint32_t a) -> int64_t {
    auto r = command(with_chk({'R', static_cast<uint8_t>(a >> 8), static_cast<uint8_t>(a)}), 5);
    if (r.size() < 5 || r[0] != 'R') {
      errors.push_back("register " + std::to_string(a) + ": bad reply");
      return -1;
    }
    return static_cast<int64_t>(static_cast<uint32_t>(r[1]) << 24 | r[2] << 16 | r[3] << 8 | r[4]);
  };
  int64_t late[kCh], drop[kCh], lmframes[kCh];
  for (int c = 0; c < kCh; ++c) {
    const uint32_t base = static_cast<uint32_t>(c) << DE_REG_CHAN_LSB;
    late[c] = reg(base | DE_LM_REG_TOTAL_LATE);
    drop[c] = reg(base | DE_LM_REG_TOTAL_DROP);
    lmframes[c] = reg(base | DE_LM_REG_FRAMES);
  }
  const int64_t ctl_id = reg(DE_REG_INFO_CHAN << DE_REG_CHAN_LSB | DE_CTRL_REG_ID);
  const std::vector<uint8_t> st = command(with_chk({'S'}), 16);
  const uint32_t sd_err = top->err_count_o, sd_ref = top->ref_count_o;
  top->final();

  // ---------------------------------------------------------------- checks
  int64_t late_total = 0, drop_total = 0;
  for (int c = 0; c < kCh; ++c) {
    late_total += late[c];
    drop_total += drop[c];
  }
  if (first_live < 0) errors.push_back("no frame other than black in " +
                                       std::to_string(frames.size()) + " frames");
  int mismatched = 0;
  for (size_t k = 0; k < frames.size(); ++k)
    if (frames[k].kind == -2) ++mismatched;
  if (mismatched) errors.push_back(std::to_string(mismatched) + " frame(s) equal no golden frame");
  if (first_live >= 0)
    for (size_t k = first_live; k < frames.size(); ++k)
      if (frames[k].kind == -1) errors.push_back("black frame " + std::to_string(k) +
                                                 " after the sequence started");
  if (late_total) errors.push_back(std::to_string(late_total) + " late line(s)");
  // The span arrays' flags are warnings: a slot lost to a full FIFO may be a Nop of the
  // bus padding (harmless) or a command (then the pixel comparison fails), and a late
  // line need not be wrong (the drain outruns the read-out); the flags are sticky, so
  // only the first event of each is seen.
  std::vector<std::string> warnings;
  for (const auto& sf : span) {
    if (sf.ovf_at.clock >= 0)
      warnings.push_back(sf.scope + ": span array FIFO overflow (slots lost) from frame " +
                         std::to_string(sf.ovf_at.frame) + " line " + std::to_string(sf.ovf_at.line));
    // A late flag is an error wherever it rises: since de_span_video arms its check only
    // when the array's reset sweep is done, nothing may raise it, not even after reset.
    if (sf.late_at.clock >= 0)
      errors.push_back(sf.scope + ": span array late line at pixel clock " +
                       std::to_string(sf.late_at.clock) + ", frame " +
                       std::to_string(sf.late_at.frame) + " line " +
                       std::to_string(sf.late_at.line));
  }
  if (drop_total) errors.push_back(std::to_string(drop_total) + " dropped word(s)");
  if (sd_err) errors.push_back(std::to_string(sd_err) + " SDRAM timing violation(s)");
  if (de_runs_bad) errors.push_back(std::to_string(de_runs_bad) + " DE run(s) not HActive long");
  if (frame_lines_bad) errors.push_back(std::to_string(frame_lines_bad) +
                                        " frame(s) without VActive lines");
  if (hs_period_bad || hs_width_bad)
    errors.push_back("hsync: " + std::to_string(hs_period_bad) + " bad period(s), " +
                     std::to_string(hs_width_bad) + " bad width(s)");
  if (ctrl_bad) errors.push_back(std::to_string(ctrl_bad) + " control token(s) with C != 0 on red/green");
  if (disagree) errors.push_back(std::to_string(disagree) + " clock(s) where the channels disagree on DE");
  if (uart.rx_ferr) errors.push_back(std::to_string(uart.rx_ferr) + " reply framing error(s)");
  // 'S' (loader version 2): [1] version, [4..9] framing / checksum / command error
  // counts, [12] bit 0 align_err, bits 1-3 pixel collisions, [14] malformed lines the
  // fetchers fixed, [15] clocks a player starved.
  if (st.size() == 16) {
    if (st[1] != 2) errors.push_back("status: loader version " + std::to_string(st[1]) + ", want 2");
    for (int k = 4; k < 10; k += 2)
      if (st[k] || st[k + 1])
        errors.push_back("status: error counter at byte " + std::to_string(k) + " is " +
                         std::to_string(st[k] << 8 | st[k + 1]));
    // Bits 1-3 (pix_collision: a span array's late or overflow flag, sticky) are judged
    // above from the flags themselves: with 648 columns the arrays' reset sweep makes the
    // first line after reset (in vertical blanking) late, so the bits are always set.
    if (st[12] & 0x01) errors.push_back("status: align_err");
    if (st[14]) errors.push_back("status: " + std::to_string(st[14]) + " malformed line(s)");
    if (st[15]) errors.push_back("status: a player starved " + std::to_string(st[15]) + " clock(s)");
  }

  // ---------------------------------------------------------------- outputs
  if (out_path) {
    FILE* f = std::fopen(out_path, "wb");
    if (!f) {
      std::fprintf(stderr, "%s: cannot write\n", out_path);
      return 2;
    }
    std::fwrite(saved.data(), 1, saved.size(), f);
    std::fclose(f);
  }
  std::string j = "{\n";
  char tmp[1024];
  std::snprintf(tmp, sizeof tmp,
                "  \"mode\": %d, \"width\": %d, \"height\": %d, \"h_total\": %d, \"v_total\": %d,\n"
                "  \"golden_frames\": %d, \"frames_wanted\": %d,\n"
                "  \"pixel_clocks\": %llu, \"core_clocks\": %llu, \"sdram_clocks\": %llu,\n"
                "  \"simulated_ms\": %.3f, \"seconds\": %.1f, \"cpu_seconds\": %.1f,\n"
                "  \"pixel_clocks_per_second\": %.0f, \"host_done_pixel_clock\": %llu,\n",
                mode, g.ha, g.va, HT, VT, ngold, want,
                static_cast<unsigned long long>(pix_cycles),
                static_cast<unsigned long long>(core_cycles),
                static_cast<unsigned long long>(sd_cycles),
                static_cast<double>(t) * kUnitPs * 1e-9, secs, cpu, pix_cycles / secs,
                static_cast<unsigned long long>(host_done_at));
  j += tmp;
  j += "  \"frames\": [";
  for (size_t k = 0; k < frames.size(); ++k) {
    const FrameInfo& fi = frames[k];
    std::snprintf(tmp, sizeof tmp,
                  "%s\n    {\"index\": %zu, \"kind\": \"%s\", \"golden\": %d, \"closest\": %d, "
                  "\"pixels_differing\": %llu, \"first_diff\": [%d, %d], \"end_pixel_clock\": %llu}",
                  k ? "," : "", k, fi.kind >= 0 ? "golden" : fi.kind == -1 ? "black" : "mismatch",
                  fi.kind, fi.best, static_cast<unsigned long long>(fi.diff), fi.first_x,
                  fi.first_y, static_cast<unsigned long long>(fi.cycle));
    j += tmp;
  }
  std::snprintf(tmp, sizeof tmp, "\n  ],\n  \"first_live_frame\": %d,\n", first_live);
  j += tmp;
  j += "  \"load_monitor\": {";
  const char* names[kCh] = {"R", "G", "B"};
  for (int c = 0; c < kCh; ++c) {
    std::snprintf(tmp, sizeof tmp,
                  "%s\"%s\": {\"total_late_lines\": %lld, \"total_dropped\": %lld, \"frames\": %lld}",
                  c ? ", " : "", names[c], static_cast<long long>(late[c]),
                  static_cast<long long>(drop[c]), static_cast<long long>(lmframes[c]));
    j += tmp;
  }
  std::snprintf(tmp, sizeof tmp,
                "},\n  \"late_lines\": %lld, \"dropped_words\": %lld, \"controller_id\": %lld,\n"
                "  \"status\": \"%s\",\n  \"sdram\": {\"violations\": %u, \"refreshes\": %u},\n"
                "  \"sync\": {\"hsync_pulses\": %llu, \"vsync_pulses\": %llu, \"bad_de_runs\": %llu, "
                "\"bad_frames\": %llu, \"hsync_bad_period\": %llu, \"hsync_bad_width\": %llu, "
                "\"ctrl_bad\": %llu, \"de_disagree\": %llu},\n",
                static_cast<long long>(late_total), static_cast<long long>(drop_total),
                static_cast<long long>(ctl_id), hexs(st).c_str(), sd_err, sd_ref,
                static_cast<unsigned long long>(hs_count), static_cast<unsigned long long>(vs_count),
                static_cast<unsigned long long>(de_runs_bad),
                static_cast<unsigned long long>(frame_lines_bad),
                static_cast<unsigned long long>(hs_period_bad),
                static_cast<unsigned long long>(hs_width_bad),
                static_cast<unsigned long long>(ctrl_bad), static_cast<unsigned long long>(disagree));
  j += tmp;
  j += "  \"span_arrays\": [";  // [pixel clock, frame, line] of each flag's first rise
  for (size_t k = 0; k < span.size(); ++k)
    j += std::string(k ? "," : "") + "\n    {\"scope\": \"" + span[k].scope +
         "\", \"overflow_first\": " + span[k].ovf_at.json() + ", \"late_first\": " +
         span[k].late_at.json() + "}";
  j += "],\n  \"led_first_lit\": {";
  bool firstl = true;
  for (int b = 0; b < 8; ++b)
    if (led_first[b].clock >= 0) {
      j += std::string(firstl ? "" : ", ") + "\"" + std::to_string(b) + "\": " + led_first[b].json();
      firstl = false;
    }
  j += "},\n";
  j += "  \"warnings\": [";
  for (size_t i = 0; i < warnings.size(); ++i) j += (i ? ", \"" : "\"") + warnings[i] + "\"";
  j += "],\n";
  j += "  \"errors\": [";
  for (size_t i = 0; i < errors.size(); ++i) j += (i ? ", \"" : "\"") + errors[i] + "\"";
  j += "],\n  \"ok\": " + std::string(errors.empty() ? "true" : "false") + "\n}\n";
  if (stats_path) {
    FILE* f = std::fopen(stats_path, "w");
    if (!f) {
      std::fprintf(stderr, "%s: cannot write\n", stats_path);
      return 2;
    }
    std::fputs(j.c_str(), f);
    std::fclose(f);
  }
  for (auto& w : warnings) std::fprintf(stderr, "board_sim: warning: %s\n", w.c_str());
  for (auto& e : errors) std::fprintf(stderr, "board_sim: error: %s\n", e.c_str());
  std::printf("board_sim: %zu frame(s), %llu pixel clocks (%.1f ms simulated) in %.0f s "
              "(%.0f CPU s), late lines %lld, dropped words %lld, SDRAM violations %u: %s\n",
              frames.size(), static_cast<unsigned long long>(pix_cycles),
              static_cast<double>(t) * kUnitPs * 1e-9, secs, cpu,
              static_cast<long long>(late_total), static_cast<long long>(drop_total), sd_err,
              errors.empty() ? "PASS" : "FAIL");
  return errors.empty() ? 0 : 1;
}
