// Fast simulation of de_array (docs/simulation.md, "The fast array").
//
// The array is cut at the chips' boundary registers into pieces that are each Verilated
// from the RTL (sim/fast/de_fast_*.sv): a head (de_skew + chip 0's core), NumChips-1
// identical units (chip c-1's boundary register + chip c's core) and a tail (the last
// boundary register, de_deskew, the sticky collision flag). One unit model is compiled
// once and instantiated NumChips-1 times, so its code stays in the caches; a unit's bus
// and pixel inputs reach logic only through its registers, so the pieces can be clocked
// one after the other (tail first, head last) and each still sees its neighbour's values
// from before the edge.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

class VerilatedContext;
class Vde_fast_head;
class Vde_fast_unit;
class Vde_fast_tail;

namespace de_fast {

struct In {
  bool rst = false;
  uint16_t ident = 0;
  uint64_t data = 0;
  bool cfg_mode = false, cfg_bit = false, obs_load = false, obs_shift = false;
};

struct Out {
  uint16_t ident = 0;
  uint64_t data = 0;
  bool pixel_valid = false;
  uint16_t pixel = 0;
  bool collision = false, cfg_bit = false, obs_bit = false;
};

class Array {
 public:
  // Throws std::runtime_error when num_pe or carry_bug differ from the compiled pieces.
  Array(int num_chips, int num_pe, int carry_bug);
  ~Array();
  Array(const Array&) = delete;
  Array& operator=(const Array&) = delete;

  // One rising clock edge with `in` held during the ending cycle; returns de_array's
  // outputs (all registers) after the edge.
  Out step(const In& in);

  int num_chips() const { return num_chips_; }
  // Re-evaluates every piece as on its first call (after registers were written from
  // outside, sim/harness fast-forward): the wiring follows the registers again.
  void settle();
  // The pieces' own context (its scope table names head, chip<c>, tail).
  VerilatedContext* context() const { return ctx_.get(); }
  static int compiled_num_pe();
  static int compiled_carry_bug();

 private:
  int num_chips_;
  std::unique_ptr<VerilatedContext> ctx_;
  std::unique_ptr<Vde_fast_head> head_;
  std::vector<std::unique_ptr<Vde_fast_unit>> units_;  // units_[c-1] = chip c
  std::unique_ptr<Vde_fast_tail> tail_;
};

}  // namespace de_fast
