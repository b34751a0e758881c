// Player of ONE colour, pixel clock domain (docs/board.md §4): takes the frame-store
// words that de_frame_fetch put into the colour's prefetch FIFO ({comp, window, word},
// exactly one end-of-line marker per line, VActive lines per frame) and feeds them
// through the prototype's input circuit (LUT + data mapper, rtl/proto/de_data_mapper.sv;
// the skew is inside de_array) into the display controller's instruction buffer of this
// colour, as the B408 frame store fed the prototype's pixel bus (§7.6.1):
//
//   prefetch FIFO (show-ahead)  ->  mapper (registered)  ->  FIFO  ->  wr_*_o
//
// A word is taken only when the small output FIFO has room for it and for the word in
// the mapper (credit), so nothing is dropped and it sustains one word per clock. The
// display controller counts end-of-line markers as lines from reset, wrapping at VActive
// (docs/display-controller.md §2.2); the player counts them the same way and reports a
// frame (frame_o) after the VActive-th. starve_o: the display controller found this
// colour's buffer late at a Refresh (dc_late_i rises: it discards the line) while the
// prefetch FIFO was empty: a late line for want of SDRAM data (the SDRAM side fell
// behind), as opposed to a line with more words than its window (overload).
`default_nettype none

module de_frame_player #(
  parameter int unsigned FifoDepth = 4      // a power of two, >= 4 for 1 word/clock
) (
  input  logic        clk_i,
  input  logic        rst_i,
  input  logic [11:0] vactive_i,            // quasi-static
  // Prefetch FIFO read side.
  input  logic        pf_valid_i,
  output logic        pf_ready_o,
  input  logic [35:0] pf_data_i,            // {comp, window[2:0], word[31:0]}
  // Display controller: this colour's y-processor write port.
  output logic        wr_valid_o,
  input  logic        wr_ready_i,
  output logic [47:0] wr_data_o,
  input  logic        dc_late_i,            // the display controller discards a late line
  // Status.
  output logic        frame_o,              // one clock after a frame's last marker
  output logic        starve_o
);
  if (FifoDepth < 4 || (FifoDepth & (FifoDepth - 1)) != 0) begin : g_bad_fifo
    $fatal(1, "de_frame_player: FifoDepth must be a power of two >= 4");
  end

  localparam int unsigned FW = $clog2(FifoDepth);

  logic        map_v;
  logic [11:0] map_id;
  logic [35:0] map_data;
  logic [47:0] fifo_q [FifoDepth];
  logic [FW:0] cnt_d, cnt_q;
  logic [FW-1:0] wp_d, wp_q, rp_d, rp_q;
  logic [11:0] lines_d, lines_q;
  logic        take, marker, push, pop, frame_d, frame_q;
  logic        late_q, starve_d, starve_q;

  // Credit: the FIFO entries plus the word in the mapper stage.
  assign take   = pf_valid_i &&
                  (({1'b0, cnt_q} + (FW + 2)'(map_v)) < (FW + 2)'(FifoDepth));
  assign marker = take && (pf_data_i[31:27] == 5'd1);

  always_comb begin
    lines_d   = lines_q;
    frame_d   = 1'b0;
    if (marker) begin
      if (lines_q + 12'd1 >= vactive_i) begin
        lines_d = 12'd0;
        frame_d = 1'b1;
      end else begin
        lines_d = lines_q + 12'd1;
      end
    end
    starve_d = dc_late_i && !late_q && !pf_valid_i;
  end

  de_data_mapper u_mapper (
    .clk_i,
    .rst_i,
    .valid_i     (take),
    .word_i      (pf_data_i[31:0]),
    .window_i    (pf_data_i[34:32]),
    .compensate_i(pf_data_i[35]),
    .valid_o     (map_v),
    .id_o        (map_id),
    .data_o      (map_data)
  );

  // FIFO (show-ahead) into the display controller's write port.
  assign push = map_v;
  assign pop  = wr_valid_o && wr_ready_i;

  always_comb begin
    wp_d  = push ? wp_q + FW'(1) : wp_q;
    rp_d  = pop ? rp_q + FW'(1) : rp_q;
    cnt_d = cnt_q + (FW + 1)'(push) - (FW + 1)'(pop);
  end

  always_ff @(posedge clk_i) begin
    if (push) fifo_q[wp_q] <= {map_id, map_data};
  end

  always_ff @(posedge clk_i) begin
    if (rst_i) begin
      cnt_q     <= '0;
      wp_q      <= '0;
      rp_q      <= '0;
      lines_q   <= 12'd0;
      frame_q   <= 1'b0;
      late_q    <= 1'b0;
      starve_q  <= 1'b0;
    end else begin
      cnt_q     <= cnt_d;
      wp_q      <= wp_d;
      rp_q      <= rp_d;
      lines_q   <= lines_d;
      frame_q   <= frame_d;
      late_q    <= dc_late_i;
      starve_q  <= starve_d;
    end
  end

  assign pf_ready_o = take;
  assign wr_valid_o = (cnt_q != '0);
  assign wr_data_o  = fifo_q[rp_q];
  assign frame_o    = frame_q;
  assign starve_o   = starve_q;
endmodule

`default_nettype wire
