// Difference Engine: one x-processor (PE) of the linear systolic array.
//
// Micro-architecture: docs/xproc.md. Instruction set: docs/isa.md (normative).
// Cycle-level reference: sw/diffengine/model/structural.py (same register names; the
// testbench tb/de_pe compares every register of every PE every cycle).
//
// Skew: a slot's identifier and data block 0 arrive together in cycle t ("stage 0");
// its block j arrives in cycle t+j ("stage j"). data_i therefore carries block 0 of
// the slot named by id_i, block 1 of the slot before it, block 2 of the slot before
// that. The 36-bit add is three 12-bit adds, one per stage, with registered block
// carries: no carry ripples through more than 12 bits in one cycle.

`default_nettype none

module de_pe
  import de_pkg::*;
#(
  // 1 = reproduce the prototype's carry fault (isa.md section 7, spec/isa.toml [adder]):
  // the carry out of block 1 enters block 2 at bit 1 (adds 2) instead of bit 0.
  parameter int unsigned CarryBug = 0,
  // 1 = the smallest form of the timing-only logic (blk1z_o tested behind the out mux, one
  // decrement per pass value): the same cycle behaviour in fewer cells, for a part that
  // is full (the iCE40 chip, docs/fpga.md section 6.3); 0 = the fast form.
  parameter int unsigned Compact = 0,
  // Timing only: how many copies of the reset (and of the bypass bit) the PE takes, 1..4.
  // Register group g (RstBus, RstAb, RstCd, RstCtl below) reads copy g % RstW, so that no
  // copy drives more than about 90 flip-flops (docs/xproc.md section 8).
  parameter int unsigned RstW = 1,
  // Timing only: 1 = the stage-0 operand selects read idsel_i, a second copy of the
  // previous PE's identifier register, so that they do not wait on id_i's fan-out to the
  // whole decode (docs/fpga-timing-log.md section 4, fourth pass); 0 = they read id_i.
  parameter int unsigned IdCopy = 0,
  // Timing only: 1 = pixv_c_o is a register of its own (a copy of the pixel-valid register
  // for the chip's collision flag and valid chain); 0 = pixv_c_o is pix_valid_o.
  parameter int unsigned PixCopy = 0,
  // 1 = the PE registers its own input (id_i, data_i) before stage 0 and computes beside
  // that register, a cycle early, what stage 0 would otherwise compute behind it: block
  // 1's zero test, X - 1 and stage 0's SRC and DST operands (docs/xproc.md section 11).
  // The PE then costs two clocks on the bus instead of one; its registers hold the same
  // values for the same slots, one clock later. blk1z_i and idsel_i are not read and
  // blk1z_o is constant (the next PE tests its own input). 0 when Compact.
  parameter int unsigned InReg = 0
) (
  input  logic             clk_i,
  // Synchronous, active high. RstW copies of ONE reset, equal in every cycle (registered
  // copies of the same signal: a reset tree), so the cycle in which reset acts is the
  // same whichever copy a register reads.
  input  logic [RstW-1:0]  rst_i,
  // Static (a chip's configuration): the PE is replaced by a register. id_o/data_o carry
  // id_i/data_i one clock later and every other register is held in reset. RstW equal
  // copies, as rst_i (the bus group does not read its copy).
  /* verilator lint_off UNUSEDSIGNAL */
  input  logic [RstW-1:0]  bypass_i = '0,
  /* verilator lint_on UNUSEDSIGNAL */
  // = !bypass_i, from a register of its own (timing only): the pass-through terms then do
  // not wait on bypass_i's fan-out, the reset of every other register.
  input  logic             live_i = 1'b1,
  input  logic [IdW-1:0]   id_i,         // identifier of the slot at stage 0
  input  logic [DataW-1:0] data_i,       // skewed: [j*12 +: 12] = block j of stage j's slot
  // Timing only: data_i's block 1 is zero, registered by the sender beside its data_o
  // (the previous PE's blk1z_o, or a register in front of PE 0). Not architectural.
  input  logic             blk1z_i,
  // Timing only: = id_i in every cycle (the previous PE's idsel_o), read when IdCopy = 1.
  /* verilator lint_off UNUSEDSIGNAL */
  input  logic [IdW-1:0]   idsel_i = '0,
  /* verilator lint_on UNUSEDSIGNAL */
  output logic [IdW-1:0]   id_o,         // registered, to the next PE
  output logic [DataW-1:0] data_o,       // registered, to the next PE (same skew)
  output logic             blk1z_o,      // registered: data_o's block 1 is zero
  output logic [IdW-1:0]   idsel_o,      // = id_o (a register of its own when IdCopy = 1)
  output logic             pix_valid_o,  // registered: a Refresh's pixel this cycle
  output logic             pixv_c_o,     // = pix_valid_o (a register of its own: PixCopy)
  output logic [PixW-1:0]  pix_o,        // registered: D[35:24], zero when not valid
  output logic [DbgW-1:0]  dbg_o         // all state, for the testbench (unused in a chip)
);

  // ---- elaboration checks ------------------------------------------------------------
  if (CarryBug > 1) begin : g_bad_carry_bug
    $fatal(1, "de_pe: CarryBug must be 0 or 1, got %0d", CarryBug);
  end
  if (Compact > 1) begin : g_bad_compact
    $fatal(1, "de_pe: Compact must be 0 or 1, got %0d", Compact);
  end
  if (!id_layout_ok()) begin : g_bad_id_layout
    $fatal(1, "de_pkg: id_t does not match the Id*Bit positions");
  end
  if (RstW < 1 || RstW > 4) begin : g_bad_rst_w
    $fatal(1, "de_pe: RstW must be 1..4, got %0d", RstW);
  end
  if (InReg > 1 || (InReg == 1 && Compact == 1)) begin : g_bad_in_reg
    $fatal(1, "de_pe: InReg must be 0 or 1 (0 when Compact), got %0d", InReg);
  end
  if (AddCarryBlk == 1) begin : g_bad_carry_blk
    // blk1z_d's zero test of a block-1 sum takes the carry into bit 0 (zero_terms).
    $fatal(1, "de_pe: the carry fault must not enter block 1 (AddCarryBlk = 1)");
  end

  // a + b + cin == 0 (mod 2^BlkW) is the AND of these bits, without the carry chain: sum
  // bit i is 0 exactly when the carry into bit i equals a[i] ^ b[i], and the carry out of
  // bit i is then a[i] | b[i]; so every bit is a function of four inputs (one LUT4), side
  // by side with the adder instead of behind it.
  function automatic logic [BlkW-1:0] zero_terms(input logic [BlkW-1:0] a,
                                                 input logic [BlkW-1:0] b, input logic cin);
    zero_terms[0] = ((a[0] ^ b[0]) == cin);
    for (int i = 1; i < BlkW; i++) begin
      zero_terms[i] = ((a[i] ^ b[i]) == (a[i-1] | b[i-1]));
    end
  endfunction

  // ---- registers (every one is a _d/_q pair) -------------------------------------------
  // Architectural: A, B, C, D as three 12-bit blocks, the flags.
  logic [NumBlk-1:0][BlkW-1:0] a_d, a_q, b_d, b_q, c_d, c_q, d_d, d_q;
  logic pa_d, pa_q, pb_d, pb_q, pc_d, pc_q;  // protect flags (set by a Set)
  logic dis_d, dis_q;                        // Dis pending for the next active Eval
  logic lock_d, lock_q;                      // Eval0 wrote D: no D write until Refresh
  logic accm_d, accm_q;                      // Acc_mode: drop negative intensities
  logic act_d, act_q;                        // this PE is selected by the current command
  // Registered outputs to the next PE; id_q doubles as the stage-1 identifier.
  logic [IdW-1:0] id_d, id_q;
  logic [NumBlk-1:0][BlkW-1:0] out_d, out_q;
  // Control pipeline: decisions taken for block 0 (stage 0/1), used for blocks 1 and 2.
  logic [IdW-1:0] id2_d, id2_q;              // stage-2 identifier
  logic xz1_d, xz1_q;                        // range address: X was 0
  logic act1_d, act1_q, prot1_d, prot1_q;    // stage-1 slot: active / use DST (protected)
  logic c1_d, c1_q;                          // data adder: carry block 0 -> block 1
  logic act2_d, act2_q, prot2_d, prot2_q;    // stage-2 slot: active / protected
  logic c2_d, c2_q;                          // data adder: carry block 1 -> block 2
  logic e0wr2_d, e0wr2_q;                    // Eval0 writes D in stage 2
  logic accen2_d, accen2_q, accc2_d, accc2_q;  // ACC: write D block 1 / its carry in
  logic accen3_d, accen3_q, accc3_d, accc3_q;  // ACC: write D block 2 / its carry in
  logic pixv_d, pixv_q;
  logic [PixW-1:0] pix_d, pix_q;
  // Timing only (not architectural state, so not in dbg_o): act_eff for the next cycle
  // when its stage-1 block 1 is zero / non-zero, decided one cycle early (docs/xproc.md 3).
  logic aez_d, aez_q, aenz_d, aenz_q;
  // Timing only, likewise: the stage-1 slot is a Dis / an Eval0 whose X was 0.
  logic disx_d, disx_q, e0x_d, e0x_q;
  // Timing only, likewise: the SRC and DST operands of the slots in stages 1 and 2,
  // selected a cycle early from the next values of the register blocks they will read.
  logic [BlkW-1:0] src1_d, src1_q, dst1_d, dst1_q, src2_d, src2_q, dst2_d, dst2_q;
  // Timing only, likewise: the register write of the slot in stage 1 / 2 (wr1, wr2), one
  // bit per destination ([0] A, [1] B, [2] C), decoded when the slot was a stage earlier.
  logic [2:0] wr1_d, wr1_q, wr2_d, wr2_q;
  // Timing only, likewise: out_q's block 1 is zero (the next PE's zero test of block 1).
  logic blk1z_d, blk1z_q;
  // Timing only, likewise: the stage-1 slot is a periodic address (per1, from id_q).
  logic per1_d, per1_q;

  // ---- inputs and decode -------------------------------------------------------------
  logic [NumBlk-1:0][BlkW-1:0] in_blk;
  id_t id0;
  // Later stages decode only the fields they act on (protection is decided at stage 0,
  // addressing needs blocks 0-1 only), so some identifier bits are unused there.
  /* verilator lint_off UNUSEDSIGNAL */
  id_t id1, id2;
  /* verilator lint_on UNUSEDSIGNAL */
  // InReg: the input register (in_id_q, in_data_q) and, beside it, what stage 0 needs,
  // computed from the unregistered input a cycle early (registers g_in_regs, below).
  logic [IdW-1:0]   in_id_q;
  /* verilator lint_off UNUSEDSIGNAL */
  logic [DataW-1:0] in_data_q;       // (InReg = 0: unused)
  /* verilator lint_on UNUSEDSIGNAL */
  logic             in_z1_q;         // block 1 of in_data_q is zero (blk1z_i's job)
  logic [BlkW:0]    in_dm0_q;        // {carry, X - 1} of block 0 of in_data_q
  logic [BlkW-1:0]  src0_q, dst0_q;  // stage 0's SRC and DST blocks
  if (InReg == 1) begin : g_in_reg
    assign in_blk = in_data_q;
    assign id0    = id_t'(in_id_q);
  end else begin : g_in_wire
    assign in_blk = data_i;
    assign id0    = id_t'(id_i);
  end
  assign id1 = id_t'(id_q);
  assign id2 = id_t'(id2_q);

  // Register reads (reg_blk, reg_flag) and the block carries (blk_carry_in, with the
  // prototype's fault when CarryBug is 1) are de_pkg functions, shared with de_span_array.
  localparam bit Bug = (CarryBug == 1);

  // ---- stage 1 address decision (needed first: it sets act for stage 0) --------------
  // An address slot fires when, periodic, its countdown (block 1) is 0, or, range, X was
  // 0 (xz1_q) and dX (block 1) is not: fire1 = id1.addr && (per1 ? z1 : xz1_q && !z1).
  logic z1, per1, act_eff;
  // The zero test of block 1 is made by the sender, from its own candidates for the
  // block, and arrives on a flip-flop beside the block (blk1z_i; blk1z_d below). A
  // Compact PE tests the block itself and leaves the flag unused (fewer cells).
  assign z1        = (Compact == 1) ? (in_blk[1] == '0) : (InReg == 1) ? in_z1_q : blk1z_i;
  // = id1.addr && (id1.sub == SubPeriodic), registered beside id_q (per1_q; not Compact).
  assign per1      = (Compact == 1) ? (id1.addr && (id1.sub == SubPeriodic)) : per1_q;
  // The slot at stage 0 one cycle behind an address slot belongs to its command, so it
  // sees that slot's decision at once; later slots of the command see the act register:
  // act_eff = id1.addr ? fire1 : act_q. Everything in it but the zero test of block 1 is
  // known a cycle earlier, so both outcomes are registered then (aez_q, aenz_q) and only
  // the zero test and one mux stand in front of stage 0 (the PE's critical path).
  assign act_eff   = z1 ? aez_q : aenz_q;

  // ---- stage 0: identifier + block 0 ---------------------------------------------------
  logic ev0, st0, rng0, xz0, pv0, prot0, wr0;
  /* verilator lint_off UNUSEDSIGNAL */
  logic active0;  // (InReg = 1: sum0 is formed from its two halves)
  /* verilator lint_on UNUSEDSIGNAL */
  logic [BlkW-1:0] src0, out0;
  logic [BlkW:0] sp0, sn0, s0;
  assign ev0     = id0.data && !id0.set;
  assign st0     = id0.data && id0.set;
  assign rng0    = id0.addr && (id0.sub != SubPeriodic);
  // X - 1 as a constant decrement with its carry out: the carry is 1 unless X is 0, so the
  // zero test of X comes out of the same carry chain, not from two LUT levels of its own.
  // InReg: computed a cycle early (in_dm0_q).
  (* keep *) logic [BlkW:0] dm0;
  assign dm0     = (InReg == 1) ? in_dm0_q : {1'b0, in_blk[0]} + {1'b0, {BlkW{1'b1}}};
  assign xz0     = !dm0[BlkW];
  // Protection is decided once per slot, here, and travels with it down the pipeline;
  // pv0 is the part that does not depend on act_eff.
  assign pv0     = ev0 && id0.prot && reg_flag(id0.dst, pa_q, pb_q, pc_q);
  assign prot0   = act_eff && pv0;
  assign active0 = ev0 && act_eff;
  // The operand selects read their own copy of the identifier (IdCopy; equal to id0).
  /* verilator lint_off UNUSEDSIGNAL */
  id_t id0s;
  /* verilator lint_on UNUSEDSIGNAL */
  assign id0s    = (IdCopy == 1) ? id_t'(idsel_i) : id0;
  // InReg: both operands come from registers (src0_q, dst0_q), so the adders start at
  // flip-flops rather than behind the identifier's decode.
  logic [BlkW-1:0] dst0;
  assign src0    = (InReg == 1) ? src0_q : reg_blk(id0s.src, a_q[0], b_q[0], c_q[0]);
  assign dst0    = (InReg == 1) ? dst0_q : reg_blk(id0s.dst, a_q[0], b_q[0], c_q[0]);
  // v0 + SRC0 with v0 = prot0 ? DST0 : in0: both sums are formed while act_eff is still
  // being decided and pv0 picks one after the adders (carry select on the operand).
  assign sp0     = {1'b0, dst0} + {1'b0, src0};
  assign sn0     = {1'b0, in_blk[0]} + {1'b0, src0};
  assign s0      = pv0 ? sp0 : sn0;
  // A protected slot writes DST with DST's own value: no write. So a write is in0 only.
  assign wr0     = (ev0 || st0) && act_eff && !pv0 && (id0.dst != RegNone);

  // In bypass, every block passes unchanged (live = 0); the rest of the PE is in reset,
  // but not yet in the first cycle of the bypass, hence the explicit term.
  logic live;
  assign live = live_i;

  // out0 = sum0 ? s0 : pass0. The select and the pass value are kept as nets of their
  // own, so that the last LUT in front of out_q[0] has the five inputs sum0, pv0, sp0,
  // sn0, pass0 (one PFUMX) rather than a 7-input function of the decisions.
  // Relative addressing counts X down to 0 and keeps it there: pass0 picks X, X - 1 or 0
  // after the decrement (a LUT4 of rng0l, the carry, the two bits).
  (* keep *) logic rng0l;
  (* keep *) logic [BlkW-1:0] pass0;
  logic sum0;
  if (InReg == 1) begin : g_sum0_split
    // sum0 for both outcomes of the zero test (kept nets), so that z1 picks one inside
    // the out0 logic itself: one routed hop from the zero test to out_q[0].
    (* keep *) logic sum0z, sum0nz;
    assign sum0z  = ev0 && aez_q && live;
    assign sum0nz = ev0 && aenz_q && live;
    assign sum0   = z1 ? sum0z : sum0nz;
  end else begin : g_sum0
    (* keep *) logic sum0_k;
    assign sum0_k = active0 && live;
    assign sum0   = sum0_k;
  end
  assign rng0l = rng0 && live;
  assign pass0 = rng0l ? (xz0 ? '0 : dm0[BlkW-1:0]) : in_blk[0];
  assign out0 = sum0 ? s0[BlkW-1:0] : pass0;

  // ---- stage 1: block 1 ------------------------------------------------------------------
  logic ev1, active1, dis1, e0_1, e0en1;
  logic [2:0] wr1;
  logic [BlkW-1:0] src1, out1;
  logic [BlkW:0] sp1, sn1, s1;
  assign ev1     = id1.data && !id1.set;
  assign active1 = ev1 && act1_q;
  // = reg_blk(id1.src, a_q[1], b_q[1], c_q[1]), registered (src1_q): no mux before the
  // adder. All ones when the slot does not add (sum1 = 0), for blk1z_d's test of in - 1.
  assign src1    = src1_q;
  // As in stage 0: both operand sums, prot1_q picks one after the adders.
  assign sp1     = {1'b0, dst1_q} + {1'b0, src1} + blk_carry_in(c1_q, 1, Bug);
  assign sn1     = {1'b0, in_blk[1]} + {1'b0, src1} + blk_carry_in(c1_q, 1, Bug);
  assign s1      = prot1_q ? sp1 : sn1;
  // = (ev1 || st1) && act1_q && !prot1_q && (id1.dst != RegNone), i.e. wr0 a cycle ago,
  // split by id1.dst then (wr1_q): no decode of the identifier in front of the register
  // blocks' next values, which src1_d/dst1_d select from (the critical path before).
  // wr1 is assigned with wr1_d below (g_wr_fast / g_wr_small).
  // Dis and Eval0 are range addresses: fire = X was 0 and dX is not; the slot's kind and
  // X == 0 were registered in its stage 0 (disx_q, e0x_q), the zero test of dX is now.
  assign dis1    = disx_q && !z1;
  assign e0_1    = e0x_q && !z1;
  assign e0en1   = e0_1 && !lock_q && !dis_q;

  // out1 = sum1 ? s1 : pass1, select and pass value kept as nets, as in stage 0.
  // An address slot decrements block 1 (the countdown, or dX when X was 0) unless it is
  // 0; then a periodic slot reloads P-1 from out_q block 0, which still holds the period
  // this slot passed on unchanged one cycle ago (no extra register), and any other slot
  // passes the 0. dec1 = live && (per1 || (id1.addr && xz1_q)); xz1_q implies id1.addr.
  (* keep *) logic sum1;
  (* keep *) logic [BlkW-1:0] pass1;
  logic dec1;
  assign sum1  = active1 && live;
  assign dec1  = live && (per1 || xz1_q);
  assign out1  = sum1 ? s1[BlkW-1:0] : pass1;

  if (Compact == 1) begin : g_pass1_small
    // One carry chain (in - dec1) and blk1z_d tested on out1 behind its mux.
    assign pass1   = z1 ? ((per1 && live) ? out_q[0] - BlkW'(1) : '0)
                        : in_blk[1] - BlkW'(dec1);
    assign blk1z_d = (out1 == '0);
  end else begin : g_pass1_fast
    // The decrement is a constant one (dm1) picked after the carry chain, so the chain
    // starts at the input block and not behind the decision: pass1 = z1 ? q1 : (dec1 ? dm1
    // : in) is one LUT5 of dm1, P - 1, in and two selects from flops (q1 is 0 unless
    // periodic, and then block 1 is 0 as well when z1).
    (* keep *) logic seld1, selq1;
    (* keep *) logic [BlkW-1:0] dm1;
    assign seld1 = dec1 && !z1;
    assign selq1 = z1 && per1 && live;
    assign dm1   = in_blk[1] - BlkW'(1);
    assign pass1 = seld1 ? dm1 : (selq1 ? out_q[0] - BlkW'(1) : in_blk[1]);
  end

  if (Compact == 0 && InReg == 1) begin : g_z1_own
    // The next PE registers its own zero test of block 1 from its input (in_z1_q).
    assign blk1z_d = 1'b1;
  end else if (Compact == 0) begin : g_z1_next
    // out1 == 0 for the next PE (blk1z_d), from the candidates rather than behind the out1
    // mux, so that the input block is three LUT levels from blk1z_q: the sums by
    // zero_terms (no carry chain) in kept groups of four bits; q1 = P - 1 = 0 when P = 1;
    // d1 = in - 1 = 0 only when in is 1, which is the same test of in + src1 with src1 all
    // ones (src1_q is, when the slot does not add; c1_q is 0 then). Only address slots
    // read the flag (they never add, but an identifier with both class bits would), so
    // each level is kept: left to itself, synthesis takes bit 0 from the adder's CCU2C
    // and merges the levels into wider, deeper functions.
    (* keep *) logic [BlkW-1:0] tn1, tp1;
    (* keep *) logic [2:0] zn_g, zp_g;
    (* keep *) logic zrest, seln1;
    logic zq1;
    assign tn1     = zero_terms(in_blk[1], src1, c1_q);
    assign tp1     = zero_terms(dst1_q, src1, c1_q);
    for (genvar g = 0; g < 3; g++) begin : g_zero_grp
      assign zn_g[g] = &tn1[g*BlkW/3 +: BlkW/3];
      assign zp_g[g] = &tp1[g*BlkW/3 +: BlkW/3];
    end
    assign zq1     = !(per1 && live) || (out_q[0] == BlkW'(1));
    assign seln1   = sum1 ? !prot1_q : g_pass1_fast.seld1;
    assign zrest   = sum1 ? (prot1_q && &zp_g) : (z1 && zq1);
    assign blk1z_d = seln1 ? &zn_g : zrest;
  end

  // ---- stage 2: block 2 ------------------------------------------------------------------
  logic ev2, active2;
  logic [2:0] wr2;
  logic [BlkW-1:0] src2, out2;
  // The carry out of block 2 (bit 35) is dropped: arithmetic wraps modulo 2^36.
  /* verilator lint_off UNUSEDSIGNAL */
  logic [BlkW:0] sp2, sn2, s2;
  /* verilator lint_on UNUSEDSIGNAL */
  assign ev2     = id2.data && !id2.set;
  assign active2 = ev2 && act2_q;
  // = reg_blk(id2.src, a_q[2], b_q[2], c_q[2]), registered (src2_q), as in stage 1.
  assign src2    = src2_q;
  // As in stage 0: both operand sums, prot2_q picks one after the adders.
  assign sp2     = {1'b0, dst2_q} + {1'b0, src2} + blk_carry_in(c2_q, 2, Bug);
  assign sn2     = {1'b0, in_blk[2]} + {1'b0, src2} + blk_carry_in(c2_q, 2, Bug);
  assign s2      = prot2_q ? sp2 : sn2;
  // = (ev2 || st2) && act2_q && !prot2_q && (id2.dst != RegNone), i.e. wr1 a cycle ago,
  // split by destination as wr1 (assigned below, g_wr_fast / g_wr_small).
  assign out2    = (active2 && live) ? s2[BlkW-1:0] : in_blk[2];

  // ---- accumulator: ACC decided in its stage 1, D block j written in stage j+1 ----------
  // The decision waits one cycle because Acc_mode needs the sign of A (bit 35), which is
  // block 2 of the intensity written by the slot just before the ACC, in this cycle.
  logic a2_sign_next, acc_act1, accen1;
  logic [BlkW:0] sa0, sa1;
  // The carry out of block 2 (bit 35) is dropped: arithmetic wraps modulo 2^36.
  /* verilator lint_off UNUSEDSIGNAL */
  logic [BlkW:0] sa2;
  /* verilator lint_on UNUSEDSIGNAL */
  always_comb begin
    a2_sign_next = a_q[2][BlkW-1];
    if (wr2[0]) begin
      a2_sign_next = in_blk[2][BlkW-1];
    end
    if (id2.refresh) begin
      a2_sign_next = 1'b0;
    end
  end
  assign acc_act1 = id1.acc && act1_q;
  assign accen1   = acc_act1 && !lock_q && !dis_q && !(accm_q && a2_sign_next);
  assign sa0 = {1'b0, d_q[0]} + {1'b0, a_q[0]};
  assign sa1 = {1'b0, d_q[1]} + {1'b0, a_q[1]} + blk_carry_in(accc2_q, 1, Bug);
  assign sa2 = {1'b0, d_q[2]} + {1'b0, a_q[2]} + blk_carry_in(accc3_q, 2, Bug);

  // D's next value before a Refresh clear. Eval0 wins over an ACC write of the same
  // cycle: an ACC can only coincide with an Eval0 that follows it in the stream.
  logic [NumBlk-1:0][BlkW-1:0] d_next;
  always_comb begin
    d_next = d_q;
    if (accen1) begin
      d_next[0] = sa0[BlkW-1:0];
    end
    if (accen2_q) begin
      d_next[1] = sa1[BlkW-1:0];
    end
    if (accen3_q) begin
      d_next[2] = sa2[BlkW-1:0];
    end
    if (e0wr2_q) begin
      d_next = {in_blk[2], {(2 * BlkW) {1'b0}}};
    end
  end

  // ---- register file next state ------------------------------------------------------------
  always_comb begin
    a_d = a_q;
    b_d = b_q;
    c_d = c_q;
    d_d = d_next;
    // Block j of a data slot is written in its stage j (only one slot per stage); the
    // value written is the input block (wr* is off for a protected slot, see wr0).
    if (wr0) begin
      case (id0.dst)
        RegA:    a_d[0] = in_blk[0];
        RegB:    b_d[0] = in_blk[0];
        default: c_d[0] = in_blk[0];
      endcase
    end
    // Stages 1 and 2: the write decoded by destination a stage earlier (wr1, wr2).
    if (wr1[0]) a_d[1] = in_blk[1];
    if (wr1[1]) b_d[1] = in_blk[1];
    if (wr1[2]) c_d[1] = in_blk[1];
    if (wr2[0]) a_d[2] = in_blk[2];
    if (wr2[1]) b_d[2] = in_blk[2];
    if (wr2[2]) c_d[2] = in_blk[2];
    // A Refresh clears block j of A-D in its stage j; the clear wins over any write.
    if (id0.refresh) begin
      a_d[0] = '0;
      b_d[0] = '0;
      c_d[0] = '0;
      d_d[0] = '0;
    end
    if (id1.refresh) begin
      a_d[1] = '0;
      b_d[1] = '0;
      c_d[1] = '0;
      d_d[1] = '0;
    end
    if (id2.refresh) begin
      a_d[2] = '0;
      b_d[2] = '0;
      c_d[2] = '0;
      d_d[2] = '0;
    end
  end

  // ---- flags next state -----------------------------------------------------------------
  logic no_class0;
  assign no_class0 = !(id0.addr || id0.data || id0.acc || id0.refresh);

  always_comb begin
    pa_d   = pa_q;
    pb_d   = pb_q;
    pc_d   = pc_q;
    dis_d  = dis_q;
    lock_d = lock_q;
    accm_d = accm_q;
    // Stage-1 writes first: they belong to the older slot.
    if (dis1) begin
      dis_d = 1'b1;
    end
    if (e0en1) begin
      lock_d = 1'b1;
    end
    if (e0_1 || acc_act1) begin
      // The Eval (Eval0 or ACC) active in this PE consumes the Sets and the Dis.
      pa_d  = 1'b0;
      pb_d  = 1'b0;
      pc_d  = 1'b0;
      dis_d = 1'b0;
    end
    // Stage-0 writes last: the younger slot wins a same-cycle conflict.
    if (st0 && act_eff) begin
      case (id0.dst)
        RegA:    pa_d = 1'b1;
        RegB:    pb_d = 1'b1;
        RegC:    pc_d = 1'b1;
        default: ;
      endcase
    end
    if (no_class0 && (id0.sub == SubAccmodeOn)) begin
      accm_d = 1'b1;
    end
    if (no_class0 && (id0.sub == SubAccmodeOff)) begin
      accm_d = 1'b0;
    end
    if (id0.refresh) begin
      pa_d   = 1'b0;
      pb_d   = 1'b0;
      pc_d   = 1'b0;
      dis_d  = 1'b0;
      lock_d = 1'b0;
      accm_d = 1'b0;
    end
  end

  // Only data and ACC slots keep act; every other slot ends the command (isa.md sec. 5).
  assign act_d = (id0.data || id0.acc) && act_eff;
  // Next cycle's act_eff for either outcome of its zero test (the address decision of
  // the slot now in stage 0, else act_d).
  assign aez_d  = id0.addr ? (id0.sub == SubPeriodic) : act_d;
  assign aenz_d = id0.addr ? xz1_d : act_d;
  assign disx_d = xz1_d && (id0.sub == SubDis);
  assign e0x_d  = xz1_d && (id0.sub == SubEval0);
  // wr1/wr2 are wr0/wr1 one cycle on; the slot in stage 0 (1) reads block 1 (2) next
  // cycle, after this cycle's writes, hence the operands from a_d, b_d, c_d.
  // Split by destination (wr0 implies id0.dst != RegNone, so the case's default is C).
  // The Compact PE (the iCE40 chip, which is full) registers one write bit per stage and
  // decodes the destination behind it, as before the split: wr1_q[0]/wr2_q[0] only (bits
  // 2:1 constant zero, removed by synthesis), the same cycle behaviour.
  if (Compact == 1) begin : g_wr_small
    assign wr1_d = {2'b00, wr0};
    assign wr2_d = {2'b00, wr1_q[0]};
    assign wr1   = {wr1_q[0] && (id1.dst != RegA) && (id1.dst != RegB),
                    wr1_q[0] && (id1.dst == RegB), wr1_q[0] && (id1.dst == RegA)};
    assign wr2   = {wr2_q[0] && (id2.dst != RegA) && (id2.dst != RegB),
                    wr2_q[0] && (id2.dst == RegB), wr2_q[0] && (id2.dst == RegA)};
  end else begin : g_wr_fast
    assign wr1_d = {wr0 && (id0.dst == RegC), wr0 && (id0.dst == RegB),
                    wr0 && (id0.dst == RegA)};
    assign wr2_d = wr1;
    assign wr1   = wr1_q;
    assign wr2   = wr2_q;
  end
  // (Compact: plain, blk1z_d does not use src1.)
  assign src1_d = (sum0 || Compact == 1 || InReg == 1) ?
                  reg_blk(id0.src, a_d[1], b_d[1], c_d[1]) : '1;
  assign dst1_d = reg_blk(id0.dst, a_d[1], b_d[1], c_d[1]);
  assign src2_d = reg_blk(id1.src, a_d[2], b_d[2], c_d[2]);
  assign dst2_d = reg_blk(id1.dst, a_d[2], b_d[2], c_d[2]);

  // ---- pipeline next state ----------------------------------------------------------------
  assign id_d     = (InReg == 1) ? in_id_q : id_i;
  assign out_d    = {out2, out1, out0};
  assign id2_d    = id_q;
  assign xz1_d    = rng0 && xz0;
  assign per1_d   = id0.addr && (id0.sub == SubPeriodic);
  assign act1_d   = act_eff;
  assign prot1_d  = prot0;
  assign c1_d     = sum0 && s0[BlkW];     // = active0 && s0[BlkW] (in bypass c1_q is held in reset)
  assign act2_d   = act1_q;
  assign prot2_d  = prot1_q;
  assign c2_d     = active1 && s1[BlkW];
  assign e0wr2_d  = e0en1;
  assign accen2_d = accen1;
  assign accc2_d  = accen1 && sa0[BlkW];
  assign accen3_d = accen2_q;
  assign accc3_d  = accen2_q && sa1[BlkW];
  // Pixel: D block 2 as it stands at the end of the Refresh's stage 2 without the
  // Refresh's own clear (forwards an ACC written in the same cycle); zero when not
  // valid so that a chip can OR the pixel outputs of its PEs.
  assign pixv_d   = id2.refresh;
  assign pix_d    = id2.refresh ? d_next[2] : '0;

  // ---- flip-flops ------------------------------------------------------------------------
  // Synchronous reset: it maps onto the FPGA flops' local set/reset with no
  // recovery/removal timing to close, and it makes reset just another clock cycle,
  // exactly as the structural model treats it.
  // The bus registers: the PE's own output, or in bypass its input one clock later. The
  // bypass register of a chip is thus this register, and the next PE's input is a
  // flip-flop with no OR or mux behind it (docs/fpga.md, section 6.3). Beside them the
  // timing-only registers that follow id_q and out_q through a bypass, so that they are
  // right in the first cycle after one: per1_q (of id_q), blk1z_q (of out_q), src1_q
  // (all ones through a bypass, where nothing adds, as in the cycle after it, where
  // act1_q is still reset).
  // Reset groups (timing only): each group reads its own copy of the reset and of the
  // bypass bit (RstW copies, all equal), so that a copy fans out to a group's set/reset
  // logic, not to the ~300 flip-flops of the PE (docs/fpga-timing-log.md section 4).
  localparam int unsigned RstBus = 0, RstAb = 1, RstCd = 2, RstCtl = 3;
  logic rst_bus, hold_ab, hold_cd, hold_ctl;
  assign rst_bus  = rst_i[RstBus % RstW];
  assign hold_ab  = rst_i[RstAb % RstW]  || bypass_i[RstAb % RstW];
  assign hold_cd  = rst_i[RstCd % RstW]  || bypass_i[RstCd % RstW];
  assign hold_ctl = rst_i[RstCtl % RstW] || bypass_i[RstCtl % RstW];

  always_ff @(posedge clk_i) begin
    if (rst_bus) begin
      out_q   <= '0;
      blk1z_q <= 1'b1;  // out_q is zero
      per1_q  <= 1'b0;
      src1_q  <= '0;
    end else begin
      out_q   <= out_d;
      blk1z_q <= blk1z_d;
      per1_q  <= per1_d;
      src1_q  <= src1_d;
    end
  end

  // InReg: the input register follows the bus (a bypassed PE passes its input through it,
  // so it costs two clocks like a PE in use), the operand registers follow the register
  // blocks (zero in reset and in bypass, as the blocks are).
  if (InReg == 1) begin : g_in_regs
    // Only the register fields of the next slot's identifier are read here.
    /* verilator lint_off UNUSEDSIGNAL */
    id_t idn;
    /* verilator lint_on UNUSEDSIGNAL */
    assign idn = id_t'(id_i);
    always_ff @(posedge clk_i) begin
      if (rst_bus) begin
        in_id_q   <= '0;
        in_data_q <= '0;
        in_z1_q   <= 1'b1;
        in_dm0_q  <= {1'b0, {BlkW{1'b1}}};
      end else begin
        in_id_q   <= id_i;
        in_data_q <= data_i;
        in_z1_q   <= (data_i[BlkW +: BlkW] == '0);
        in_dm0_q  <= {1'b0, data_i[0 +: BlkW]} + {1'b0, {BlkW{1'b1}}};
      end
    end
    // The slot on id_i now is in stage 0 next cycle and reads the register blocks as they
    // stand after this cycle's writes: = reg_blk(idn.src, a_d[0], b_d[0], c_d[0]), built
    // as a forward, so that the late act_eff (wr0 = wpre && act_eff) picks between two
    // values formed without it: the block as it stands, or the input block written now;
    // a Refresh in stage 0 clears all three.
    logic wpre, hit_s, hit_d, fw_s, fw_d;
    logic [BlkW-1:0] base_s, base_d;
    assign wpre   = (ev0 || st0) && !pv0 && (id0.dst != RegNone);
    assign hit_s  = wpre && (idn.src == id0.dst);
    assign hit_d  = wpre && (idn.dst == id0.dst);
    assign fw_s   = z1 ? (hit_s && aez_q) : (hit_s && aenz_q);
    assign fw_d   = z1 ? (hit_d && aez_q) : (hit_d && aenz_q);
    assign base_s = reg_blk(idn.src, a_q[0], b_q[0], c_q[0]);
    assign base_d = reg_blk(idn.dst, a_q[0], b_q[0], c_q[0]);
    always_ff @(posedge clk_i) begin
      if (hold_ab) begin
        src0_q <= '0;
        dst0_q <= '0;
      end else begin
        src0_q <= id0.refresh ? '0 : (fw_s ? in_blk[0] : base_s);
        dst0_q <= id0.refresh ? '0 : (fw_d ? in_blk[0] : base_d);
      end
    end
  end else begin : g_no_in_regs
    assign in_id_q   = '0;
    assign in_data_q = '0;
    assign in_z1_q   = 1'b1;
    assign in_dm0_q  = '0;
    assign src0_q    = '0;
    assign dst0_q    = '0;
  end

  // Everything else; a bypassed PE holds it in reset (no pixel, an all-zero state).
  always_ff @(posedge clk_i) begin
    if (hold_ab) begin
      a_q <= '0;
      b_q <= '0;
    end else begin
      a_q <= a_d;
      b_q <= b_d;
    end
  end
  always_ff @(posedge clk_i) begin
    if (hold_cd) begin
      c_q <= '0;
      d_q <= '0;
    end else begin
      c_q <= c_d;
      d_q <= d_d;
    end
  end
  always_ff @(posedge clk_i) begin
    if (hold_ctl) begin
      pa_q     <= 1'b0;
      pb_q     <= 1'b0;
      pc_q     <= 1'b0;
      dis_q    <= 1'b0;
      lock_q   <= 1'b0;
      accm_q   <= 1'b0;
      act_q    <= 1'b0;
      id2_q    <= '0;
      xz1_q    <= 1'b0;
      act1_q   <= 1'b0;
      prot1_q  <= 1'b0;
      c1_q     <= 1'b0;
      act2_q   <= 1'b0;
      prot2_q  <= 1'b0;
      c2_q     <= 1'b0;
      e0wr2_q  <= 1'b0;
      accen2_q <= 1'b0;
      accc2_q  <= 1'b0;
      accen3_q <= 1'b0;
      accc3_q  <= 1'b0;
      pix_q    <= '0;
      aez_q    <= 1'b0;
      aenz_q   <= 1'b0;
      disx_q   <= 1'b0;
      e0x_q    <= 1'b0;
      wr1_q    <= '0;
      wr2_q    <= '0;
      dst1_q   <= '0;
      src2_q   <= '0;
      dst2_q   <= '0;
    end else begin
      pa_q     <= pa_d;
      pb_q     <= pb_d;
      pc_q     <= pc_d;
      dis_q    <= dis_d;
      lock_q   <= lock_d;
      accm_q   <= accm_d;
      act_q    <= act_d;
      id2_q    <= id2_d;
      xz1_q    <= xz1_d;
      act1_q   <= act1_d;
      prot1_q  <= prot1_d;
      c1_q     <= c1_d;
      act2_q   <= act2_d;
      prot2_q  <= prot2_d;
      c2_q     <= c2_d;
      e0wr2_q  <= e0wr2_d;
      accen2_q <= accen2_d;
      accc2_q  <= accc2_d;
      accen3_q <= accen3_d;
      accc3_q  <= accc3_d;
      pix_q    <= pix_d;
      aez_q    <= aez_d;
      aenz_q   <= aenz_d;
      disx_q   <= disx_d;
      e0x_q    <= e0x_d;
      wr1_q    <= wr1_d;
      wr2_q    <= wr2_d;
      dst1_q   <= dst1_d;
      src2_q   <= src2_d;
      dst2_q   <= dst2_d;
    end
  end

  // The second copy of id_q for the next PE's operand selects: a kept process of its own,
  // or yosys' opt_merge folds it into id_q (docs/fpga-timing-log.md section 4).
  // One kept process per bit, for id_q as for its copy: a keep on a vector's process, or
  // on one of the two copies only, still lets opt_merge fold them into one. Without the
  // copy (IdCopy = 0) id_q is a plain register (synthesis may then drop unread bits).
  if (IdCopy == 1) begin : g_idsel
    for (genvar k = 0; k < IdW; k++) begin : g_id_bit
      (* keep *) always_ff @(posedge clk_i) begin
        if (rst_bus) id_q[k] <= 1'b0;
        else         id_q[k] <= id_d[k];
      end
    end
    logic [IdW-1:0] idsel_q;
    for (genvar k = 0; k < IdW; k++) begin : g_bit
      (* keep *) always_ff @(posedge clk_i) begin
        if (rst_bus) idsel_q[k] <= 1'b0;
        else         idsel_q[k] <= id_d[k];
      end
    end
    assign idsel_o = idsel_q;
  end else begin : g_no_idsel
    always_ff @(posedge clk_i) begin
      if (rst_bus) id_q <= '0;
      else         id_q <= id_d;
    end
    assign idsel_o = id_q;
  end

  // The pixel-valid register and, with PixCopy, a copy of it for the chip's collision
  // flag and valid chain (de_chip), each a kept process (opt_merge, as for id_q).
  if (PixCopy == 1) begin : g_pixv_copy
    logic pixvc_q;
    (* keep *) always_ff @(posedge clk_i) begin
      if (hold_ctl) pixv_q <= 1'b0;
      else          pixv_q <= pixv_d;
    end
    (* keep *) always_ff @(posedge clk_i) begin
      if (hold_ctl) pixvc_q <= 1'b0;
      else          pixvc_q <= pixv_d;
    end
    assign pixv_c_o = pixvc_q;
  end else begin : g_pixv
    always_ff @(posedge clk_i) begin
      if (hold_ctl) pixv_q <= 1'b0;
      else          pixv_q <= pixv_d;
    end
    assign pixv_c_o = pixv_q;
  end

  // ---- outputs ----------------------------------------------------------------------------
  assign id_o        = id_q;
  assign data_o      = out_q;
  assign blk1z_o     = blk1z_q;
  assign pix_valid_o = pixv_q;
  assign pix_o       = pix_q;

  // Layout = DBG_FIELDS in sw/diffengine/model/structural.py, MSB first.
  assign dbg_o = {a_q, b_q, c_q, d_q,
                  pa_q, pb_q, pc_q, dis_q, lock_q, accm_q, act_q,
                  id_q, id2_q, out_q,
                  xz1_q, act1_q, prot1_q, c1_q, act2_q, prot2_q, c2_q,
                  e0wr2_q, accen2_q, accc2_q, accen3_q, accc3_q,
                  pixv_q, pix_q};

endmodule

`default_nettype wire
