// Plain C++ Verilator harness for the full-colour display_controller (docs/pipeline.md,
// "display_controller harness"; no Python in the clock loop).
//
// Reads three .de48 streams (R, G, B; docs/formats.md §2). Each stream is a sequence of
// scanlines, each ended by an instruction with identifier 0x100 (Refresh), which is
// exactly the end-of-line marker of docs/display-controller.md §2.2. Line n of the
// stream is written, with its marker, into y-processor write port (n mod NumBuf) of that
// colour; every other port writes only a marker for line n, so the k-th marker of every
// buffer ends the k-th active line counted from reset (§2.2) and the commands of a line
// keep their order. After reset the controller starts at the first vertical-blank line
// (§2.1), so the first granted window is line 0 of frame 0: the harness starts writing
// line 0 right after reset. A stream of L lines fills ceil(L / VActive) frames (missing
// lines are empty: a marker only).
//
// The writer is an ideal y-processor: valid whenever it has a word, advanced on
// valid && ready. Pixels are captured from rgb_o while blank_o is low; hsync/vsync/blank
// are checked against the mode (pulse widths, periods, line and pixel counts); the
// sticky align_err_o / pix_collision_o must stay low. After the last frame the Load
// Monitor and controller registers are read over reg_addr_i and written as JSON.
//
//   Vdisplay_controller R.de48 G.de48 B.de48 -o OUT.dcf [--mode 0..3] [--stats S.json]
//                       [--progress] [--quiet]
//
// OUT.dcf ("display controller frames"), little-endian:
//   offset 0  "DCF1"   4 bytes
//   offset 4  u32 width, u32 height, u32 frames, u32 channels (3), u32 bits (12)
//   offset 24 frames x height x width x 3 u16: R, G, B of each pixel, row-major
// Exit status: 0 ok, 1 a check failed (frame still written), 2 usage / input error.
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "Vdisplay_controller.h"
#include "de_isa.h"
#include "de_verilated.h"
#include "verilated.h"
#include <ctime>
#include <unistd.h>

#ifndef DC_TEST_GEOM
#define DC_TEST_GEOM 16, 2, 3, 3, 6, 1, 2, 2
#endif

namespace {

constexpr int kCh = 3;
constexpr uint16_t kRefresh = DE_ID_REFRESH;
constexpr unsigned kIdMagicLsb = 24;  // ID registers: the magic in ID[31:24] (docs/display-controller.md §6)

struct Geom {
  int ha, hfp, hs, hbp, va, vfp, vs, vbp;
  bool hpos, vpos;  // positive sync pulses
  int htotal() const { return ha + hfp + hs + hbp; }
  int vtotal() const { return va + vfp + vs + vbp; }
};

// docs/display-controller.md §3; the fixed modes come from de_isa.h (spec/video.toml).
Geom mode_geom(int mode) {
  if (mode == DE_VIDEO_MODE_TEST) {
    const int t[8] = {DC_TEST_GEOM};  // the TestMode parameter of this build
    return {t[0], t[1], t[2], t[3], t[4], t[5], t[6], t[7], false, false};
  }
  const de_video_mode* m = de_video_mode_get(mode);
  if (!m) m = de_video_mode_get(0);
  return {m->h[0], m->h[1], m->h[2], m->h[3], m->v[0], m->v[1], m->v[2], m->v[3],
          m->hpol != 0, m->vpol != 0};
}

bool read_de48(const char* path, std::vector<uint64_t>& out, std::string& err) {
  FILE* f = std::fopen(path, "rb");
  if (!f) {
    err = std::string(path) + ": cannot open";
    return false;
  }
  unsigned char hdr[8];
  if (std::fread(hdr, 1, 8, f) != 8 || std::memcmp(hdr, "DE48", 4) != 0) {
    err = std::string(path) + ": not a DE48 instruction stream (bad header)";
    std::fclose(f);
    return false;
  }
  std::vector<unsigned char> buf;
  unsigned char chunk[1 << 16];
  size_t n;
  while ((n = std::fread(chunk, 1, sizeof chunk, f)) > 0) buf.insert(buf.end(), chunk, chunk + n);
  std::fclose(f);
  if (buf.size() % 6) {
    err = std::string(path) + ": truncated instruction at byte " +
          std::to_string(8 + buf.size() / 6 * 6);
    return false;
  }
  out.reserve(buf.size() / 6);
  for (size_t i = 0; i < buf.size(); i += 6) {
    uint64_t v = 0;
    for (int k = 0; k < 6; ++k) v = (v << 8) | buf[i + k];
    out.push_back(v);
  }
  return true;
}

// Line boundaries of a stream: lines[n] = [begin, end) including its Refresh.
std::vector<std::pair<size_t, size_t>> split_lines(const std::vector<uint64_t>& w, size_t& tail) {
  std::vector<std::pair<size_t, size_t>> lines;
  size_t start = 0;
  for (size_t i = 0; i < w.size(); ++i)
    if ((w[i] >> DE_WORD_BITS) == kRefresh) {
      lines.emplace_back(start, i + 1);
      start = i + 1;
    }
  tail = w.size() - start;  // words after the last Refresh: an unterminated line
  return lines;
}

void set_word(EData* wide, int lsb, uint64_t v) {  // 48-bit field at bit lsb
  for (int k = 0; k < 48; ++k) {
    int bit = lsb + k;
    EData m = EData(1) << (bit & 31);
    if ((v >> k) & 1) wide[bit >> 5] |= m;
    else wide[bit >> 5] &= ~m;
  }
}

struct PulseCheck {  // widths and periods of a pulse train (active = level `on`)
  const char* name;
  int on;
  uint64_t count = 0, bad_width = 0, bad_period = 0, last_rise = 0, width = 0;
  bool in = false, seen = false;
  int first_width = -1;
  int64_t first_period = -1;
  void step(int level, uint64_t cyc, uint64_t want_w, uint64_t want_p) {
    bool act = level == on;
    if (act && !in) {
      if (seen) {
        uint64_t p = cyc - last_rise;
        if (first_period < 0) first_period = static_cast<int64_t>(p);
        if (p != want_p) ++bad_period;
      }
      seen = true;
      last_rise = cyc;
      width = 0;
      ++count;
    }
    if (act) ++width;
    if (!act && in) {
      if (first_width < 0) first_width = static_cast<int>(width);
      if (width != want_w) ++bad_width;
    }
    in = act;
  }
};

}  // namespace

int main(int argc, char** argv) {
  const char* in[kCh] = {nullptr, nullptr, nullptr};
  const char* out_path = nullptr;
  const char* stats_path = nullptr;
  int mode = 0;
  bool progress = false, quiet = false;
  int npos = 0;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "-o") && i + 1 < argc) out_path = argv[++i];
    else if (!std::strcmp(argv[i], "--stats") && i + 1 < argc) stats_path = argv[++i];
    else if (!std::strcmp(argv[i], "--mode") && i + 1 < argc) mode = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--progress")) progress = true;
    else if (!std::strcmp(argv[i], "--quiet")) quiet = true;
    else if (argv[i][0] == '-' && argv[i][1]) {
      std::fprintf(stderr, "%s: unknown option %s\n", argv[0], argv[i]);
      return 2;
    } else if (npos < kCh) in[npos++] = argv[i];
    else {
      std::fprintf(stderr, "%s: too many inputs\n", argv[0]);
      return 2;
    }
  }
  if (npos != kCh || !out_path || mode < 0 || mode > 3) {
    std::fprintf(stderr,
                 "usage: %s R.de48 G.de48 B.de48 -o OUT.dcf [--mode 0..3] [--stats S.json] "
                 "[--progress] [--quiet]\n", argv[0]);
    return 2;
  }
  const Geom g = mode_geom(mode);
  const int HT = g.htotal(), VT = g.vtotal();

  std::vector<uint64_t> words[kCh];
  std::vector<std::pair<size_t, size_t>> lines[kCh];
  size_t max_lines = 0;
  for (int c = 0; c < kCh; ++c) {
    std::string err;
    if (!read_de48(in[c], words[c], err)) {
      std::fprintf(stderr, "%s\n", err.c_str());
      return 2;
    }
    size_t tail = 0;
    lines[c] = split_lines(words[c], tail);
    if (tail)
      std::fprintf(stderr, "%s: warning: %zu word(s) after the last Refresh ignored\n", in[c], tail);
    for (auto& ln : lines[c])
      if (ln.second - ln.first - 1 > static_cast<size_t>(HT - 1))
        std::fprintf(stderr, "%s: warning: line %zu has %zu slots, the window has %d: it will be late\n",
                     in[c], static_cast<size_t>(&ln - &lines[c][0]), ln.second - ln.first - 1, HT - 1);
    if (lines[c].size() > max_lines) max_lines = lines[c].size();
  }
  const int frames = std::max<int>(1, static_cast<int>((max_lines + g.va - 1) / g.va));
  const size_t total_lines = static_cast<size_t>(frames) * g.va;

  auto ctx = std::make_unique<VerilatedContext>();
  ctx->commandArgs(1, argv);
  auto top = std::make_unique<Vdisplay_controller>(ctx.get());
  auto tick = [&]() { de_sim::tick(*top); };
  top->rst_i = 1;
  top->mode_i = mode;
  top->wr_valid_i = 0;
  top->reg_addr_i = (DE_REG_INFO_CHAN << DE_REG_CHAN_LSB) | DE_CTRL_REG_ID;
  top->out8_shift_i = 4;
  top->out8_sat_i = 0;
  de_sim::chains_idle(*top);
  for (int i = 0; i < 4; ++i) tick();
  top->rst_i = 0;
  tick();  // the controller's registers read one clock after the address (blank lines)
  tick();
  const uint32_t ctl_id = top->reg_rdata_o;
  if ((ctl_id >> kIdMagicLsb) != DE_CTRL_ID_MAGIC) {
    std::fprintf(stderr, "%s: controller ID register reads 0x%08x (want 0x%02X......)\n", argv[0], ctl_id,
                 DE_CTRL_ID_MAGIC);
    return 2;
  }
  const int num_buf = (ctl_id >> 16) & 0xF;
  const int latency = ctl_id & 0xFFFF;
  const int chips = latency - 3;
  if (chips * 9 < g.ha)
    std::fprintf(stderr, "%s: warning: %d chips = %d PEs < %d active columns (align_err expected)\n",
                 argv[0], chips, chips * 9, g.ha);

  // Per (colour, buffer): the word queue (built lazily from the line table).
  struct Port {
    size_t line = 0, pos = 0;  // next line, next word within it (the marker is last)
    uint64_t written = 0;
  };
  std::vector<Port> port(kCh * num_buf);
  auto line_len = [&](int c, int b, size_t n) -> size_t {  // words incl. marker
    if (n % num_buf != static_cast<size_t>(b) || n >= lines[c].size()) return 1;
    return lines[c][n].second - lines[c][n].first;
  };
  auto line_word = [&](int c, int b, size_t n, size_t k) -> uint64_t {
    size_t len = line_len(c, b, n);
    if (k + 1 == len) return static_cast<uint64_t>(kRefresh) << DE_WORD_BITS | (n % g.va);  // marker
    return words[c][lines[c][n].first + k];
  };
  const int wide_words = (kCh * num_buf * 48 + 31) / 32;
  EData* wr_data = &top->wr_data_i[0];
  std::memset(wr_data, 0, sizeof(EData) * wide_words);

  std::vector<uint16_t> pix(static_cast<size_t>(frames) * g.va * g.ha * kCh, 0);
  const uint64_t expect_cycles = static_cast<uint64_t>(frames) * VT * HT + latency + 8;
  const uint64_t max_cycles = expect_cycles + 2ull * VT * HT;
  PulseCheck hs{"hsync", g.hpos ? 1 : 0}, vs{"vsync", g.vpos ? 1 : 0};
  uint64_t cycles = 0, bad_line_len = 0, bad_line_period = 0, line_start_prev = 0;
  int frame = 0, row = 0, col = 0;
  bool prev_blank = true, any_line = false, collided = false;
  std::vector<std::string> errors;
  auto t0 = std::chrono::steady_clock::now();
  const std::clock_t c0 = std::clock();  // process CPU time: the rate on a busy machine
  auto t_prog = t0;
  const bool tty = isatty(2);

  while (frame < frames && cycles < max_cycles) {
    uint32_t valid = 0;
    for (int c = 0; c < kCh; ++c)
      for (int b = 0; b < num_buf; ++b) {
        Port& p = port[c * num_buf + b];
        if (p.line < total_lines) {
          valid |= 1u << (c * num_buf + b);
          set_word(wr_data, (c * num_buf + b) * DE_RECORD_BITS, line_word(c, b, p.line, p.pos));
        }
      }
    top->wr_valid_i = valid;
    top->clk_i = 0;
    top->eval();
    const uint32_t ready = static_cast<uint32_t>(top->wr_ready_o);
    top->clk_i = 1;
    top->eval();
    ++cycles;
    for (int c = 0; c < kCh; ++c)
      for (int b = 0; b < num_buf; ++b) {
        const int i = c * num_buf + b;
        if ((valid >> i) & (ready >> i) & 1) {
          Port& p = port[i];
          ++p.written;
          if (++p.pos == line_len(c, b, p.line)) {
            p.pos = 0;
            ++p.line;
          }
        }
      }
    // Video side (registered outputs after this edge).
    const bool blank = top->blank_o;
    hs.step(top->hsync_o, cycles, g.hs, HT);
    vs.step(top->vsync_o, cycles, static_cast<uint64_t>(g.vs) * HT, static_cast<uint64_t>(VT) * HT);
    if (!blank) {
      if (prev_blank) {  // a line starts
        if (any_line && cycles - line_start_prev != static_cast<uint64_t>(HT) &&
            row != 0)
          ++bad_line_period;
        line_start_prev = cycles;
        any_line = true;
        col = 0;
      }
      if (col < g.ha) {
        const uint64_t rgb = top->rgb_o;
        uint16_t* px = &pix[((static_cast<size_t>(frame) * g.va + row) * g.ha + col) * kCh];
        for (int c = 0; c < kCh; ++c) px[c] = (rgb >> (12 * c)) & 0xFFF;
      }
      ++col;
    } else if (!prev_blank) {  // a line ends
      if (col != g.ha) ++bad_line_len;
      if (++row == g.va) {
        row = 0;
        ++frame;
      }
    }
    prev_blank = blank;
    if (top->pix_collision_o && !collided) {
      collided = true;
      errors.push_back("pix_collision_o set at cycle " + std::to_string(cycles));
    }
    if ((cycles & 0xFFF) == 0 && (progress || tty)) {
      auto now = std::chrono::steady_clock::now();
      if (std::chrono::duration<double>(now - t_prog).count() > 0.5) {
        t_prog = now;
        double el = std::chrono::duration<double>(now - t0).count();
        if (progress)
          std::fprintf(stderr, "progress %llu %llu\n", static_cast<unsigned long long>(cycles),
                       static_cast<unsigned long long>(expect_cycles));
        else
          std::fprintf(stderr, "\rdc_harness: frame %d/%d line %d/%d  %.0f cycles/s   ", frame + 1,
                       frames, row, g.va, cycles / el);
      }
    }
  }
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double cpu_secs = static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC;
  if (tty && !progress) std::fprintf(stderr, "\n");
  if (frame < frames) errors.push_back("only " + std::to_string(frame) + " of " +
                                       std::to_string(frames) + " frames came out");
  if (bad_line_len) errors.push_back(std::to_string(bad_line_len) + " active line(s) not " +
                                     std::to_string(g.ha) + " pixels long");
  if (bad_line_period) errors.push_back(std::to_string(bad_line_period) +
                                        " line start(s) not HTotal apart");
  if (hs.bad_width || hs.bad_period)
    errors.push_back("hsync: " + std::to_string(hs.bad_width) + " bad widths, " +
                     std::to_string(hs.bad_period) + " bad periods");
  if (vs.bad_width || vs.bad_period)
    errors.push_back("vsync: " + std::to_string(vs.bad_width) + " bad widths, " +
                     std::to_string(vs.bad_period) + " bad periods");
  // From reset (v = VActive) to the end of the last frame's active part: VT - VActive +
  // frames * VT - (VT - VActive) lines; one hsync per line, one vsync per frame.
  const uint64_t want_hs = static_cast<uint64_t>(frames) * VT;
  if (hs.count + 1 < want_hs || hs.count > want_hs + 1)
    errors.push_back("hsync: " + std::to_string(hs.count) + " pulses, want about " +
                     std::to_string(want_hs));
  if (vs.count != static_cast<uint64_t>(frames))
    errors.push_back("vsync: " + std::to_string(vs.count) + " pulses, want " + std::to_string(frames));
  if (top->align_err_o) errors.push_back("align_err_o set");
  if (top->pix_collision_o) errors.push_back("pix_collision_o set at the end");

  // Let the snapshot settle, then read the registers (data one clock after the address).
  top->wr_valid_i = 0;
  for (int i = 0; i < 4; ++i) tick();
  auto rd = [&](uint32_t addr) -> uint32_t {
    top->reg_addr_i = addr;
    tick();
    return top->reg_rdata_o;
  };
  FILE* js = stats_path ? std::fopen(stats_path, "w") : nullptr;
  if (stats_path && !js) {
    std::fprintf(stderr, "%s: cannot write\n", stats_path);
    return 2;
  }
  std::string j;
  char tmp[512];
  std::snprintf(tmp, sizeof tmp,
                "{\n  \"mode\": %d,\n  \"width\": %d,\n  \"height\": %d,\n  \"h_total\": %d,\n"
                "  \"v_total\": %d,\n  \"chips\": %d,\n  \"num_buf\": %d,\n  \"array_latency\": %d,\n"
                "  \"frames\": %d,\n  \"cycles\": %llu,\n  \"seconds\": %.6f,\n"
                "  \"cycles_per_second\": %.1f,\n  \"cpu_seconds\": %.6f,\n"
                "  \"cycles_per_cpu_second\": %.1f,\n  \"context_threads\": %u,\n",
                mode, g.ha, g.va, HT, VT, chips, num_buf, latency, frames,
                static_cast<unsigned long long>(cycles), secs, cycles / secs, cpu_secs,
                cycles / cpu_secs, ctx->threads());
  j += tmp;
  std::snprintf(tmp, sizeof tmp,
                "  \"sync\": {\"hsync_pulses\": %llu, \"hsync_width\": %d, \"hsync_period\": %lld, "
                "\"vsync_pulses\": %llu, \"vsync_width\": %d, \"vsync_period\": %lld},\n"
                "  \"align_err\": %d,\n  \"pix_collision\": [%d, %d, %d],\n  \"words_written\": [",
                static_cast<unsigned long long>(hs.count), hs.first_width,
                static_cast<long long>(hs.first_period), static_cast<unsigned long long>(vs.count),
                vs.first_width, static_cast<long long>(vs.first_period), int(top->align_err_o),
                int(top->pix_collision_o & 1), int((top->pix_collision_o >> 1) & 1),
                int((top->pix_collision_o >> 2) & 1));
  j += tmp;
  for (int c = 0; c < kCh; ++c) {
    uint64_t s = 0;
    for (int b = 0; b < num_buf; ++b) s += port[c * num_buf + b].written;
    j += std::to_string(s) + (c + 1 < kCh ? ", " : "],\n");
  }
  // The register map is spec/regs.toml's (de_isa.h).
  const uint32_t info = DE_REG_INFO_CHAN << DE_REG_CHAN_LSB;
  j += "  \"controller\": {\"id\": " + std::to_string(rd(info | DE_CTRL_REG_ID)) +
       ", \"align_err\": " + std::to_string(rd(info | DE_CTRL_REG_ALIGN_ERR) & 1) +
       "},\n  \"load_monitor\": {\n";
  const char* names[kCh] = {"R", "G", "B"};
  uint64_t late_total = 0, dropped_total = 0;
  for (int c = 0; c < kCh; ++c) {
    const uint32_t base = static_cast<uint32_t>(c) << DE_REG_CHAN_LSB;
    const uint32_t id = rd(base + DE_LM_REG_ID);
    if ((id >> kIdMagicLsb) != DE_LM_ID_MAGIC) errors.push_back(std::string("load monitor ") + names[c] +
                                             ": bad ID register");
    const int bins = (id >> 16) & 0xFF, shift = (id >> 12) & 0xF;
    const uint32_t fc = rd(base + DE_LM_REG_FRAMES), iss = rd(base + DE_LM_REG_ISSUED),
                   fre = rd(base + DE_LM_REG_FREE), late = rd(base + DE_LM_REG_LATE),
                   drop = rd(base + DE_LM_REG_DROP), mx = rd(base + DE_LM_REG_MAX_ISSUED),
                   last = rd(base + DE_LM_REG_LAST_LINE), tdrop = rd(base + DE_LM_REG_TOTAL_DROP),
                   tlate = rd(base + DE_LM_REG_TOTAL_LATE);
    late_total += tlate;
    dropped_total += tdrop;
    std::snprintf(tmp, sizeof tmp,
                  "    \"%s\": {\"frame_count\": %u, \"issued\": %u, \"free\": %u, \"late_lines\": %u, "
                  "\"dropped\": %u, \"max_issued\": %u, \"last_line\": %u, \"total_dropped\": %u, "
                  "\"total_late_lines\": %u, \"bin_width\": %d, \"hist\": [",
                  names[c], fc, iss, fre, late, drop, mx, last, tdrop, tlate, 1 << shift);
    j += tmp;
    for (int b = 0; b < bins; ++b) j += std::to_string(rd(base + DE_LM_HIST_BASE + b)) + (b + 1 < bins ? ", " : "");
    j += "],\n      \"line_issued\": [";
    const int nl = std::min(g.va, 1024);
    std::vector<uint32_t> rec(nl);
    for (int l = 0; l < nl; ++l) rec[l] = rd(base + DE_LM_LINE_BASE + l);
    for (int l = 0; l < nl; ++l) j += std::to_string(rec[l] & 0xFFF) + (l + 1 < nl ? ", " : "");
    j += "],\n      \"late_line_numbers\": [";
    bool first = true;
    for (int l = 0; l < nl; ++l)
      if (rec[l] >> 31) {
        j += (first ? "" : ", ") + std::to_string(l);
        first = false;
      }
    j += std::string("]}") + (c + 1 < kCh ? ",\n" : "\n  },\n");
  }
  j += "  \"errors\": [";
  for (size_t i = 0; i < errors.size(); ++i) {
    j += "\"" + errors[i] + "\"" + (i + 1 < errors.size() ? ", " : "");
  }
  j += "],\n  \"ok\": " + std::string(errors.empty() ? "true" : "false") + "\n}\n";
  if (js) {
    std::fputs(j.c_str(), js);
    std::fclose(js);
  }

  FILE* f = std::fopen(out_path, "wb");
  if (!f) {
    std::fprintf(stderr, "%s: cannot write\n", out_path);
    return 2;
  }
  const uint32_t hdr[5] = {static_cast<uint32_t>(g.ha), static_cast<uint32_t>(g.va),
                           static_cast<uint32_t>(frames), kCh, 12};
  std::fwrite("DCF1", 1, 4, f);
  std::fwrite(hdr, 4, 5, f);  // little-endian hosts only (x86, ARM)
  std::fwrite(pix.data(), 2, pix.size(), f);
  std::fclose(f);
  for (auto& e : errors) std::fprintf(stderr, "dc_harness: error: %s\n", e.c_str());
  if (late_total)
    std::fprintf(stderr, "dc_harness: warning: %llu late line(s), %llu word(s) discarded (overload)\n",
                 static_cast<unsigned long long>(late_total),
                 static_cast<unsigned long long>(dropped_total));
  if (!quiet)
    std::printf("dc_harness: %d chips x 3, %d y-proc, mode %d (%dx%d), %d frame(s), %llu cycles in "
                "%.3f s = %.0f cycles/s (%.0f per CPU second, all threads)\n", chips, num_buf, mode,
                g.ha, g.va, frames, static_cast<unsigned long long>(cycles), secs, cycles / secs,
                cycles / cpu_secs);
  top->final();
  return errors.empty() ? 0 : 1;
}
