// Difference Engine: one chip of nine x-processors (Kuijk 1995, 7.4.5, Fig. 7.7).
//
// Bus:    id/data (skewed blocks) -> PE 0 -> ... -> PE 8 -> boundary register -> out.
// Pixels: the upstream chip's pixel OR the nine PEs' pixels -> boundary register.
// Both travel with the collision flag in one de_pkg::link_t (link_i -> link_o).
// The boundary registers keep the combinational depth independent of the chip count.
// Because both buses gain exactly one register per chip, a pixel of column q leaves the
// last chip at (Refresh entry) + q + NumChips + const for every q: raster order with no
// gap and no collision (docs/array.md derives it). With InReg = 1 (each PE registers its
// input: two bus clocks per PE position) the pixel chain has a register per PE instead,
// two per bypassed PE, and column q leaves at entry + q + (NumPe + 1) NumChips + const.
//
// Configuration (7.4.5): a serial shift register with one bypass bit per PE. A bypassed
// PE's place is taken by a register on the bus and on the pixel chain (the source's
// bypass is a wire; registered here so that the chip's clock does not depend on how many
// PEs are bypassed in a row; on the bus it is the PE's own output register) and the rest
// of the PE is held in reset (no pixel, an all-zero observation word); relative
// addressing makes the remaining PEs a smaller array, one clock later per bypassed PE.
// Observation (7.4.5): a second serial register that loads each PE's controller outputs
// (flags, stage-1 identifier, control pipeline) on obs_load and shifts them out.
`default_nettype none

module de_chip
  import de_pkg::*;
#(
  parameter int unsigned NumPe     = 9,
  parameter int unsigned CarryBug  = 0,
  parameter int unsigned Compact   = 0,   // de_pe Compact: 1 = the smallest PE (iCE40)
  // Test only: PEs whose bus output is corrupted (bit i = PE i), to show bypass works.
  parameter logic [31:0] FaultMask = '0,
  // Timing only: copies of the reset on rst_i (a reset tree, below); 1 = one reset.
  parameter int unsigned RstW      = 1,
  // Timing only: 1 = the fast form's kept register copies (the identifier for the next
  // PE's operand selects, the pixel-valid bit for the collision flag); they hold the
  // values of the registers they copy, so 0 changes no output. The FPGA builds and the
  // testbenches keep 1; the Verilated harnesses build 0 (the copies cost them 11 %).
  parameter int unsigned TimingCopies = 1,
  // What-if only (fpga/scripts/flow.py chip, its pe9_nobypass run): 1 = every PE's
  // bypass_i tied to 0 and live_i to 1, so synthesis sees the static configuration as
  // the constant it is in use (what the bypass costs, which STA cannot know is static).
  // The configuration chain still shifts but bypasses no PE. 0 in every product.
  parameter int unsigned TieBypass = 0,
  // 1 = every PE registers its own input (de_pe InReg: two clocks per PE position on the
  // bus) and the pixel chain has one register per PE, two per bypassed PE, so that the
  // pixels still leave one per clock in raster order (docs/array.md); 0 = one clock per
  // PE position and a combinational pixel chain inside the chip.
  parameter int unsigned InReg = 0
) (
  input  logic             clk_i,
  // Synchronous, active high: RstW registered copies of ONE reset, equal in every cycle.
  // Copy k % RstW resets group k: PE i's register groups are k = 5i .. 5i+3 (de_pe
  // RstW), its bypass, pixel and observation registers here k = 5i+4, the configuration
  // k = 5 NumPe, the boundary registers k = 5 NumPe + 1; so RstW = 5 NumPe + 2 gives
  // every group a copy of its own (fpga/chip_top.sv) and no copy drives the whole chip.
  input  logic [RstW-1:0]  rst_i,
  // The bus and pixel chain from the upstream chip (its coll is not used: the array ORs
  // the chips' flags) and to the next, registered. link_o.coll: two pixels met on the
  // chain this cycle (registered): two Refreshes were closer than the array is wide,
  // breaking "one Refresh active at a time" (7.4.1).
  input  link_t            link_i,
  output link_t            link_o,
  // Timing only: link_i.data's block 1 is zero, registered upstream (the previous chip's
  // boundary register, or a register beside the input skew); blk1z_o likewise for link_o.
  input  logic             blk1z_i,
  output logic             blk1z_o,
  // Timing only: = link_i.id in every cycle, a register of its own (the previous chip's
  // idsel_o, or at the array input link_i.id itself), which the PE 0 stage-0 operand
  // selects read (de_pe IdCopy); idsel_o likewise for link_o.id (= link_o.id when
  // Compact). Not architectural.
  /* verilator lint_off UNUSEDSIGNAL */
  input  logic [IdW-1:0]   idsel_i,
  /* verilator lint_on UNUSEDSIGNAL */
  output logic [IdW-1:0]   idsel_o,
  // configuration chain: shifts one bit per clock while chain_ctl_i.cfg_mode;
  // observation chain: parallel load on .obs_load, shift one bit per clock on .obs_shift
  input  chain_ctl_t       chain_ctl_i,
  input  chain_t           chain_i,
  output chain_t           chain_o,
  output logic [NumPe-1:0] bypass_o     // current configuration, for tests and waves
);
  // Keep the chip a module of its own in Verilator's C++: the 72 instances then share one
  // class instead of flattening 648 PEs into one 90 MB root (build time 11 -> 2 min for 72 chips on 2 cores).
  /* verilator no_inline_module */

  // The chip is its core (PEs, bypass, chains: no register between its bus input and
  // output) followed by the boundary registers. The split lets the fast simulation
  // (sim/fast, docs/simulation.md) cut the array at the registers and compile one chip
  // once; the logic is the same either way.
  link_t core_link;

  de_chip_core #(.NumPe(NumPe), .CarryBug(CarryBug), .Compact(Compact), .FaultMask(FaultMask),
                 .RstW(RstW), .TimingCopies(TimingCopies), .TieBypass(TieBypass),
                 .InReg(InReg))
  u_core (
    .clk_i, .rst_i, .link_i, .blk1z_i, .idsel_i, .chain_ctl_i, .chain_i, .chain_o,
    .bypass_o, .link_o(core_link)
  );

  de_chip_bound #(.IdCopy((Compact == 0 && TimingCopies == 1 && InReg == 0) ? 1 : 0)) u_bound (
    .clk_i, .rst_i(rst_i[(5 * NumPe + 1) % RstW]), .link_i(core_link), .link_o, .blk1z_o,
    .idsel_o
  );
endmodule

// The chip without its boundary registers: bus and pixel chain from input to output
// pass through no logic but a gated OR (the PEs' own outputs and the pixel bypass
// registers are registered); the bus path crosses none, the pixel chain one OR of its
// sources, each gated by a registered reach bit.
/* verilator lint_off DECLFILENAME */
module de_chip_core
  import de_pkg::*;
#(
  parameter int unsigned NumPe     = 9,
  parameter int unsigned CarryBug  = 0,
  parameter int unsigned Compact   = 0,   // de_pe Compact: 1 = the smallest PE (iCE40)
  parameter logic [31:0] FaultMask = '0,
  parameter int unsigned RstW      = 1,   // copies of the reset (de_chip)
  parameter int unsigned TimingCopies = 1,  // de_chip
  parameter int unsigned TieBypass = 0,     // de_chip (what-if only)
  parameter int unsigned InReg     = 0      // de_chip
) (
  input  logic             clk_i,
  /* verilator lint_off UNUSEDSIGNAL */
  input  logic [RstW-1:0]  rst_i,        // equal copies; the boundary's is not used here
  input  link_t            link_i,       // .coll not used
  /* verilator lint_on UNUSEDSIGNAL */
  input  logic             blk1z_i,      // registered: link_i.data's block 1 is zero
  /* verilator lint_off UNUSEDSIGNAL */
  input  logic [IdW-1:0]   idsel_i,      // = link_i.id, a register of its own (not Compact)
  /* verilator lint_on UNUSEDSIGNAL */
  output link_t            link_o,       // combinational: the last PE's bus (or bypass),
                                         // its pixel OR the PEs' pixels, two pixels met here
  input  chain_ctl_t       chain_ctl_i,
  input  chain_t           chain_i,
  output chain_t           chain_o,
  output logic [NumPe-1:0] bypass_o
);
  // Observation word per PE: {pA,pB,pC,dis,lock,acc_mode,act,id1} and the 12 control
  // pipeline bits {xz1 .. accc3}; positions follow dbg_o (structural.DBG_FIELDS).
  // Field positions come from de_pkg (spec/isa.toml [debug]): the control bits run
  // from xz1 down to accc3, the flags from pA down to act, directly above id1.
  localparam int unsigned DbgCtlW = DbgXz1Lsb - DbgAccc3Lsb + 1;
  localparam int unsigned ObsW    = (DbgPaLsb - DbgId1Lsb + 1) + DbgCtlW;

  if (NumPe < 1 || NumPe > 32) begin : g_bad_num_pe
    $fatal(1, "de_chip: NumPe must be 1..32, got %0d", NumPe);
  end
  if (TieBypass > 1) begin : g_bad_tie_bypass
    $fatal(1, "de_chip: TieBypass must be 0 or 1, got %0d", TieBypass);
  end
  // Copies of the reset per PE (de_pe RstW): four groups when the chip has a tree.
  localparam int unsigned PeRstW = (RstW < 4) ? RstW : 4;
  logic rst_cfg;        // the configuration registers' copy
  assign rst_cfg = rst_i[(5 * NumPe) % RstW];

  logic [NumPe:0][IdW-1:0]   bus_id;
  logic [NumPe:0][DataW-1:0] bus_data;
  // Registered: bus_data's block 1 is zero. The last PE's is unused: the boundary
  // register makes its own from link_o (so that the chip's ports stay link_t).
  /* verilator lint_off UNUSEDSIGNAL */
  logic [NumPe:0]            bus_blk1z;
  // Timing only: a second copy of bus_id for the next PE's operand selects (de_pe IdCopy).
  logic [NumPe:0][IdW-1:0]   bus_idsel;
  /* verilator lint_on UNUSEDSIGNAL */
  logic [NumPe:0][PixW-1:0]  pix_or;
  logic [NumPe:0]            pixv_or;
  logic [NumPe-1:0][PixW-1:0] src_pix;  // what PE i puts on the pixel chain
  logic [NumPe-1:0]           src_pixv;
  /* verilator lint_off UNUSEDSIGNAL */
  logic [NumPe-1:0][PixW-1:0] pe_pix_all;  // PE i's pixel register (InReg = 1's chain)
  logic [NumPe-1:0]           pe_pixv_all; // its valid bit (the copy, pe_pixvc)
  /* verilator lint_on UNUSEDSIGNAL */
  /* verilator lint_off UNUSEDSIGNAL */
  logic [NumPe-1:0]          coll;     // (InReg = 1: the collision travels on the chain)
  /* verilator lint_on UNUSEDSIGNAL */
  logic [NumPe-1:0]          byp_d, byp_q;
  logic [NumPe-1:0][PeRstW-1:0] pe_byp;    // de_pe bypass_i (equal copies)
  logic [NumPe-1:0]          pe_live;          // de_pe live_i
  logic [NumPe-1:0][PeRstW-1:0] pe_rst;    // de_pe rst_i (equal copies)
  logic [NumPe-1:0]          rst_loc;          // PE i's registers in this module
  logic [NumPe*ObsW-1:0]     obs_d, obs_q, obs_load;

  assign bus_id[0]   = link_i.id;
  assign bus_idsel[0] = idsel_i;
  assign bus_data[0] = link_i.data;
  assign bus_blk1z[0] = blk1z_i;
  assign pix_or[0]   = link_i.pix_valid ? link_i.pix : '0;
  assign pixv_or[0]  = link_i.pix_valid;

  for (genvar i = 0; i < NumPe; i++) begin : g_pe
    logic [IdW-1:0]   pe_id;
    logic [DataW-1:0] pe_data;
    logic             pe_blk1z;
    logic             pe_pixv;
    logic             pe_pixvc;   // = pe_pixv, a copy for the valid chain and collision
    logic [PixW-1:0]  pe_pix;
    // Only the observation fields of the debug vector are used inside a chip.
    /* verilator lint_off UNUSEDSIGNAL */
    logic [DbgW-1:0]  pe_dbg;
    /* verilator lint_on UNUSEDSIGNAL */

    // A bypassed PE is its own bus register: it passes id and data on one clock later
    // and holds the rest of its state in reset (de_pe bypass_i).
    for (genvar g = 0; g < PeRstW; g++) begin : g_rst
      assign pe_rst[i][g] = rst_i[(5 * i + g) % RstW];
    end
    assign rst_loc[i] = rst_i[(5 * i + 4) % RstW];

    logic [IdW-1:0]   pe_idsel;
    de_pe #(.CarryBug(CarryBug), .Compact(Compact), .RstW(PeRstW),
            .IdCopy((Compact == 0 && TimingCopies == 1 && InReg == 0) ? 1 : 0),
            .InReg(InReg),
            .PixCopy((Compact == 0 && TimingCopies == 1) ? 1 : 0)) u_pe (
      .clk_i,
      .rst_i      (pe_rst[i]),
      .bypass_i   ((TieBypass == 1) ? '0 : pe_byp[i]),
      .live_i     ((TieBypass == 1) ? 1'b1 : pe_live[i]),
      .id_i       (bus_id[i]),
      .data_i     (bus_data[i]),
      .blk1z_i    (bus_blk1z[i]),
      .idsel_i    (bus_idsel[i]),
      .id_o       (pe_id),
      .data_o     (pe_data),
      .blk1z_o    (pe_blk1z),
      .idsel_o    (pe_idsel),
      .pix_valid_o(pe_pixv),
      .pixv_c_o   (pe_pixvc),
      .pix_o      (pe_pix),
      .dbg_o      (pe_dbg)
    );

    // A bypassed PE is a register (registered bypass): the bus takes one clock per PE
    // whatever the configuration, so no combinational path runs through two PEs. On the
    // bus that register is the PE's own output register (bypass_i), so the next PE's
    // input comes straight from a flip-flop. The pixel chain takes a register here, so
    // the pixels of the PEs in front catch up with the bus: pixels stay in raster order
    // with no gap, one clock later per bypassed PE (docs/array.md). A faulty PE (test
    // parameter) garbles what it passes on while it is in use.
    logic             byp_pixv_q;
    logic [PixW-1:0]  byp_pix_q;
    always_ff @(posedge clk_i) begin
      if (rst_loc[i] || !byp_q[i]) begin
        byp_pixv_q <= 1'b0;
        byp_pix_q  <= '0;
      end else begin
        byp_pixv_q <= pixv_or[i];
        byp_pix_q  <= pix_or[i];
      end
    end
    assign bus_id[i+1]   = pe_id;
    assign bus_idsel[i+1] = pe_idsel;
    assign bus_data[i+1] = (FaultMask[i] && !byp_q[i]) ? ~pe_data : pe_data;
    // The garbled block is zero where the PE's was all ones (test only; with no fault
    // this is the PE's flip-flop).
    assign bus_blk1z[i+1] = (FaultMask[i] && !byp_q[i]) ? (pe_data[BlkW +: BlkW] == '1)
                                                          : pe_blk1z;
    // The pixel chain at PE i (below): a bypassed PE's register replaces everything in
    // front of it, a PE in use adds its pixel. At most one PE of the whole array drives a
    // pixel in a cycle, so OR is a mux.
    assign pe_pix_all[i]  = pe_pix;
    assign pe_pixv_all[i] = pe_pixvc;
    assign src_pix[i]  = byp_q[i] ? byp_pix_q  : (pe_pixv ? pe_pix : '0);
    assign src_pixv[i] = byp_q[i] ? byp_pixv_q : pe_pixvc;
    assign coll[i]     = pixv_or[i] && pe_pixvc && !byp_q[i];
    // A bypassed PE's stage-1 identifier register carries the passing slots; the
    // observation word shows zero there, as it did when the PE's id_q was in reset: from
    // the clock after the bypass bit is set to the clock after it is cleared (byp_id0_q).
    logic byp_id0_q;
    always_ff @(posedge clk_i) begin
      if (rst_loc[i]) byp_id0_q <= 1'b0;
      else byp_id0_q <= byp_q[i];
    end
    assign obs_load[i*ObsW +: ObsW] = {pe_dbg[DbgPaLsb:DbgActLsb],
                                       byp_id0_q ? '0 : pe_dbg[DbgId1Lsb +: IdW],
                                       pe_dbg[DbgAccc3Lsb +: DbgCtlW]};
  end

  // The pixel chain, pix_or[n+1] = byp_q[n] ? byp_pix_q[n] : pix_or[n] | pixel of PE n,
  // is not built as a chain of NumPe OR gates (static timing would see them all in one
  // path, whatever the configuration) but as an OR of its sources each gated by a
  // registered reach bit: reach_q[n][s] = source s (0: the chip input, k+1: PE k or its
  // bypass register) gets to position n, i.e. no PE in s..n-1 is bypassed. reach_q
  // follows byp_q, so every cycle gives the chain's values. It is shifted with the bypass
  // bits rather than recomputed from them (one mux per bit, not an AND chain behind the
  // shift): a bit entering PE 0 moves PE k's bit to PE k+1, so reach[n][s] takes
  // reach[n-1][s-1], and the chip input reaches n if it reached n-1 and PE 0 is in use.
  logic [NumPe:1][NumPe:0] reach_d, reach_q;
  always_comb begin
    reach_d = reach_q;
    if (chain_ctl_i.cfg_mode) begin
      reach_d = '0;
      reach_d[1][1] = 1'b1;  // PE 0 itself: its pixel or its bypass register
      reach_d[1][0] = !chain_i.cfg;
      for (int n = 2; n <= NumPe; n++) begin
        reach_d[n][0] = !chain_i.cfg && reach_q[n-1][0];
        for (int s = 1; s <= n; s++) begin
          reach_d[n][s] = reach_q[n-1][s-1];
        end
      end
    end
  end
  for (genvar n = 1; n <= NumPe; n++) begin : g_pix_or
    always_comb begin
      pix_or[n]  = reach_q[n][0] ? pix_or[0] : '0;
      pixv_or[n] = reach_q[n][0] && pixv_or[0];
      for (int s = 1; s <= n; s++) begin
        pix_or[n]  = pix_or[n] | (reach_q[n][s] ? src_pix[s-1] : '0);
        pixv_or[n] = pixv_or[n] | (reach_q[n][s] && src_pixv[s-1]);
      end
    end
  end

  // Configuration shift register: enters at PE 0, leaves after PE NumPe-1.
  // {byp_q, cfg_bit_i} shifted by one; its top bit is the one leaving (cfg_bit_o).
  logic [NumPe:0] byp_shifted;
  assign byp_shifted = {byp_q, chain_i.cfg};
  always_comb begin
    byp_d = byp_q;
    if (chain_ctl_i.cfg_mode) byp_d = byp_shifted[NumPe-1:0];
  end
  assign chain_o.cfg = byp_shifted[NumPe];
  assign bypass_o  = byp_q;

  // Observation shift register: PE 0's word shifts out first, LSB first.
  always_comb begin
    obs_d = obs_q;
    if (chain_ctl_i.obs_load) obs_d = obs_load;
    else if (chain_ctl_i.obs_shift) obs_d = {chain_i.obs, obs_q[NumPe*ObsW-1:1]};
  end
  assign chain_o.obs = obs_q[0];

  // The PEs' copies of byp_q: !byp_q, a register of its own for each PE's pass-through
  // terms (de_pe live_i), and byp_q again for the PE's own reset (bypass_i, one copy per
  // reset group of the PE), all kept, so that none waits on another's fan-out nor on the
  // shift register's placement. A Compact chip (the iCE40, which is full) takes byp_q
  // itself.
  for (genvar i = 0; i < NumPe; i++) begin : g_pe_byp
    if (Compact == 1) begin : g_small
      assign pe_byp[i]  = {PeRstW{byp_q[i]}};
      assign pe_live[i] = !byp_q[i];
    end else begin : g_fast
      // One process per copy, marked keep: yosys keeps such a cell, while a keep on the
      // variable does not stop opt_merge from folding equal registers into one.
      logic live_q;
      logic [PeRstW-1:0] byp_pe_q;
      (* keep *) always_ff @(posedge clk_i) begin
        if (rst_loc[i]) live_q <= 1'b1;
        else            live_q <= !byp_d[i];
      end
      for (genvar g = 0; g < PeRstW; g++) begin : g_copy
        (* keep *) always_ff @(posedge clk_i) begin
          if (rst_loc[i]) byp_pe_q[g] <= 1'b0;
          else            byp_pe_q[g] <= byp_d[i];
        end
      end
      assign pe_byp[i]  = byp_pe_q;
      assign pe_live[i] = live_q;
    end
  end

  // Configuration and observation registers; each PE's observation word is reset by
  // that PE's copy of the reset.
  always_ff @(posedge clk_i) begin
    if (rst_cfg) begin
      byp_q   <= '0;
      reach_q <= '1;   // no PE bypassed
    end else begin
      byp_q   <= byp_d;
      reach_q <= reach_d;
    end
  end
  for (genvar i = 0; i < NumPe; i++) begin : g_obs
    always_ff @(posedge clk_i) begin
      if (rst_loc[i]) obs_q[i*ObsW +: ObsW] <= '0;
      else            obs_q[i*ObsW +: ObsW] <= obs_d[i*ObsW +: ObsW];
    end
  end

  if (InReg == 0) begin : g_link_or
    assign link_o = {bus_id[NumPe], bus_data[NumPe], pixv_or[NumPe], pix_or[NumPe], |coll};
  end else begin : g_link_chain
    // One register per PE on the pixel chain, two per bypassed PE: the bus costs two
    // clocks per PE position, so each used column's pixel follows the one before it by
    // exactly one clock, and a bypassed position delays what is upstream by its two.
    logic [NumPe:0][PixW-1:0] cp;
    logic [NumPe:0]           cv, cc;
    assign cp[0] = link_i.pix_valid ? link_i.pix : '0;
    assign cv[0] = link_i.pix_valid;
    assign cc[0] = 1'b0;
    for (genvar i = 0; i < NumPe; i++) begin : g_chain
      logic [PixW-1:0] a_pix_q, b_pix_q;
      logic            a_pixv_q, b_pixv_q, a_coll_q, b_coll_q;
      always_ff @(posedge clk_i) begin
        if (rst_loc[i]) begin
          {a_pix_q, a_pixv_q, a_coll_q} <= '0;
          {b_pix_q, b_pixv_q, b_coll_q} <= '0;
        end else begin
          a_pix_q  <= cp[i] | pe_pix_all[i];
          a_pixv_q <= cv[i] | pe_pixv_all[i];
          a_coll_q <= cc[i] | (cv[i] && pe_pixv_all[i]);
          {b_pix_q, b_pixv_q, b_coll_q} <= {a_pix_q, a_pixv_q, a_coll_q};
        end
      end
      assign cp[i+1] = byp_q[i] ? b_pix_q  : a_pix_q;
      assign cv[i+1] = byp_q[i] ? b_pixv_q : a_pixv_q;
      assign cc[i+1] = byp_q[i] ? b_coll_q : a_coll_q;
    end
    assign link_o = {bus_id[NumPe], bus_data[NumPe], cv[NumPe], cp[NumPe], cc[NumPe]};
  end

endmodule

// A chip's boundary registers: they keep the combinational depth independent of the chip
// count and give both buses exactly one register per chip (docs/array.md).
module de_chip_bound
  import de_pkg::*;
#(
  // Timing only: 1 = idsel_o is a register of its own (a copy of id_q for the next chip's
  // PE 0 operand selects, de_pe IdCopy); 0 = idsel_o is id_q.
  parameter int unsigned IdCopy = 0
) (
  input  logic            clk_i,
  input  logic            rst_i,
  input  link_t           link_i,
  output link_t           link_o,
  output logic            blk1z_o,  // timing only: link_o.data's block 1 is zero (registered)
  output logic [IdW-1:0]  idsel_o   // timing only: = link_o.id in every cycle
);
  // One register per field, named as the trace harness binds them (sim/harness).
  logic [IdW-1:0]   id_q;
  logic [DataW-1:0] data_q;
  logic             pixv_q;
  logic [PixW-1:0]  pix_q;
  logic             coll_q;
  logic             blk1z_q;

  if (IdCopy == 1) begin : g_idsel
    // id_q and its copy as kept per-bit processes: otherwise yosys' opt_merge folds the
    // copy into id_q (docs/fpga-timing-log.md section 4, third and fourth pass).
    logic [IdW-1:0] idsel_q;
    for (genvar k = 0; k < IdW; k++) begin : g_bit
      (* keep *) always_ff @(posedge clk_i) begin
        if (rst_i) id_q[k] <= 1'b0;
        else       id_q[k] <= link_i.id[k];
      end
      (* keep *) always_ff @(posedge clk_i) begin
        if (rst_i) idsel_q[k] <= 1'b0;
        else       idsel_q[k] <= link_i.id[k];
      end
    end
    always_ff @(posedge clk_i) begin
      if (rst_i) {data_q, pixv_q, pix_q, coll_q} <= '0;
      else       {data_q, pixv_q, pix_q, coll_q} <= {link_i.data, link_i.pix_valid,
                                                     link_i.pix, link_i.coll};
    end
    assign idsel_o = idsel_q;
  end else begin : g_no_idsel
    always_ff @(posedge clk_i) begin
      if (rst_i) {id_q, data_q, pixv_q, pix_q, coll_q} <= '0;
      else       {id_q, data_q, pixv_q, pix_q, coll_q} <= link_i;
    end
    assign idsel_o = id_q;
  end
  // The next chip's PE 0 reads its zero test of block 1 from a flip-flop too; its input
  // here is the last PE's bus register, so the test is the only logic in front of it.
  always_ff @(posedge clk_i) begin
    if (rst_i) blk1z_q <= 1'b1;
    else       blk1z_q <= (link_i.data[BlkW +: BlkW] == '0);
  end
  assign blk1z_o = blk1z_q;

  assign link_o = {id_q, data_q, pixv_q, pix_q, coll_q};
endmodule

`default_nettype wire
