// Difference Engine - Load Monitor (Kuijk 1995 §7.5; design and register map in
// docs/display-controller.md §6).
//
// Watches the Access Controller's event outputs (all registered with instr_o) and keeps:
// * per line: instructions issued in the line's window, free (Nop) slots left, and which
//   buffers were late (had not delivered their whole line when the Refresh went);
// * per frame (snapshot taken at the Refresh of the last active line): totals, number of
//   late lines, instructions discarded, maximum per line and a histogram of
//   instructions per line (NumBins bins of 2^BinShift, the last bin open-ended);
// * cumulative discard and late-line counters.
// The host reads 32-bit registers through a synchronous read port (data one clock after
// the address).
`default_nettype none

module de_load_monitor #(
  parameter int unsigned NumBuf   = 4,
  parameter int unsigned NumBins  = 16,
  parameter int unsigned BinShift = 7,
  parameter int unsigned MaxLines = 1024
) (
  input  logic              clk_i,
  input  logic              rst_i,
  // Events from de_access_ctrl.
  input  logic              ev_refresh_i,
  input  logic              ev_line_active_i,
  input  logic [11:0]       ev_line_i,
  input  logic              ev_last_line_i,
  input  logic [NumBuf-1:0] ev_late_i,
  input  logic              ev_issue_i,
  input  logic              ev_free_i,
  input  logic [NumBuf-1:0] drop_i,
  // Host register read port.
  input  logic [11:0]       reg_addr_i,
  output logic [31:0]       reg_rdata_o
);

  localparam int unsigned LineAw = (MaxLines > 1) ? $clog2(MaxLines) : 1;

  // Parameter checks at elaboration.
  if (NumBuf < 1 || NumBuf > 8) begin : g_bad_numbuf
    $fatal(1, "de_load_monitor: NumBuf must be 1..8");
  end
  if (NumBins < 1 || NumBins > 64) begin : g_bad_bins
    $fatal(1, "de_load_monitor: NumBins must be 1..64");
  end
  if (BinShift > 11) begin : g_bad_shift
    $fatal(1, "de_load_monitor: BinShift must be 0..11");
  end
  if (MaxLines < 1 || MaxLines > 1024) begin : g_bad_lines
    $fatal(1, "de_load_monitor: MaxLines must be 1..1024 (register window 0x400-0x7FF)");
  end

  // Number of set bits of a buffer vector (at most 8).
  function automatic logic [3:0] popcount(logic [NumBuf-1:0] x);
    popcount = '0;
    for (int unsigned i = 0; i < NumBuf; i++) popcount = popcount + 4'(x[i]);
  endfunction

  // ---------------------------------------------------------------------------------
  // Current line window.
  logic [11:0] ln_issued_d, ln_issued_q, ln_free_d, ln_free_q;
  // A frame's statistics: accumulated live (fr_) and published at its last line (sn_,
  // what the host reads).
  typedef struct packed {
    logic [31:0]              issued;
    logic [31:0]              free;
    logic [31:0]              drop;
    logic [15:0]              late;   // late lines
    logic [11:0]              max;    // most instructions in one line
    logic [NumBins-1:0][15:0] hist;   // lines per bin of instructions per line
  } frame_stats_t;
  frame_stats_t fr_d, fr_q, sn_d, sn_q;
  // Cumulative.
  logic [31:0] frames_d, frames_q, tot_drop_d, tot_drop_q, tot_late_d, tot_late_q;
  logic [11:0] last_line_d, last_line_q;
  logic [31:0] last_rec_d, last_rec_q;

  logic [3:0]  n_late, n_drop;
  logic        line_late, rec_we;
  logic [31:0] rec;
  logic [11:0] bin_raw;
  logic [5:0]  bin;

  assign n_late    = popcount(ev_late_i);
  assign n_drop    = popcount(drop_i);
  assign line_late = (n_late != 4'd0);
  assign rec_we    = ev_refresh_i & ev_line_active_i;
  // Record: [31] late, [30:28] 0, [27:24] late buffers, [23:12] free, [11:0] issued.
  assign rec       = {line_late, 3'b000, n_late, ln_free_q, ln_issued_q};
  assign bin_raw   = ln_issued_q >> BinShift;
  // The last bin collects everything at or above its lower edge.
  assign bin       = (bin_raw >= 12'(NumBins)) ? 6'(NumBins - 1) : bin_raw[5:0];

  always_comb begin
    ln_issued_d = ln_issued_q + 12'(ev_issue_i);
    ln_free_d   = ln_free_q + 12'(ev_free_i);
    fr_d        = fr_q;
    fr_d.drop   = fr_q.drop + 32'(n_drop);
    sn_d        = sn_q;
    frames_d    = frames_q;
    tot_drop_d  = tot_drop_q + 32'(n_drop);
    tot_late_d  = tot_late_q;
    last_line_d = last_line_q;
    last_rec_d  = last_rec_q;
    if (ev_refresh_i) begin
      // The Refresh slot itself is neither issued nor free: the next window starts now.
      ln_issued_d = '0;
      ln_free_d   = '0;
    end
    if (rec_we) begin
      fr_d.issued    = fr_q.issued + 32'(ln_issued_q);
      fr_d.free      = fr_q.free + 32'(ln_free_q);
      fr_d.late      = fr_q.late + 16'(line_late);
      tot_late_d     = tot_late_q + 32'(line_late);
      fr_d.max       = (ln_issued_q > fr_q.max) ? ln_issued_q : fr_q.max;
      fr_d.hist[bin] = fr_q.hist[bin] + 16'd1;
      last_line_d = ev_line_i;
      last_rec_d  = rec;
    end
    if (ev_last_line_i) begin
      // Frame done: publish everything including this line and this cycle's discards.
      sn_d     = fr_d;
      frames_d = frames_q + 32'd1;
      fr_d     = '0;
    end
  end

  always_ff @(posedge clk_i) begin
    if (rst_i) begin
      ln_issued_q <= '0;
      ln_free_q   <= '0;
      fr_q        <= '0;
      sn_q        <= '0;
      frames_q    <= '0;
      tot_drop_q  <= '0;
      tot_late_q  <= '0;
      last_line_q <= '0;
      last_rec_q  <= '0;
    end else begin
      ln_issued_q <= ln_issued_d;
      ln_free_q   <= ln_free_d;
      fr_q        <= fr_d;
      sn_q        <= sn_d;
      frames_q    <= frames_d;
      tot_drop_q  <= tot_drop_d;
      tot_late_q  <= tot_late_d;
      last_line_q <= last_line_d;
      last_rec_q  <= last_rec_d;
    end
  end

  // ---------------------------------------------------------------------------------
  // Per-line table: a simple dual-port RAM (write at the Refresh, synchronous read by
  // the host). Written in the memory-inference idiom rather than as a _d/_q pair so that
  // synthesis maps it to block RAM; entries are not reset (reads of lines not yet shown
  // return whatever the RAM holds).
  logic [31:0] line_ram [MaxLines];
  logic [31:0] line_rd_q;
  logic        line_we;

  assign line_we = rec_we && (32'(ev_line_i) < MaxLines);

  always_ff @(posedge clk_i) begin
    if (line_we) line_ram[ev_line_i[LineAw-1:0]] <= rec;
    line_rd_q <= line_ram[reg_addr_i[LineAw-1:0]];
  end

  // ---------------------------------------------------------------------------------
  // Register read port (map in docs/display-controller.md §6).
  logic [31:0] rdata_d, rdata_q;
  logic        sel_line_q;
  logic        sel_line_d;

  always_comb begin
    rdata_d    = 32'h0;
    sel_line_d = 1'b0;
    // The windows of spec/regs.toml: LINE[] (1024 entries), HIST[] (64 entries).
    if (reg_addr_i[11:10] == de_pkg::LmLineBase[11:10]) begin
      sel_line_d = (32'(reg_addr_i[9:0]) < MaxLines);
    end else if (reg_addr_i[11:6] == de_pkg::LmHistBase[11:6]) begin
      if (32'(reg_addr_i[5:0]) < NumBins) rdata_d = {16'h0, sn_q.hist[reg_addr_i[5:0]]};
    end else begin
      unique case (reg_addr_i)
        de_pkg::LmRegId:        rdata_d = {de_pkg::LmIdMagic, 8'(NumBins), 4'(BinShift), 4'(NumBuf),
                                           8'h01};
        de_pkg::LmRegFrames:    rdata_d = frames_q;
        de_pkg::LmRegIssued:    rdata_d = sn_q.issued;
        de_pkg::LmRegFree:      rdata_d = sn_q.free;
        de_pkg::LmRegLate:      rdata_d = {16'h0, sn_q.late};
        de_pkg::LmRegDrop:      rdata_d = sn_q.drop;
        de_pkg::LmRegMaxIssued: rdata_d = {20'h0, sn_q.max};
        de_pkg::LmRegLastLine:  rdata_d = {20'h0, last_line_q};
        de_pkg::LmRegLastRec:   rdata_d = last_rec_q;
        de_pkg::LmRegTotalDrop: rdata_d = tot_drop_q;
        de_pkg::LmRegTotalLate: rdata_d = tot_late_q;
        default: rdata_d = 32'h0;
      endcase
    end
  end

  always_ff @(posedge clk_i) begin
    if (rst_i) begin
      rdata_q    <= '0;
      sel_line_q <= 1'b0;
    end else begin
      rdata_q    <= rdata_d;
      sel_line_q <= sel_line_d;
    end
  end

  assign reg_rdata_o = sel_line_q ? line_rd_q : rdata_q;

endmodule

`default_nettype wire
