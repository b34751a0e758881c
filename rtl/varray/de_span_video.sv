// Difference Engine: the span-serial array behind de_array's pixel-bus contract
// (docs/fpga.md, "Span-serial array", 3.5).
//
// clk_i is the pixel clock and carries the instruction bus exactly as de_array sees it
// (one slot per clock, unskewed); clk_core_i runs the span-serial array (de_span_array)
// at a multiple of it. Pixels leave on the pixel clock with a fixed latency, as from
// de_array: a Refresh on id_i in the cycle ending with edge E puts column q on
// pix_o right after edge E + Latency - 1 + q (de_array: Latency = NumChips + 3).
//
//   id_i/data_i ─► de_async_fifo ─► de_span_array ─► line buffer ─► read out Latency after
//   (pixel clock)     (to core)   (core clock)     (NumLineBuf     each Refresh, one
//                                                   lines)          column per pixel clock
//
// A line must be complete in the line buffer when its read-out starts (the count of
// completed lines crosses back in Gray code); if it is not, or a slot found the FIFO
// full, late_o / overflow_o rise and stay up until reset (late_o armed once the array is
// first idle after reset, below): the frame is then wrong, and
// Latency or the core clock is too small for the stream. Reset: rst_i (pixel domain),
// held for a few pixel clocks; the core side takes it through a synchroniser.
`default_nettype none

module de_span_video
  import de_pkg::*;
#(
  parameter int unsigned NumCols    = 648,
  parameter int unsigned MaxSlots   = 4,
  parameter int unsigned CarryBug   = 0,
  parameter int unsigned Latency    = 300,  // pixel clocks, Refresh -> column 0
  parameter int unsigned NumLineBuf = 4,
  parameter int unsigned FifoAw     = 8     // 256 slots between the clock domains
) (
  input  logic             clk_i,
  input  logic             rst_i,
  input  logic             clk_core_i,
  input  logic [IdW-1:0]   id_i,
  input  logic [DataW-1:0] data_i,
  output logic             pix_valid_o,
  output logic [PixW-1:0]  pix_o,
  output logic             late_o,
  output logic             overflow_o
);
  localparam int unsigned CA = NumCols > 1 ? $clog2(NumCols) : 1;
  localparam int unsigned LA = $clog2(NumLineBuf);
  localparam int unsigned DQ = NumLineBuf;   // Refreshes waiting for their read-out
  localparam int unsigned QW = $clog2(DQ) + 1;

  if (NumLineBuf != 2 && NumLineBuf != 4 && NumLineBuf != 8) begin : g_bad_nb
    $fatal(1, "de_span_video: NumLineBuf must be 2, 4 or 8");
  end
  // Refreshes are at least NumCols slots apart (isa.md 6). The drain of line k+NB-1 may
  // start that soon after Refresh k+NB-1 and overwrites line k's buffer, whose read-out
  // ends at Refresh k + Latency + NumCols; nor may more than DQ read-outs wait.
  if (Latency < 3 || Latency > (NumLineBuf - 2) * NumCols) begin : g_bad_latency
    $fatal(1, "de_span_video: Latency must be 3..(NumLineBuf-2) * NumCols, got %0d",
           Latency);
  end

  // ==== pixel clock: bus into the FIFO ====================================================
  logic fifo_full, ovf_d, ovf_q, is_refresh;
  assign is_refresh = id_i[IdRefreshBit];

  logic rst_c1_q, rst_c2_q;                  // rst_i synchronised to the core clock
  logic              fvalid, fready, cready;
  logic [IdW+DataW-1:0] fword;
  // A two-entry skid buffer between the FIFO and the array: the FIFO's read (block
  // RAM) ends in a register, and the FIFO's read enable depends on the buffer's count
  // only, not on the array's ready (its front-end decode).
  logic              cvalid;
  logic [IdW+DataW-1:0] cword;

  // The board's dual-clock FIFO (rtl/prim): 2^FifoAw words of block RAM with a registered
  // show-ahead read. The bus writes every clock; full only raises the sticky overflow.
  logic fifo_wready;
  /* verilator lint_off UNUSEDSIGNAL */  // free count: the bus cannot wait, full is an error
  logic [FifoAw:0] fifo_wfree;
  /* verilator lint_on UNUSEDSIGNAL */
  de_async_fifo #(.Width(IdW + DataW), .Depth(1 << FifoAw)) u_fifo (
    .wclk_i  (clk_i),
    .wrst_i  (rst_i),
    .wvalid_i(!rst_i),
    .wready_o(fifo_wready),
    .wdata_i ({id_i, data_i}),
    .wfree_o (fifo_wfree),
    .rclk_i  (clk_core_i),
    .rrst_i  (rst_c2_q),
    .rvalid_o(fvalid),
    .rready_i(fready),
    .rdata_o (fword)
  );
  assign fifo_full = !fifo_wready;
  de_skid #(.W(IdW + DataW)) u_skid (
    .clk_i  (clk_core_i),
    .rst_i  (rst_c2_q),
    .valid_i(fvalid),
    .ready_o(fready),
    .data_i (fword),
    .valid_o(cvalid),
    .ready_i(cready),
    .data_o (cword)
  );
  assign ovf_d = ovf_q || fifo_full;

  // ==== core clock: the array and the line buffer writes ==================================
  logic            cpix_valid, cbusy;
  logic [PixW-1:0] cpix;
  logic [11:0]     cpix_col;
  logic [2:0]      wline_d, wline_q, wgray_q;   // completed lines (mod 8), Gray copy

  de_span_array #(.NumCols(NumCols), .MaxSlots(MaxSlots), .CarryBug(CarryBug)) u_span (
    .clk_i        (clk_core_i),
    .rst_i        (rst_c2_q),
    .instr_valid_i(cvalid),
    .instr_ready_o(cready),
    .id_i         (cword[IdW+DataW-1 -: IdW]),
    .data_i       (cword[DataW-1:0]),
    .pix_valid_o  (cpix_valid),
    .pix_o        (cpix),
    .pix_col_o    (cpix_col),
    .busy_o       (cbusy)
  );

  logic [PixW-1:0] lbuf [NumLineBuf << CA];
  logic lb_we, lb_last;
  assign lb_we   = cpix_valid;
  assign lb_last = cpix_valid && (cpix_col == 12'(NumCols - 1));
  assign wline_d = wline_q + 3'(lb_last);

  always_ff @(posedge clk_core_i) begin
    if (lb_we) begin
      lbuf[{wline_q[LA-1:0], CA'(cpix_col)}] <= cpix;
    end
  end

  // Armed the first time the array is idle after reset. Its reset sweep (2 x NumCols core
  // clocks) and the lines queued during it can outlast Latency, so a read-out before then
  // is not a late line of the picture (it falls in the blanking after reset); counting it
  // would leave late_o up on every board from reset on and hide a real late line.
  logic armed_c_d, armed_c_q;
  assign armed_c_d = armed_c_q || !cbusy;

  always_ff @(posedge clk_core_i) begin
    rst_c1_q <= rst_i;
    rst_c2_q <= rst_c1_q;
    if (rst_c2_q) begin
      wline_q   <= '0;
      wgray_q   <= '0;
      armed_c_q <= 1'b0;
    end else begin
      wline_q   <= wline_d;
      wgray_q   <= wline_d ^ (wline_d >> 1);
      armed_c_q <= armed_c_d;
    end
  end

  // ==== pixel clock: read-out Latency after each Refresh ===================================
  logic [15:0] t_d, t_q;                     // free-running pixel clock count
  logic [15:0] due_q [DQ];                   // read-out start times, oldest first
  logic [15:0] due_d [DQ];
  logic [QW-1:0] ndue_d, ndue_q;
  logic        rd_d, rd_q, pixv_q;
  logic [CA-1:0] rcol_d, rcol_q;
  logic [2:0]  rline_d, rline_q;
  logic [2:0]  dgray1_q, dgray2_q, done;     // completed lines, crossed from the core
  logic        late_d, late_q;
  logic        arm1_q, arm2_q;               // armed_c_q crossed to the pixel clock (a level)
  logic [PixW-1:0] pix_q;
  logic        start;

  // Gray to binary for the 3-bit completed-lines count.
  assign done  = {dgray2_q[2], dgray2_q[2] ^ dgray2_q[1],
                  dgray2_q[2] ^ dgray2_q[1] ^ dgray2_q[0]};
  assign start = (ndue_q != '0) && (due_q[0] == t_q);

  always_comb begin
    t_d     = t_q + 16'd1;
    due_d   = due_q;
    ndue_d  = ndue_q;
    rd_d    = rd_q;
    rcol_d  = rcol_q;
    rline_d = rline_q;
    late_d  = late_q;
    if (start) begin
      for (int i = 0; i < DQ - 1; i++) begin
        due_d[i] = due_q[i + 1];
      end
      ndue_d = ndue_q - QW'(1);
      rd_d   = 1'b1;
      rcol_d = '0;
      // The line must be complete (one more completed line than read out).
      if (arm2_q && done == rline_q) begin
        late_d = 1'b1;
      end
    end else if (rd_q) begin
      rcol_d = rcol_q + 1'b1;
      if (rcol_q == CA'(NumCols - 1)) begin
        rd_d    = 1'b0;
        rline_d = rline_q + 3'd1;
      end
    end
    if (is_refresh) begin
      // Column 0 two clocks after the start (read, then the output register).
      if (ndue_d < QW'(DQ)) begin
        due_d[ndue_d[QW-2:0]] = t_q + 16'(Latency - 2);
        ndue_d = ndue_d + QW'(1);
      end else begin
        late_d = 1'b1;
      end
    end
  end

  always_ff @(posedge clk_i) begin
    if (rd_q) begin
      pix_q <= lbuf[{rline_q[LA-1:0], rcol_q}];
    end else begin
      pix_q <= '0;
    end
  end

  always_ff @(posedge clk_i) begin
    if (rst_i) begin
      t_q      <= '0;
      ndue_q   <= '0;
      rd_q     <= 1'b0;
      pixv_q   <= 1'b0;
      rcol_q   <= '0;
      rline_q  <= '0;
      late_q   <= 1'b0;
      arm1_q   <= 1'b0;
      arm2_q   <= 1'b0;
      ovf_q    <= 1'b0;
      dgray1_q <= '0;
      dgray2_q <= '0;
      for (int i = 0; i < DQ; i++) begin
        due_q[i] <= '0;
      end
    end else begin
      t_q      <= t_d;
      ndue_q   <= ndue_d;
      rd_q     <= rd_d;
      pixv_q   <= rd_q;
      rcol_q   <= rcol_d;
      rline_q  <= rline_d;
      late_q   <= late_d;
      arm1_q   <= armed_c_q;
      arm2_q   <= arm1_q;
      ovf_q    <= ovf_d;
      dgray1_q <= wgray_q;
      dgray2_q <= dgray1_q;
      due_q    <= due_d;
    end
  end

  assign pix_valid_o   = pixv_q;
  assign pix_o         = pix_q;
  assign late_o        = late_q;
  assign overflow_o    = ovf_q;

  // The array's own busy flag is for benches; the column of a pixel is its position.
endmodule

`default_nettype wire
