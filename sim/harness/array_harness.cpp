// Plain C++ Verilator harness for the bare x-processor array (no Python in the clock
// loop). Plays a 48-bit instruction stream (.de48, docs/formats.md) through de_array,
// one instruction per clock, collects the pixels that leave the last PE and writes a
// raw frame (.depx: "DEPX", u32 width, u32 height, then u16 little-endian pixels),
// which `diffengine` converts to PNG. Prints simulated cycles per second.
//
//   array_harness IN.de48 OUT.depx [--width N] [--repeat K] [--quiet] [--trace-pixels]
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "Vde_array.h"
#include "verilated.h"

namespace {

struct Instr {
  uint16_t ident;
  uint64_t data;
};

bool read_de48(const char* path, std::vector<Instr>& out, std::string& err) {
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
  unsigned char w[6];
  size_t n;
  while ((n = std::fread(w, 1, 6, f)) == 6) {
    uint64_t v = 0;
    for (int i = 0; i < 6; ++i) v = (v << 8) | w[i];
    out.push_back({static_cast<uint16_t>(v >> 36), v & ((1ULL << 36) - 1)});
  }
  std::fclose(f);
  if (n != 0) {
    err = std::string(path) + ": truncated instruction at byte " +
          std::to_string(8 + 6 * out.size());
    return false;
  }
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: %s IN.de48 OUT.depx [--width N] [--repeat K] [--quiet]\n",
                 argv[0]);
    return 2;
  }
  int width = 0, repeat = 1;
  bool quiet = false, trace_pixels = false, collided = false;
  for (int i = 3; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--width") && i + 1 < argc) width = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--repeat") && i + 1 < argc) repeat = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--quiet")) quiet = true;
    else if (!std::strcmp(argv[i], "--trace-pixels")) trace_pixels = true;
    else {
      std::fprintf(stderr, "%s: unknown option %s\n", argv[0], argv[i]);
      return 2;
    }
  }
  std::vector<Instr> prog;
  std::string err;
  if (!read_de48(argv[1], prog, err)) {
    std::fprintf(stderr, "%s\n", err.c_str());
    return 1;
  }
  auto ctx = std::make_unique<VerilatedContext>();
  ctx->commandArgs(1, argv);
  auto top = std::make_unique<Vde_array>(ctx.get());
  top->eval();
  const int n_pe = top->n_pe_o;  // the array reports its own column count
  if (n_pe <= 0) {
    std::fprintf(stderr, "%s: the array reports %d PEs\n", argv[0], n_pe);
    return 1;
  }
  if (width <= 0 || width > n_pe) width = n_pe;

  auto tick = [&]() {
    top->clk_i = 0;
    top->eval();
    top->clk_i = 1;
    top->eval();
  };
  top->rst_i = 1;
  top->ident_i = 0;
  top->data_i = 0;
  top->cfg_mode_i = 0;
  top->cfg_bit_i = 0;
  top->obs_load_i = 0;
  top->obs_shift_i = 0;
  for (int i = 0; i < 4; ++i) tick();
  top->rst_i = 0;

  std::vector<uint16_t> pixels;
  uint64_t cycles = 0;
  auto t0 = std::chrono::steady_clock::now();
  const size_t drain = static_cast<size_t>(n_pe) * 2 + 64;
  // One Refresh active at a time (7.4.1): pixels of two Refreshes fewer than n_pe
  // cycles apart would meet on the pixel bus, so pad with Nops, as the access
  // controller's fixed line period does in the real system.
  uint64_t nops_added = 0;
  for (int r = 0; r < repeat; ++r) {
    uint64_t since_refresh = static_cast<uint64_t>(n_pe);
    size_t i = 0;
    for (size_t left = drain; i < prog.size() || left > 0;) {
      Instr in{0, 0};
      if (i < prog.size()) {
        in = prog[i];
        if (in.ident == 0x100 && since_refresh < static_cast<uint64_t>(n_pe)) {
          in = Instr{0, 0};
          ++nops_added;
        } else {
          ++i;
        }
      } else {
        --left;
      }
      since_refresh = (in.ident == 0x100) ? 1 : since_refresh + 1;
      top->ident_i = in.ident;
      top->data_i = in.data;
      tick();
      ++cycles;
      if (top->pixel_valid_o && r == 0) pixels.push_back(top->pixel_o);
      if (trace_pixels && top->pixel_valid_o)
        std::printf("cycle %llu pixel %zu = %u\n", static_cast<unsigned long long>(cycles),
                    pixels.size() - 1, top->pixel_o);
      if (trace_pixels && in.ident == 0x100)
        std::printf("cycle %llu Refresh in\n", static_cast<unsigned long long>(cycles));
      if (top->pix_collision_o && !collided) {
        collided = true;
        std::fprintf(stderr, "%s: pixel collision at cycle %llu\n", argv[1],
                     static_cast<unsigned long long>(cycles));
      }
    }
  }
  if (top->pix_collision_o) {
    std::fprintf(stderr, "%s: pixel collision in the array (Refreshes too close)\n", argv[1]);
    return 1;
  }
  double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const uint32_t height = static_cast<uint32_t>(pixels.size() / n_pe);
  if (pixels.size() % n_pe) {
    std::fprintf(stderr, "%s: %zu pixels is not a whole number of %d-column lines\n",
                 argv[1], pixels.size(), n_pe);
    return 1;
  }
  FILE* f = std::fopen(argv[2], "wb");
  if (!f) {
    std::fprintf(stderr, "%s: cannot write\n", argv[2]);
    return 1;
  }
  const uint32_t w32 = static_cast<uint32_t>(width);
  std::fwrite("DEPX", 1, 4, f);
  std::fwrite(&w32, 4, 1, f);
  std::fwrite(&height, 4, 1, f);
  for (uint32_t y = 0; y < height; ++y)
    std::fwrite(&pixels[static_cast<size_t>(y) * n_pe], 2, width, f);
  std::fclose(f);
  if (!quiet)
    std::printf("harness: %d PEs, %zu instructions x %d (+%llu Nops for Refresh spacing), "
                "%llu cycles in %.3f s = %.0f cycles/s, %u lines\n", n_pe, prog.size(), repeat,
                static_cast<unsigned long long>(nops_added / (repeat ? repeat : 1)),
                static_cast<unsigned long long>(cycles), secs, cycles / secs, height);
  top->final();
  return 0;
}
