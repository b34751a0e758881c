// FPGA measurement wrapper for ONE Difference Engine chip (de_chip, Kuijk 1995 7.4.5).
//
// Not part of the design: it only gives place-and-route a top whose every timed path
// starts and ends at a flip-flop, and which needs a dozen pins whatever NumPe is, so the
// same wrapper fits a 48-pin iCE40 UP5K and an ECP5 and fmax is PE-to-PE, not pin-bound.
//
//   pins -> serial-in shift register (id, data, pix_valid, pix: 61 bits) -> de_chip
//   de_chip's registered outputs -> two-stage registered XOR fold -> 1 pin
//
// The shift register gives every chip input an arbitrary, independent value (nothing can
// be folded as constant); the XOR fold makes every chip output observable, so synthesis
// keeps the whole chip. The configuration and observation chain pins are registered
// and passed through as they are. de_chip registers its own outputs (boundary
// registers), so the only combinational paths inside are the chip's.
`default_nettype none

module chip_top #(
  parameter int unsigned NumPe    = 9,
  parameter int unsigned CarryBug = 0,
  parameter int unsigned Compact  = 0,   // de_pe Compact (1: the iCE40 chip, which is full)
  parameter int unsigned TieBypass = 0,  // de_chip TieBypass (1: flow.py's what-if chip)
  // de_chip InReg: 1 = each PE registers its input (docs/xproc.md section 11), the chip
  // the ECP5 flow measures; the Compact (iCE40) chip always builds 0.
  parameter int unsigned InReg    = 1
) (
  input  logic clk_i,
  input  logic rst_i,
  input  logic sin_i,         // serial stimulus for the 61 bus input bits
  input  logic cfg_mode_i,
  input  logic cfg_bit_i,
  input  logic obs_load_i,
  input  logic obs_shift_i,
  input  logic obs_bit_i,
  output logic cfg_bit_o,
  output logic obs_bit_o,
  output logic fold_o         // XOR of every chip output bit, registered
);
  // The input shift register holds one link_t without its collision bit, LSB first:
  // id, data, pix_valid, pix (de_pkg's widths).
  localparam int unsigned IdW     = de_pkg::IdW;
  localparam int unsigned DataW   = de_pkg::DataW;
  localparam int unsigned BlkW    = de_pkg::BlkW;
  localparam int unsigned PixW    = de_pkg::PixW;
  localparam int unsigned DataLsb = IdW;                       // sh_q[DataLsb +: DataW]
  localparam int unsigned PixVLsb = DataLsb + DataW;           // sh_q[PixVLsb]
  localparam int unsigned PixLsb  = PixVLsb + 1;               // sh_q[PixLsb +: PixW]
  localparam int unsigned InW     = PixLsb + PixW;
  localparam int unsigned OutW    = InW + NumPe + 1;           // + bypass, collision
  localparam int unsigned Grp  = 4;                            // XOR inputs per LUT
  localparam int unsigned NGrp = (OutW + Grp - 1) / Grp;

  localparam int unsigned RstW = (Compact == 1) ? 1 : 5 * NumPe + 2;  // reset tree (not iCE40)
  logic             cfg_mode_q, cfg_bit_q, obs_load_q, obs_shift_q, obs_bit_q;
  // The registered reset as RstW copies of one flip-flop (a reset tree: every copy is
  // the same register of the same input, so reset acts in the same cycle as with one),
  // each driving one group of de_chip's registers instead of one driving about 3,000.
  // Each copy is a process of its own marked keep (yosys then keeps the cell; a keep on
  // the variable alone, or one process for the vector, lets opt_merge fold them into one).
  logic [RstW-1:0]  rst_q;
  for (genvar k = 0; k < RstW; k++) begin : g_rst
    (* keep *) always_ff @(posedge clk_i) rst_q[k] <= rst_i;
  end
  logic [InW-1:0]   sh_q;
  logic             blk1z_q;
  de_pkg::link_t    link_o;
  de_pkg::chain_t   chain_o;
  logic [NumPe-1:0] bypass_o;
  logic [NGrp*Grp-1:0] out_vec;
  logic [NGrp-1:0]  fold1_q;
  logic             fold_q;

  always_ff @(posedge clk_i) begin
    cfg_mode_q  <= cfg_mode_i;
    cfg_bit_q   <= cfg_bit_i;
    obs_load_q  <= obs_load_i;
    obs_shift_q <= obs_shift_i;
    obs_bit_q   <= obs_bit_i;
    // de_chip's input block 1 (sh_q[DataLsb+BlkW +: BlkW]) is zero next cycle, when the
    // register has shifted by one: what the upstream chip's boundary register provides.
    blk1z_q     <= (sh_q[DataLsb+BlkW-1 +: BlkW] == '0);
  end
  logic [IdW-1:0]   idsel;
  if (Compact == 1) begin : g_in_small
    always_ff @(posedge clk_i) sh_q <= {sh_q[InW-2:0], sin_i};
    assign idsel = '0;   // not read: the Compact chip's PEs have no identifier copy
  end else begin : g_in_fast
    // The identifier bits of the shift register and a copy of them (de_chip idsel_i):
    // what the upstream chip's boundary register and its copy provide in an array
    // (de_chip_bound IdCopy). Each bit of both a kept process, or opt_merge folds them.
    logic [IdW-1:0] sh_in, idsel_q;
    assign sh_in = {sh_q[IdW-2:0], sin_i};
    always_ff @(posedge clk_i) sh_q[InW-1:IdW] <= sh_q[InW-2:IdW-1];
    for (genvar k = 0; k < IdW; k++) begin : g_id_bit
      (* keep *) always_ff @(posedge clk_i) sh_q[k]    <= sh_in[k];
      (* keep *) always_ff @(posedge clk_i) idsel_q[k] <= sh_in[k];
    end
    assign idsel = idsel_q;
  end

  de_chip #(.NumPe(NumPe), .CarryBug(CarryBug), .Compact(Compact), .RstW(RstW),
            .TieBypass(TieBypass), .InReg((Compact == 1) ? 0 : InReg)) u_chip (
    .clk_i,
    .rst_i      (rst_q),
    // id, data, pix_valid, pix from the shift register; de_chip does not use link_i.coll
    .link_i     ({sh_q[IdW-1:0], sh_q[DataLsb +: DataW], sh_q[PixVLsb], sh_q[PixLsb +: PixW],
                  1'b0}),
    .link_o,
    .blk1z_i    (blk1z_q),
    .blk1z_o    (),
    .idsel_i    (idsel),
    .idsel_o    (),
    .chain_ctl_i({cfg_mode_q, obs_load_q, obs_shift_q}),
    .chain_i    ({cfg_bit_q, obs_bit_q}),
    .chain_o,
    .bypass_o
  );

  assign out_vec = (NGrp * Grp)'({link_o.coll, bypass_o, link_o.pix, link_o.pix_valid,
                                  link_o.data, link_o.id});
  assign cfg_bit_o = chain_o.cfg;
  assign obs_bit_o = chain_o.obs;

  always_ff @(posedge clk_i) begin
    for (int g = 0; g < NGrp; g++) fold1_q[g] <= ^out_vec[g*Grp +: Grp];
    fold_q <= ^fold1_q;
  end
  assign fold_o = fold_q;
endmodule

`default_nettype wire
