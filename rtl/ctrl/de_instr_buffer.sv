// Difference Engine - Instruction Buffer (Kuijk 1995, §7.5; design in docs/display-controller.md).
//
// One per y-processor. A FIFO of 48-bit instructions ({12-bit identifier, 36-bit data})
// written by the y-processor at its own rate and read onto the instruction bus at one
// instruction per clock when the Access Controller grants it.
//
// Single clock domain: the y-processor writes through a synchronous ready/valid port
// clocked by the pixel clock (a y-processor on its own clock needs a CDC FIFO in front).
//
// Commit gating: the bus may only carry whole commands (isa.md §2: "slots of one
// command are contiguous"), so the read side only offers entries that are known to be
// complete. An instruction whose identifier has neither the DATA (bit 10) nor the ACC
// (bit 9) bit set starts a command; writing it proves that everything before it is
// complete. A Refresh identifier (0x100) written by the y-processor is the end-of-line
// marker and commits itself and everything before it.
//
// Progress: the uncommitted tail is at most one command (MaxCmdLen slots, 10 for Eval8),
// so Depth > MaxCmdLen guarantees that a full buffer always has a committed head.
// drain_i (used by the Access Controller to discard a late line) also offers the
// uncommitted tail, so even a malformed stream cannot wedge the buffer.
`default_nettype none

module de_instr_buffer #(
  parameter int unsigned Depth     = 16,
  parameter int unsigned MaxCmdLen = 10
) (
  input  logic                       clk_i,
  input  logic                       rst_i,
  // Write side (y-processor).
  input  logic                       wr_valid_i,
  output logic                       wr_ready_o,
  input  logic [de_pkg::RecW-1:0]                wr_data_i,
  // Read side (instruction bus, via the Access Controller).
  output logic                       rd_valid_o,
  input  logic                       rd_ready_i,
  input  logic                       drain_i,
  output logic [de_pkg::RecW-1:0]                rd_data_o,
  // Status.
  output logic                       full_o,
  output logic                       empty_o,
  output logic [$clog2(Depth):0]     level_o,
  output logic [$clog2(Depth):0]     committed_o
);

  localparam int unsigned AW = $clog2(Depth);

  // Parameter checks at elaboration.
  if (Depth < 2) begin : g_bad_depth_small
    $fatal(1, "de_instr_buffer: Depth must be >= 2");
  end
  if ((1 << AW) != Depth) begin : g_bad_depth_pow2
    $fatal(1, "de_instr_buffer: Depth must be a power of two");
  end
  if (Depth <= MaxCmdLen) begin : g_bad_depth_cmd
    $fatal(1, "de_instr_buffer: Depth must exceed MaxCmdLen (a whole command plus one)");
  end

  // Pointers carry one extra wrap bit so that full and empty are distinguishable.
  logic [AW:0]              wr_ptr_d, wr_ptr_q;
  logic [AW:0]              rd_ptr_d, rd_ptr_q;
  logic [AW:0]              cm_ptr_d, cm_ptr_q;
  // Storage in the memory idiom (unpacked array, one synchronous write port, read by
  // index) so that FPGA synthesis maps it to distributed RAM: as a _d/_q packed array it
  // became 768 flip-flops and a 48-bit read mux, ~3,500 LUT4 per buffer on ECP5
  // (docs/display-controller.md §9.7).
  logic [de_pkg::RecW-1:0]              mem_q [Depth];
  logic                     mem_we;
  logic [AW-1:0]            mem_wa;

  logic        wr_fire, rd_fire;
  logic [de_pkg::IdW-1:0] wr_id;
  logic        wr_is_start, wr_is_marker;
  logic [AW:0] level, committed;

  assign wr_id        = de_pkg::rec_id(wr_data_i);
  assign wr_is_start  = de_pkg::id_starts_cmd(wr_id);
  assign wr_is_marker = (wr_id == de_pkg::IdRefresh);

  assign level       = wr_ptr_q - rd_ptr_q;
  assign committed   = cm_ptr_q - rd_ptr_q;
  assign full_o      = (level == (AW + 1)'(Depth));
  assign empty_o     = (level == '0);
  assign level_o     = level;
  assign committed_o = committed;

  assign wr_ready_o = ~full_o;
  assign rd_valid_o = drain_i ? ~empty_o : (committed != '0);
  assign rd_data_o  = mem_q[rd_ptr_q[AW-1:0]];

  assign wr_fire = wr_valid_i & wr_ready_o;
  assign rd_fire = rd_valid_o & rd_ready_i;

  always_comb begin
    wr_ptr_d = wr_ptr_q;
    rd_ptr_d = rd_ptr_q;
    cm_ptr_d = cm_ptr_q;
    if (wr_fire) begin
      wr_ptr_d = wr_ptr_q + 1'b1;
      if (wr_is_marker) begin
        cm_ptr_d = wr_ptr_q + 1'b1;
      end else if (wr_is_start) begin
        cm_ptr_d = wr_ptr_q;
      end
    end
    if (rd_fire) begin
      rd_ptr_d = rd_ptr_q + 1'b1;
      // A drained uncommitted entry drags the commit point along (wr commits are always
      // beyond it, so they take precedence).
      if (committed == '0 && !(wr_fire && (wr_is_marker || wr_is_start))) begin
        cm_ptr_d = rd_ptr_q + 1'b1;
      end
    end
  end

  always_ff @(posedge clk_i) begin
    if (rst_i) begin
      wr_ptr_q <= '0;
      rd_ptr_q <= '0;
      cm_ptr_q <= '0;
    end else begin
      wr_ptr_q <= wr_ptr_d;
      rd_ptr_q <= rd_ptr_d;
      cm_ptr_q <= cm_ptr_d;
    end
  end

  assign mem_we = wr_fire;
  assign mem_wa = wr_ptr_q[AW-1:0];

  // Storage is not reset: every entry is qualified by the pointers. The write-enabled
  // indexed store is the one exception to "always_ff only assigns q <= d" (docs/style.md):
  // it is the idiom synthesis tools recognise as RAM.
  always_ff @(posedge clk_i) begin
    if (mem_we) begin
      mem_q[mem_wa] <= wr_data_i;
    end
  end

`ifdef FORMAL
  // Properties proven by tb/formal/de_instr_buffer.sby (k-induction). The environment
  // writes a running sequence number (modulo 2^FW, FW = AW + 2 > log2 of the largest
  // level, so a lost or repeated word cannot alias) into the low data bits and arbitrary
  // identifiers, so the commit logic sees every identifier pattern; the n-th word read
  // must carry sequence number n and the identifier that was written with it (tracked
  // for one arbitrary word k).
  localparam int unsigned FW = AW + 2;
  logic        f_past_valid = 1'b0;
  logic [FW-1:0] f_wr_cnt, f_rd_cnt;
  (* anyconst *) logic [FW-1:0] f_k;
  logic [11:0] f_k_id;
  logic        f_k_seen;

  always_ff @(posedge clk_i) begin
    f_past_valid <= 1'b1;
    if (rst_i) begin
      f_wr_cnt <= '0;
      f_rd_cnt <= '0;
      f_k_seen <= 1'b0;
    end else begin
      if (wr_fire) f_wr_cnt <= f_wr_cnt + 1'b1;
      if (rd_fire) f_rd_cnt <= f_rd_cnt + 1'b1;
      if (wr_fire && f_wr_cnt == f_k) begin
        f_k_id   <= wr_id;
        f_k_seen <= 1'b1;
      end
    end
  end

  always_comb begin
    if (!f_past_valid) assume (rst_i);
    assume (wr_data_i[FW-1:0] == f_wr_cnt);
  end

  logic [FW-1:0] f_k_off;
  assign f_k_off = f_k - f_rd_cnt;

  always_comb begin
    if (f_past_valid && !rst_i) begin
      // Pointer invariants.
      assert (level <= (AW + 1)'(Depth));
      assert (committed <= level);
      assert (f_wr_cnt - f_rd_cnt == FW'(level));
      // No loss, duplication or reordering: reads return 0, 1, 2, ... in order.
      if (rd_valid_o) assert (rd_data_o[FW-1:0] == f_rd_cnt);
      // The tracked word k keeps its identifier.
      if (rd_fire && f_rd_cnt == f_k) assert (f_k_seen && de_pkg::rec_id(rd_data_o) == f_k_id);
      // Inductive strengthening: the stored words are consecutive sequence numbers.
      for (int unsigned i = 0; i < Depth; i++) begin
        if (i < level) begin
          assert (mem_q[AW'(rd_ptr_q[AW-1:0] + AW'(i))][FW-1:0] == f_rd_cnt + FW'(i));
        end
      end
      if (f_k_seen && f_k_off < FW'(level)) begin
        assert (de_pkg::rec_id(mem_q[AW'(rd_ptr_q[AW-1:0] + AW'(f_k_off))]) == f_k_id);
      end
      // Word k cannot be in the buffer before it has been written.
      if (!f_k_seen) assert (f_k_off >= FW'(level));
    end
  end
`endif

endmodule

`default_nettype wire
