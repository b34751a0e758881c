// Difference Engine: the virtual x-processor array (docs/fpga.md, "Virtual array").
//
// A drop-in for de_array (same ports, same parameters, plus Fold and step_o) that
// builds NumChips*NumPe virtual columns from P = NumChips*NumPe/Fold physical PEs.
// Each physical PE serves Fold columns; their whole state (A-D, flags, the bus output
// registers, the control pipeline: de_pe's 236 flip-flops) lives in a Fold-deep delay
// line (distributed RAM), so every PE is a combinational de_vpe plus a state register.
//
// Timing model: clk_i is a core clock Fold times the slot (= pixel) rate. A "step" is
// Fold core cycles; in cycle k of a step (phase k) every physical PE p serves virtual
// column k*P + p (interleaved mapping). Within a phase the P PEs form an ordinary
// systolic chain (PE p reads PE p-1's output registers, which are the state of column
// k*P+p-1); PE 0 in phase k > 0 reads PE P-1's output of phase k-1 through a one-cycle
// hand-off register, i.e. column k*P-1 as it stood in the same step. So every virtual
// column sees exactly the input sequence of the plain array, step by step.
//
//   ident_i/data_i are sampled once per step, in the cycle with step_o = 1;
//   ident_o/data_o/pixel_valid_o/pixel_o change once per step, after that cycle's edge,
//   and hold for the Fold cycles of the step (one pixel per step: raster order, no gap).
//   Latency: the pixel of column q of a Refresh sampled in step s is on pixel_o during
//   step s + q + 4 (de_array: cycle t + q + NumChips + 2).
//
// Not in the virtual array: PE bypass (cfg chain is one flip-flop, the bits are ignored)
// and the observation chain (obs_bit_o = 0); FaultMask must be 0. Reset: rst_i clears
// the state of every column within Fold cycles (held internally), so one cycle suffices.
module de_varray
  import de_pkg::*;
#(
  parameter int unsigned NumChips  = 72,   // virtual columns = NumChips * NumPe
  parameter int unsigned CarryBug  = 0,
  parameter int unsigned NumPe     = 9,
  parameter logic [1023:0] FaultMask = '0,
  parameter int unsigned Fold      = 8     // columns per physical PE
) (
  input  logic             clk_i,
  input  logic             rst_i,
  input  logic [IdW-1:0]   ident_i,
  input  logic [DataW-1:0] data_i,
  output logic [IdW-1:0]   ident_o,
  output logic [DataW-1:0] data_o,
  output logic             pixel_valid_o,
  output logic [PixW-1:0]  pixel_o,
  output logic [15:0]      n_pe_o,
  output logic             pix_collision_o,
  input  logic             cfg_mode_i,
  input  logic             cfg_bit_i,
  output logic             cfg_bit_o,
  /* verilator lint_off UNUSEDSIGNAL */
  input  logic             obs_load_i,
  input  logic             obs_shift_i,
  /* verilator lint_on UNUSEDSIGNAL */
  output logic             obs_bit_o,
  output logic             step_o          // ident_i/data_i are sampled in this cycle
);
  localparam int unsigned NumCol = NumChips * NumPe;
  localparam int unsigned NumPhy = NumCol / (Fold < 1 ? 1 : Fold);
  localparam int unsigned StW    = 236;    // de_vpe's state (checked there)
  localparam int unsigned PhW    = Fold > 1 ? $clog2(Fold) : 1;
  localparam int unsigned WpW    = Fold > 2 ? $clog2(Fold - 1) : 1;

  if (NumChips < 1 || NumCol > 4096) begin : g_bad_size
    $fatal(1, "de_varray: NumChips*NumPe must be 1..4096, got %0d", NumCol);
  end
  if (Fold < 1 || Fold > 64 || NumCol % Fold != 0) begin : g_bad_fold
    $fatal(1, "de_varray: Fold must be 1..64 and divide NumChips*NumPe (%0d), got %0d",
           NumCol, Fold);
  end
  if (CarryBug > 1) begin : g_bad_carry_bug
    $fatal(1, "de_varray: CarryBug must be 0 or 1");
  end
  if (FaultMask != '0) begin : g_bad_fault_mask
    $fatal(1, "de_varray: no PE bypass, FaultMask must be 0");
  end

  // ---- phase and reset stretch ---------------------------------------------------------
  logic [PhW-1:0] ph_d, ph_q;
  logic [WpW-1:0] wp_d, wp_q;
  logic [PhW:0]   rcnt_d, rcnt_q;
  logic           rst_int, last;
  assign rst_int = rst_i || (rcnt_q != '0);
  assign last    = (ph_q == PhW'(Fold - 1));
  assign ph_d    = (rst_i || last) ? '0 : ph_q + 1'b1;
  assign wp_d    = (rst_i || wp_q == WpW'(Fold > 1 ? Fold - 2 : 0)) ? '0 : wp_q + 1'b1;
  assign rcnt_d  = (rcnt_q != '0) ? rcnt_q - 1'b1 : '0;
  assign step_o  = (ph_q == '0) && !rst_int;

  // ---- input skew (de_skew, advanced once per step) --------------------------------------
  logic [BlkW-1:0] sk1_d, sk1_q, sk2_d, sk2_q, sk3_d, sk3_q;
  assign sk1_d = ph_q == '0 ? data_i[2*BlkW-1:BlkW] : sk1_q;
  assign sk2_d = ph_q == '0 ? data_i[3*BlkW-1:2*BlkW] : sk2_q;
  assign sk3_d = ph_q == '0 ? sk2_q : sk3_q;

  // ---- physical PEs -----------------------------------------------------------------------
  logic [NumPhy:0][IdW-1:0]   bus_id;
  logic [NumPhy:0][DataW-1:0] bus_data;
  logic [NumPhy:0][PixW-1:0]  pix_or;
  logic [NumPhy:0]            pixv_or;
  logic [NumPhy-1:0]          coll;
  logic [IdW-1:0]             ho_id_d, ho_id_q;      // hand-off: PE P-1 -> PE 0
  logic [DataW-1:0]           ho_data_d, ho_data_q;

  assign bus_id[0]   = ph_q == '0 ? ident_i : ho_id_q;
  assign bus_data[0] = ph_q == '0 ? {sk3_q, sk1_q, data_i[BlkW-1:0]} : ho_data_q;
  assign pix_or[0]   = '0;
  assign pixv_or[0]  = 1'b0;
  assign ho_id_d     = bus_id[NumPhy];
  assign ho_data_d   = bus_data[NumPhy];

  for (genvar p = 0; p < NumPhy; p++) begin : g_pe
    logic [StW-1:0] st_q, st_next, st_d, st_old;
    logic           pe_pixv;
    logic [PixW-1:0] pe_pix;
    /* verilator lint_off UNUSEDSIGNAL */
    logic [DbgW-1:0] pe_dbg;
    /* verilator lint_on UNUSEDSIGNAL */

    de_vpe #(.CarryBug(CarryBug), .StW(StW)) u_pe (
      .st_i       (st_q),
      .st_o       (st_next),
      .id_i       (bus_id[p]),
      .data_i     (bus_data[p]),
      .id_o       (bus_id[p+1]),
      .data_o     (bus_data[p+1]),
      .pix_valid_o(pe_pixv),
      .pix_o      (pe_pix),
      .dbg_o      (pe_dbg)
    );
    assign st_d = rst_int ? '0 : st_next;

    // The other Fold-1 columns' states: a delay line, read before write at wp_q, so the
    // state written now comes back into st_q Fold cycles later (its column's next turn).
    if (Fold == 1) begin : g_direct
      assign st_old = st_d;
    end else begin : g_ram
      logic [StW-1:0] mem [Fold - 1];
      assign st_old = rst_int ? '0 : mem[wp_q];
      always_ff @(posedge clk_i) begin
        mem[wp_q] <= st_d;
      end
    end
    always_ff @(posedge clk_i) begin
      st_q <= st_old;
    end

    assign pix_or[p+1]  = pix_or[p] | (pe_pixv ? pe_pix : '0);
    assign pixv_or[p+1] = pixv_or[p] | pe_pixv;
    assign coll[p]      = pixv_or[p] && pe_pixv;
  end

  // ---- pixels: exactly one column emits per step (one Refresh active at a time) ------------
  logic            accv_d, accv_q, pixv_d, pixv_q, coll_d, coll_q;
  logic [PixW-1:0] acc_d, acc_q, pix_d, pix_q;
  logic            first;
  assign first  = (ph_q == '0);
  assign accv_d = rst_int ? 1'b0 : (first ? 1'b0 : accv_q) | pixv_or[NumPhy];
  assign acc_d  = rst_int ? '0 : (first ? '0 : acc_q) | pix_or[NumPhy];
  assign pixv_d = rst_int ? 1'b0 : (last ? accv_d : pixv_q);
  assign pix_d  = rst_int ? '0 : (last ? acc_d : pix_q);
  assign coll_d = !rst_i && (coll_q || (|coll) || (!first && accv_q && pixv_or[NumPhy]));

  // ---- bus output: column NumCol-1 (PE P-1 in the last phase), then de_deskew -------------
  logic [IdW-1:0]  oid_d, oid_q, oid2_d, oid2_q, oid3_d, oid3_q;
  logic [BlkW-1:0] ob0_d, ob0_q, ob0b_d, ob0b_q, ob0c_d, ob0c_q, ob1_d, ob1_q, ob1b_d, ob1b_q;
  logic [BlkW-1:0] ob2_d, ob2_q;
  assign oid_d  = last ? bus_id[NumPhy] : oid_q;
  assign ob0_d  = last ? bus_data[NumPhy][BlkW-1:0] : ob0_q;
  assign ob1_d  = last ? bus_data[NumPhy][2*BlkW-1:BlkW] : ob1_q;
  assign ob2_d  = last ? bus_data[NumPhy][3*BlkW-1:2*BlkW] : ob2_q;
  assign oid2_d = last ? oid_q : oid2_q;
  assign oid3_d = last ? oid2_q : oid3_q;
  assign ob0b_d = last ? ob0_q : ob0b_q;
  assign ob0c_d = last ? ob0b_q : ob0c_q;
  assign ob1b_d = last ? ob1_q : ob1b_q;

  logic cfg_d, cfg_q;
  assign cfg_d = cfg_mode_i ? cfg_bit_i : cfg_q;

  always_ff @(posedge clk_i) begin
    if (rst_i) begin
      ph_q      <= '0;
      wp_q      <= '0;
      rcnt_q    <= (PhW + 1)'(Fold - 1);   // clear the other Fold-1 states after rst_i
      sk1_q     <= '0;
      sk2_q     <= '0;
      sk3_q     <= '0;
      ho_id_q   <= '0;
      ho_data_q <= '0;
      accv_q    <= 1'b0;
      acc_q     <= '0;
      pixv_q    <= 1'b0;
      pix_q     <= '0;
      coll_q    <= 1'b0;
      oid_q     <= '0;
      oid2_q    <= '0;
      oid3_q    <= '0;
      ob0_q     <= '0;
      ob0b_q    <= '0;
      ob0c_q    <= '0;
      ob1_q     <= '0;
      ob1b_q    <= '0;
      ob2_q     <= '0;
      cfg_q     <= 1'b0;
    end else begin
      ph_q      <= ph_d;
      wp_q      <= wp_d;
      rcnt_q    <= rcnt_d;
      sk1_q     <= sk1_d;
      sk2_q     <= sk2_d;
      sk3_q     <= sk3_d;
      ho_id_q   <= ho_id_d;
      ho_data_q <= ho_data_d;
      accv_q    <= accv_d;
      acc_q     <= acc_d;
      pixv_q    <= pixv_d;
      pix_q     <= pix_d;
      coll_q    <= coll_d;
      oid_q     <= oid_d;
      oid2_q    <= oid2_d;
      oid3_q    <= oid3_d;
      ob0_q     <= ob0_d;
      ob0b_q    <= ob0b_d;
      ob0c_q    <= ob0c_d;
      ob1_q     <= ob1_d;
      ob1b_q    <= ob1b_d;
      ob2_q     <= ob2_d;
      cfg_q     <= cfg_d;
    end
  end

  assign ident_o         = oid3_q;
  assign data_o          = {ob2_q, ob1b_q, ob0c_q};
  assign pixel_valid_o   = pixv_q;
  assign pixel_o         = pix_q;
  assign n_pe_o          = 16'(NumCol);
  assign pix_collision_o = coll_q;
  assign cfg_bit_o       = cfg_q;
  assign obs_bit_o       = 1'b0;
endmodule
