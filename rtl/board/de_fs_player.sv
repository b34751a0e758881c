// Frame store and player of ONE colour (docs/board.md §4, §5).
//
// The frame store is a block RAM of FsDepth 32-bit words in the prototype's encoding
// (docs/formats.md §3: [31:27] LUT code, [26:0] operand), written by the UART loader.
// The player plays the colour's image - FsLen words from FsBase - once per video frame,
// as the B408 frame store fed the prototype's pixel bus (§7.6.1), through the input
// circuit (LUT + data mapper, rtl/proto/de_data_mapper.sv; the skew is inside de_array)
// into the display controller's instruction buffer of this colour:
//
//   issue (address)  ->  s1 (BRAM data)  ->  mapper (registered)  ->  FIFO  ->  wr_*_o
//
// Frames stay aligned with the display controller's line count, whatever the image
// holds: the buffer counts end-of-line markers (a REFRESH word, LUT code 1) as lines
// from reset, wrapping at VActive (docs/display-controller.md §2.2), so the player writes
// exactly vactive_i markers per frame: it counts the markers it plays, restarts the image
// after the vactive_i-th (words after it are never played), and pads with markers when
// the image ends early. An empty image (FsLen 0, the state after reset) is a black frame.
//
// A new image descriptor (base, length, window, compensation) from the loader waits in
// a pending register and takes effect when the player starts its next frame, so a frame
// is never a mixture of two descriptors (double-buffer by loading the new image at
// another base). A read issued in the cycle the player restarts belongs to the old frame
// and is dropped (one-bit epoch tag).
//
// Flow control: a read is issued only when the FIFO has room for it and for every word
// already in flight (credit check), so the FIFO never overflows and the player sustains
// one word per clock.
`default_nettype none

module de_fs_player #(
  parameter int unsigned FsDepth   = 1024,   // words, a power of two
  parameter int unsigned FifoDepth = 4,      // a power of two, >= 4 for 1 word/clock
  localparam int unsigned AW = $clog2(FsDepth)
) (
  input  logic          clk_i,
  input  logic          rst_i,
  // Loader: frame-store write port.
  input  logic          fs_we_i,
  input  logic [AW-1:0] fs_addr_i,
  input  logic [31:0]   fs_wdata_i,
  // Loader: new descriptor (takes effect at the next frame start).
  input  logic          desc_set_i,
  input  logic [15:0]   desc_base_i,
  input  logic [15:0]   desc_len_i,
  input  logic [2:0]    desc_window_i,
  input  logic          desc_comp_i,
  input  logic [11:0]   vactive_i,        // active lines of the video mode (quasi-static)
  // Display controller: this colour's y-processor write port.
  output logic          wr_valid_o,
  input  logic          wr_ready_i,
  output logic [47:0]   wr_data_o,
  // Status.
  output logic          frame_o,          // one clock when a frame's last marker is played
  output logic          pending_o         // a descriptor is waiting for the next frame
);
  if (FsDepth < 2 || FsDepth > 65536 || (FsDepth & (FsDepth - 1)) != 0) begin : g_bad_depth
    $fatal(1, "de_fs_player: FsDepth must be a power of two, 2..65536");
  end
  if (FifoDepth < 4 || (FifoDepth & (FifoDepth - 1)) != 0) begin : g_bad_fifo
    $fatal(1, "de_fs_player: FifoDepth must be a power of two >= 4");
  end

  localparam logic [31:0] MarkerWord = 32'h0800_0000;   // LUT code 1 = REFRESH
  localparam int unsigned FW = $clog2(FifoDepth);

  // ---------------------------------------------------------------- frame store (BRAM)
  logic [31:0]   mem_q [FsDepth];
  logic [AW-1:0] rd_addr;
  logic [31:0]   rd_q;

  always_ff @(posedge clk_i) begin
    if (fs_we_i) mem_q[fs_addr_i] <= fs_wdata_i;
  end
  always_ff @(posedge clk_i) begin
    rd_q <= mem_q[rd_addr];
  end

  // ---------------------------------------------------------------- descriptors
  logic [15:0] act_base_d, act_base_q, act_len_d, act_len_q;
  logic [2:0]  act_win_d, act_win_q;
  logic        act_comp_d, act_comp_q;
  logic [15:0] pend_base_d, pend_base_q, pend_len_d, pend_len_q;
  logic [2:0]  pend_win_d, pend_win_q;
  logic        pend_comp_d, pend_comp_q, pend_d, pend_q;

  // ---------------------------------------------------------------- player state
  logic [15:0] idx_d, idx_q;       // next word of the image
  logic [11:0] lines_d, lines_q;   // markers played in this frame
  logic        epoch_d, epoch_q;
  logic        s1_v_d, s1_v_q, s1_syn_d, s1_syn_q, s1_ep_d, s1_ep_q, s1_comp_d, s1_comp_q;
  logic [2:0]  s1_win_d, s1_win_q;
  logic        frame_d, frame_q;

  // Mapper and FIFO.
  logic        map_v;
  logic [11:0] map_id;
  logic [35:0] map_data;
  logic [47:0] fifo_q [FifoDepth];
  logic [FW:0] cnt_d, cnt_q;
  logic [FW-1:0] wp_d, wp_q, rp_d, rp_q;
  logic        push, pop, issue, syn, live, wrap;
  logic [31:0] s1_word;

  assign syn     = (idx_q >= act_len_q);
  assign rd_addr = AW'(act_base_q + idx_q);
  // Credit check: the FIFO entries plus the words in s1 and in the mapper stage.
  assign issue   = ({1'b0, cnt_q} + (FW + 2)'(s1_v_q) + (FW + 2)'(map_v))
                   < (FW + 2)'(FifoDepth);
  assign s1_word = s1_syn_q ? MarkerWord : rd_q;
  assign live    = s1_v_q && (s1_ep_q == epoch_q);
  assign wrap    = live && (s1_word[31:27] == 5'd1) && (lines_q + 12'd1 >= vactive_i);

  always_comb begin
    act_base_d  = act_base_q;
    act_len_d   = act_len_q;
    act_win_d   = act_win_q;
    act_comp_d  = act_comp_q;
    pend_base_d = pend_base_q;
    pend_len_d  = pend_len_q;
    pend_win_d  = pend_win_q;
    pend_comp_d = pend_comp_q;
    pend_d      = pend_q;
    idx_d       = idx_q;
    lines_d     = lines_q;
    epoch_d     = epoch_q;
    frame_d     = 1'b0;

    // Issue: a frame-store read, or a padding marker once the image is exhausted.
    s1_v_d    = issue;
    s1_syn_d  = syn;
    s1_ep_d   = epoch_q;
    s1_win_d  = act_win_q;
    s1_comp_d = act_comp_q;
    if (issue && !syn) idx_d = idx_q + 16'd1;

    // s1: count markers; after the vactive_i-th restart the image (new epoch).
    if (live && s1_word[31:27] == 5'd1) lines_d = lines_q + 12'd1;
    if (wrap) begin
      lines_d = 12'd0;
      idx_d   = 16'd0;
      epoch_d = ~epoch_q;
      frame_d = 1'b1;
      if (pend_q) begin
        act_base_d = pend_base_q;
        act_len_d  = pend_len_q;
        act_win_d  = pend_win_q;
        act_comp_d = pend_comp_q;
        pend_d     = 1'b0;
      end
    end
    // A descriptor arriving in the restart cycle waits for the frame after.
    if (desc_set_i) begin
      pend_base_d = desc_base_i;
      pend_len_d  = desc_len_i;
      pend_win_d  = desc_window_i;
      pend_comp_d = desc_comp_i;
      pend_d      = 1'b1;
    end
  end

  de_data_mapper u_mapper (
    .clk_i,
    .rst_i,
    .valid_i     (live),
    .word_i      (s1_word),
    .window_i    (s1_win_q),
    .compensate_i(s1_comp_q),
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
      act_base_q  <= 16'd0;
      act_len_q   <= 16'd0;
      act_win_q   <= 3'd0;
      act_comp_q  <= 1'b0;
      pend_base_q <= 16'd0;
      pend_len_q  <= 16'd0;
      pend_win_q  <= 3'd0;
      pend_comp_q <= 1'b0;
      pend_q      <= 1'b0;
      idx_q       <= 16'd0;
      lines_q     <= 12'd0;
      epoch_q     <= 1'b0;
      s1_v_q      <= 1'b0;
      s1_syn_q    <= 1'b0;
      s1_ep_q     <= 1'b0;
      s1_win_q    <= 3'd0;
      s1_comp_q   <= 1'b0;
      frame_q     <= 1'b0;
      cnt_q       <= '0;
      wp_q        <= '0;
      rp_q        <= '0;
    end else begin
      act_base_q  <= act_base_d;
      act_len_q   <= act_len_d;
      act_win_q   <= act_win_d;
      act_comp_q  <= act_comp_d;
      pend_base_q <= pend_base_d;
      pend_len_q  <= pend_len_d;
      pend_win_q  <= pend_win_d;
      pend_comp_q <= pend_comp_d;
      pend_q      <= pend_d;
      idx_q       <= idx_d;
      lines_q     <= lines_d;
      epoch_q     <= epoch_d;
      s1_v_q      <= s1_v_d;
      s1_syn_q    <= s1_syn_d;
      s1_ep_q     <= s1_ep_d;
      s1_win_q    <= s1_win_d;
      s1_comp_q   <= s1_comp_d;
      frame_q     <= frame_d;
      cnt_q       <= cnt_d;
      wp_q        <= wp_d;
      rp_q        <= rp_d;
    end
  end

  assign wr_valid_o = (cnt_q != '0);
  assign wr_data_o  = fifo_q[rp_q];
  assign frame_o    = frame_q;
  assign pending_o  = pend_q;
endmodule

`default_nettype wire
