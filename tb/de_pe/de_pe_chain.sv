// Testbench wrapper: N de_pe in a chain behind the input skew, every PE's state exposed.
//
// The driver feeds one instruction per clock in unskewed form (id + 36-bit data, like
// sw/diffengine/model/structural.py Array.step); the skew registers here delay block 1 by one
// and block 2 by two cycles, as the array top's input skew will.

module de_pe_chain
  import de_pkg::*;
#(
  parameter int unsigned N        = 9,
  parameter int unsigned CarryBug = 0,
  // de_pe Compact (1: the iCE40 form); the fast form (0) also takes the identifier copy
  // (de_pe IdCopy = 1, idsel_i/idsel_o chained as in de_chip).
  parameter int unsigned Compact  = 0,
  parameter int unsigned InReg    = 0   // de_pe InReg: each PE registers its input
) (
  input  logic               clk_i,
  input  logic               rst_i,
  input  logic [IdW-1:0]     id_i,
  input  logic [DataW-1:0]   data_i,       // unskewed
  output logic [IdW-1:0]     id_o,         // last PE's outputs (still skewed)
  output logic [DataW-1:0]   data_o,
  output logic [N-1:0]       pix_valid_o,  // per PE
  output logic [N*PixW-1:0]  pix_o,        // PE p at [p*PixW +: PixW]
  output logic [N*DbgW-1:0]  dbg_o         // PE p at [p*DbgW +: DbgW]
);

  if (N < 1) begin : g_bad_n
    $fatal(1, "de_pe_chain: N must be >= 1");
  end

  // ---- input skew ----------------------------------------------------------------------
  logic [BlkW-1:0] sk1_d, sk1_q, sk2a_d, sk2a_q, sk2b_d, sk2b_q;
  logic sk1z_q;  // sk1_q is zero, registered (de_pe blk1z_i of PE 0)
  assign sk1_d  = data_i[BlkW +: BlkW];
  assign sk2a_d = data_i[2*BlkW +: BlkW];
  assign sk2b_d = sk2a_q;

  // Synchronous reset, like de_pe.
  always_ff @(posedge clk_i) begin
    if (rst_i) begin
      sk1_q  <= '0;
      sk2a_q <= '0;
      sk2b_q <= '0;
      sk1z_q <= 1'b1;
    end else begin
      sk1_q  <= sk1_d;
      sk2a_q <= sk2a_d;
      sk2b_q <= sk2b_d;
      sk1z_q <= (sk1_d == '0);
    end
  end

  // ---- the chain -----------------------------------------------------------------------
  logic [N:0][IdW-1:0]   id_link;
  logic [N:0][DataW-1:0] data_link;
  logic [N:0]            blk1z_link;
  logic [N:0][IdW-1:0]   idsel_link;
  assign id_link[0]   = id_i;
  assign idsel_link[0] = id_i;
  assign data_link[0] = {sk2b_q, sk1_q, data_i[BlkW-1:0]};
  assign blk1z_link[0] = sk1z_q;

  for (genvar p = 0; p < N; p++) begin : g_pe
    de_pe #(
      .CarryBug(CarryBug),
      .Compact (Compact),
      .IdCopy  ((Compact == 1 || InReg == 1) ? 0 : 1),
      .InReg   (InReg)
    ) u_pe (
      .clk_i,
      .rst_i,
      .id_i       (id_link[p]),
      .data_i     (data_link[p]),
      .blk1z_i    (blk1z_link[p]),
      .idsel_i    (idsel_link[p]),
      .id_o       (id_link[p+1]),
      .data_o     (data_link[p+1]),
      .blk1z_o    (blk1z_link[p+1]),
      .idsel_o    (idsel_link[p+1]),
      .pix_valid_o(pix_valid_o[p]),
      .pix_o      (pix_o[p*PixW +: PixW]),
      .dbg_o      (dbg_o[p*DbgW +: DbgW])
    );
  end

  assign id_o   = id_link[N];
  assign data_o = data_link[N];

endmodule
