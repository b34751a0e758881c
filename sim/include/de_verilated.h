// de_verilated.h - what every C++ harness of a Verilated Difference Engine top shares
// (sim/harness, sim/dc, sim/fast): one clock cycle, and the inputs of the de_array ports
// (reset, bus, configuration and observation chains). Templates, because each harness has
// its own Verilated class (Vde_array, Vdisplay_controller, Vflat, the fast pieces).
#pragma once

namespace de_sim {

// One clock cycle: the falling edge, then the rising edge the registers take.
template <class Top>
inline void tick(Top& t) {
  t.clk_i = 0;
  t.eval();
  t.clk_i = 1;
  t.eval();
}

// The configuration and observation chains idle: no PE bypassed, nothing observed.
template <class Top>
inline void chains_idle(Top& t) {
  t.cfg_mode_i = 0;
  t.cfg_bit_i = 0;
  t.obs_load_i = 0;
  t.obs_shift_i = 0;
}

// The de_array inputs of one cycle from a record with rst, ident, data, cfg_mode,
// cfg_bit, obs_load and obs_shift (de_fast::In).
template <class Top, class In>
inline void drive(Top& t, const In& in) {
  t.rst_i = in.rst;
  t.id_i = in.ident;
  t.data_i = in.data;
  t.cfg_mode_i = in.cfg_mode;
  t.cfg_bit_i = in.cfg_bit;
  t.obs_load_i = in.obs_load;
  t.obs_shift_i = in.obs_shift;
}

}  // namespace de_sim
