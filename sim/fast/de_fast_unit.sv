// Fast simulation (docs/simulation.md, "The fast array"): one repeated piece of a de_array
// cut at the chips' boundary registers = the boundary register of chip c-1 followed by the
// core of chip c. Its bus and pixel inputs reach logic only through registers, so one
// compiled model serves every chip 1..NumChips-1 and its evaluation never depends
// combinationally on what another piece computes in the same cycle.
// Simulation wiring only: every register and gate comes from the RTL modules.
`default_nettype none

module de_fast_unit
  import de_pkg::*;
#(
  parameter int unsigned NumPe    = 9,
  parameter int unsigned CarryBug = 0
) (
  input  logic       clk_i,
  input  logic       rst_i,
  input  link_t      link_i,       // chip c-1's core outputs (combinational there), registered here
  output link_t      link_o,       // chip c's core outputs
  output logic       prev_coll_o,  // chip c-1's collision flag (its boundary register)
  input  chain_ctl_t chain_ctl_i,
  input  chain_t     chain_i,
  output chain_t     chain_o
);
  link_t b_link;
  logic  b_blk1z;
  // Timing only: with IdCopy = 0 the boundary passes its id register itself (the pieces
  // are built as de_chip with TimingCopies = 0, as the trace build's flat de_array is).
  logic [IdW-1:0] b_idsel;
  /* verilator lint_off UNUSEDSIGNAL */
  logic [NumPe-1:0] bypass;
  /* verilator lint_on UNUSEDSIGNAL */

  de_chip_bound #(.IdCopy(0)) u_bound (.clk_i, .rst_i, .link_i, .link_o(b_link),
                                       .blk1z_o(b_blk1z), .idsel_o(b_idsel));
  assign prev_coll_o = b_link.coll;

  de_chip_core #(.NumPe(NumPe), .CarryBug(CarryBug), .TimingCopies(0)) u_core (
    .clk_i, .rst_i, .link_o, .chain_ctl_i, .chain_i, .chain_o,
    .link_i     (b_link),
    .blk1z_i    (b_blk1z),
    .idsel_i    (b_idsel),
    .bypass_o   (bypass)
  );
endmodule

`default_nettype wire
