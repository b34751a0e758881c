// Difference Engine: the x-processor array, NumChips chips of nine PEs in a line.
//
//   id_i/data_i (one instruction per clock, unskewed)
//     -> de_skew -> chip 0 -> chip 1 -> ... -> chip NumChips-1 -> de_deskew -> id_o/data_o
//   pixels leave the last chip in column order, one per clock (pix_valid_o/pix_o).
//
// Latency (docs/array.md): the pixel of column q of a Refresh that enters at cycle t
// leaves at t + q + NumChips + PixLatency0, where q counts only PEs that are not
// bypassed, plus one per bypassed PE; with InReg = 1 at t + q + (NumPe + 1) NumChips + 4
// (each PE registers its input: two clocks per PE position on the bus). Two Refreshes must be at least n_pe_o cycles apart (7.4.1: one Refresh
// active at a time); pix_collision_o flags a violation and stays set until reset.
`default_nettype none

module de_array
  import de_pkg::*;
#(
  parameter int unsigned NumChips  = 72,   // 648 PEs: 640 columns plus spares (7.8)
  parameter int unsigned CarryBug  = 0,
  parameter int unsigned NumPe     = 9,    // PEs per chip (the source's chip has 9)
  // Test only: chip c's PE i is faulty when bit c*NumPe+i is set (bypass test).
  parameter logic [1023:0] FaultMask = '0,
  // de_chip TimingCopies: 0 leaves out the timing-only register copies (the Verilated
  // harnesses, sim/Makefile); no output changes.
  parameter int unsigned TimingCopies = 1,
  // de_chip InReg: 1 = every PE registers its input (the chip of the FPGA flow, which
  // closes faster; docs/array.md, "Pixel timing"); 0 = one clock per PE position.
  parameter int unsigned InReg = 0
) (
  input  logic             clk_i,
  input  logic             rst_i,
  input  logic [IdW-1:0]   id_i,
  input  logic [DataW-1:0] data_i,
  output logic [IdW-1:0]   id_o,
  output logic [DataW-1:0] data_o,
  output logic             pix_valid_o,
  output logic [PixW-1:0]  pix_o,
  output logic [15:0]      n_pe_o,           // PEs built (bypassed ones included)
  output logic             pix_collision_o,
  input  logic             cfg_mode_i,
  input  logic             cfg_bit_i,
  output logic             cfg_bit_o,
  input  logic             obs_load_i,
  input  logic             obs_shift_i,
  output logic             obs_bit_o
);
  if (NumChips < 1 || NumChips * NumPe > 4096) begin : g_bad_size
    // 12-bit X and dX address at most 4096 columns (7.4.2).
    $fatal(1, "de_array: NumChips*NumPe must be 1..4096, got %0d", NumChips * NumPe);
  end
  if (CarryBug > 1) begin : g_bad_carry_bug
    $fatal(1, "de_array: CarryBug must be 0 or 1");
  end

  // What chip c receives (link_c[c], chain_c[c]) and passes on (link_c[c+1]).
  link_t  [NumChips:0] link_c;
  // Timing only: link_c[c].data's block 1 is zero (registered); de_deskew needs no flag.
  /* verilator lint_off UNUSEDSIGNAL */
  logic   [NumChips:0] blk1z_c;
  // Timing only: = link_c[c].id, the previous chip's copy of its id register (de_chip
  // idsel_o); chip 0's is link_c[0].id itself (the array input is not registered here).
  logic   [NumChips:0][IdW-1:0] idsel_c;
  /* verilator lint_on UNUSEDSIGNAL */
  chain_t [NumChips:0] chain_c;
  logic   [NumChips-1:0] coll_c;
  // Bypass bits per chip: visible in waves and to testbenches through the hierarchy.
  /* verilator lint_off UNUSEDSIGNAL */
  logic [NumChips-1:0][NumPe-1:0] bypass_c;
  /* verilator lint_on UNUSEDSIGNAL */

  // Chip 0 takes the skewed bus and no pixel; the chains enter there too.
  de_skew u_skew (.clk_i, .rst_i, .id_i, .data_i, .id_o(link_c[0].id), .blk_o(link_c[0].data));
  assign {link_c[0].pix_valid, link_c[0].pix, link_c[0].coll} = '0;
  assign chain_c[0] = {cfg_bit_i, 1'b0};
  // Beside de_skew's block-1 register: chip 0's PE 0 reads its zero test of block 1 from
  // a flip-flop like every other PE (de_pe blk1z_i).
  logic skew_blk1z_q;
  always_ff @(posedge clk_i) begin
    if (rst_i) skew_blk1z_q <= 1'b1;
    else       skew_blk1z_q <= (data_i[BlkW +: BlkW] == '0);
  end
  assign blk1z_c[0] = skew_blk1z_q;
  assign idsel_c[0] = link_c[0].id;

  for (genvar c = 0; c < NumChips; c++) begin : g_chip
    de_chip #(
      .NumPe    (NumPe),
      .CarryBug (CarryBug),
      .FaultMask(32'(FaultMask[c*NumPe +: NumPe])),
      .TimingCopies(TimingCopies),
      .InReg    (InReg)
    ) u_chip (
      .clk_i, .rst_i,
      .link_i     (link_c[c]),
      .link_o     (link_c[c+1]),
      .blk1z_i    (blk1z_c[c]),
      .blk1z_o    (blk1z_c[c+1]),
      .idsel_i    (idsel_c[c]),
      .idsel_o    (idsel_c[c+1]),
      .chain_ctl_i({cfg_mode_i, obs_load_i, obs_shift_i}),
      .chain_i    (chain_c[c]),
      .chain_o    (chain_c[c+1]),
      .bypass_o   (bypass_c[c])
    );
    assign coll_c[c] = link_c[c+1].coll;
  end

  de_deskew u_deskew (
    .clk_i, .rst_i,
    .id_i (link_c[NumChips].id), .blk_i(link_c[NumChips].data), .id_o, .data_o
  );

  logic coll_d, coll_q;
  assign coll_d = coll_q | (|coll_c);
  always_ff @(posedge clk_i) begin
    if (rst_i) coll_q <= 1'b0;
    else       coll_q <= coll_d;
  end

  assign pix_valid_o     = link_c[NumChips].pix_valid;
  assign pix_o           = link_c[NumChips].pix;
  assign n_pe_o          = 16'(NumChips * NumPe);
  assign pix_collision_o = coll_q;
  assign cfg_bit_o       = chain_c[NumChips].cfg;
  // The last chip's words come out first; within a chip, PE 0's word first.
  assign obs_bit_o       = chain_c[NumChips].obs;
endmodule

`default_nettype wire
