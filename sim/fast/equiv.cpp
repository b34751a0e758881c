// Equivalence check of the fast array (sim/fast) against the whole de_array Verilated flat
// (rtl/array/de_array.sv): the same random inputs into both, every output compared every
// cycle. Inputs cover what the composition could get wrong: reset in mid-stream, the
// bypass configuration chain (cfg_mode/cfg_bit), the observation chain (obs_load/shift),
// pixel collisions, and instruction streams rich in Refresh, ACC and address slots.
//
//   equiv --cycles N --seed S      exit 0 when equal, 1 at the first difference
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <random>
#include <string>

#include "Vflat.h"
#include "de_fast.h"
#include "de_isa.h"
#include "de_verilated.h"
#include "verilated.h"

int main(int argc, char** argv) {
  long long cycles = 200000;
  uint64_t seed = 1;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--cycles") && i + 1 < argc) cycles = std::atoll(argv[++i]);
    else if (!std::strcmp(argv[i], "--seed") && i + 1 < argc) seed = std::strtoull(argv[++i], nullptr, 0);
    else if (!std::strcmp(argv[i], "--help") || !std::strcmp(argv[i], "-h")) {
      std::printf("usage: %s [--cycles N] [--seed S]\n"
                  "Random inputs into the flat de_array and the fast array (sim/fast);\n"
                  "exit 1 at the first cycle where an output differs.\n", argv[0]);
      return 0;
    } else {
      std::fprintf(stderr, "%s: unknown argument '%s' (try --help)\n", argv[0], argv[i]);
      return 2;
    }
  }
  auto ctx = std::make_unique<VerilatedContext>();
  ctx->commandArgs(argc, argv);
  auto flat = std::make_unique<Vflat>(ctx.get(), "flat");
  de_fast::Array fast(DE_EQUIV_CHIPS,
                      de_fast::Array::compiled_num_pe(), de_fast::Array::compiled_carry_bug());
  std::printf("equiv: %d chips, carry bug %d, %lld cycles, seed %llu (replay: --seed %llu)\n",
              DE_EQUIV_CHIPS, de_fast::Array::compiled_carry_bug(), cycles,
              static_cast<unsigned long long>(seed), static_cast<unsigned long long>(seed));
  std::mt19937_64 rng(seed);
  auto pct = [&](int p) { return static_cast<int>(rng() % 100) < p; };
  // Phases change the mix every few thousand cycles so that each regime lasts long
  // enough to matter (a long stream without Refresh lets D saturate, etc.).
  int refresh_pct = 2, cfg_pct = 0, obs_pct = 0;
  long long stats_cfg = 0, stats_obs = 0, stats_pix = 0, stats_rst = 0;
  bool cfg_mode = false;
  for (long long c = 0; c < cycles; ++c) {
    if (c % 4096 == 0) {
      refresh_pct = static_cast<int>(rng() % 6);
      cfg_pct = (rng() % 4 == 0) ? 30 : 0;
      obs_pct = (rng() % 3 == 0) ? 20 : 0;
    }
    de_fast::In in;
    in.rst = c < 3 || (c % 50000 == 25000 && pct(50));
    if (pct(90)) {
      // The identifiers of the instruction look-up table, plus raw random ones below.
      in.ident = static_cast<uint16_t>(pct(refresh_pct) ? DE_ID_REFRESH
                                                        : de_lut_ident(rng() % DE_LUT_ENTRIES));
    } else {
      in.ident = static_cast<uint16_t>(rng() & DE_ID_MASK);
    }
    const int kind = static_cast<int>(rng() % 4);
    in.data = kind == 0 ? (rng() & 0xfffffffffULL)
                        : kind == 1 ? (rng() % 64)
                                    : kind == 2 ? ((rng() % 40) | ((rng() % 40) << 12)) : 0;
    if (cfg_pct && pct(cfg_pct)) cfg_mode = !cfg_mode;
    in.cfg_mode = cfg_mode;
    in.cfg_bit = pct(15);  // mostly PEs in use, some bypassed
    in.obs_load = obs_pct && pct(obs_pct / 4);
    in.obs_shift = obs_pct && pct(obs_pct);
    stats_cfg += in.cfg_mode;
    stats_obs += in.obs_load;
    stats_rst += in.rst;

    Vflat& f = *flat;
    de_sim::drive(f, in);
    de_sim::tick(f);
    const de_fast::Out o = fast.step(in);
    stats_pix += o.pixel_valid;
    const bool same = o.ident == f.id_o && o.data == f.data_o &&
                      o.pixel_valid == static_cast<bool>(f.pix_valid_o) &&
                      o.pixel == f.pix_o && o.collision == static_cast<bool>(f.pix_collision_o) &&
                      o.cfg_bit == static_cast<bool>(f.cfg_bit_o) &&
                      o.obs_bit == static_cast<bool>(f.obs_bit_o);
    if (!same) {
      std::printf(
          "equiv: DIFFERENT at cycle %lld (seed %llu)\n"
          "  flat: ident %03x data %09llx pixv %d pixel %03x coll %d cfg_bit %d obs_bit %d\n"
          "  fast: ident %03x data %09llx pixv %d pixel %03x coll %d cfg_bit %d obs_bit %d\n",
          c, static_cast<unsigned long long>(seed), f.id_o,
          static_cast<unsigned long long>(f.data_o), f.pix_valid_o, f.pix_o,
          f.pix_collision_o, f.cfg_bit_o, f.obs_bit_o, o.ident,
          static_cast<unsigned long long>(o.data), o.pixel_valid, o.pixel, o.collision,
          o.cfg_bit, o.obs_bit);
      return 1;
    }
  }
  flat->final();
  std::printf("equiv: EQUAL for %lld cycles (%lld pixels, %lld cfg_mode cycles, %lld obs loads, "
              "%lld reset cycles)\n", cycles, stats_pix, stats_cfg, stats_obs, stats_rst);
  return 0;
}
