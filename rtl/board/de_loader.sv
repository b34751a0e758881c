// UART loader of the board top, version 2: the host's command protocol (docs/board.md
// §3, docs/sdram-frames-spec.md §3).
//
// Every command is a command byte, fixed header bytes, (for 'X') 4*N data bytes, and a
// checksum byte chosen so that all the command's bytes sum to 0 mod 256. Multi-byte
// fields are big-endian. Every complete command gets a reply:
//
//   'X' ch o2 o1 o0 n1 n0 {4 bytes per word}*N ck  write N (1..1024) words into colour
//                                  ch's SDRAM region from offset o (< 2^21)      -> K/E
//   'F' ch slot t2 t1 t0 win flags ck  frame slot (0..63) of ch: table offset t
//                                  (a multiple of 4, < 2^21), window, compensation -> K/E
//   'Q' first count hold loop ck   the sequence of slots (first + count <= 64, hold
//                                  1..255 frames each, loop 0/1), from the next frame
//                                  boundary                                      -> K/E
//   'O' shift sat ck               8-bit output window of the DVI pixels          -> K/E
//   'R' a1 a0 ck                   read display-controller register a    -> 'R' d3..d0 / E
//   'S' ck                         status                                -> 'S' + 15 bytes
//
// 'W' and 'P' (version 1, the block-RAM frame stores) are gone: an old host tool gets
// them counted as bytes that are not a command, and reads version 2 in 'S'.
// Replies: 'K' done; 'E' checksum wrong, a field out of range, or a UART framing error
// inside the command; 'T' the command stopped arriving (no byte for 2^TimeoutBits clocks;
// it is abandoned). Words of an 'X' are written as they arrive (no staging copy), so
// after an 'E' the host re-sends the command; a framing error stops the writes of the
// rest of its command. X words, F and Q go to the SDRAM side (de_sdram_frames) through
// its command FIFO, in order, one entry each; should the FIFO be full (it drains far
// faster than the UART fills it) the command is answered 'E' and counted. Bytes that are
// not a command byte are counted and skipped (resynchronisation). The host waits for each
// reply: a reply due while the previous one is still being sent is dropped and counted.
`default_nettype none

module de_loader #(
  parameter int unsigned NumChips    = 1,
  parameter int unsigned TimeoutBits = 22     // 2^22 clocks = 168 ms at 25 MHz
) (
  input  logic          clk_i,
  input  logic          rst_i,
  // UART receiver / transmitter.
  input  logic          rx_valid_i,
  input  logic [7:0]    rx_data_i,
  input  logic          rx_ferr_i,
  output logic          tx_valid_o,
  input  logic          tx_ready_i,
  output logic [7:0]    tx_data_o,
  // SDRAM side's command FIFO: {type, fields} (de_sdram_frames): type 1 X word
  // {ch, off[20:0], word}, 2 F {ch, slot, table[20:0], window, comp}, 3 Q {first,
  // count, hold, loop}.
  output logic          sd_cmd_valid_o,
  input  logic          sd_cmd_ready_i,
  output logic [56:0]   sd_cmd_o,
  // Output window and display-controller register port.
  output logic [2:0]    out8_shift_o,
  output logic          out8_sat_o,
  output logic [13:0]   reg_addr_o,
  input  logic [31:0]   reg_rdata_i,
  // Status sources.
  input  logic          frame_i,          // a frame played (colour R's player)
  input  logic          pending_i,        // a sequence waits for a frame boundary
  input  logic          align_err_i,
  input  logic [2:0]    pix_collision_i,
  input  logic [7:0]    malformed_i,      // malformed lines fixed by the fetchers
  input  logic [7:0]    late_i,           // late lines for want of SDRAM data
  output logic [15:0]   rx_ferr_count_o,
  output logic [15:0]   chk_err_count_o,
  output logic [15:0]   cmd_err_count_o
);
  if (TimeoutBits < 4 || TimeoutBits > 30) begin : g_bad_timeout
    $fatal(1, "de_loader: TimeoutBits must be 4..30");
  end

  typedef enum logic [2:0] {SCmd, SHdr, SData, SChk, SReg} state_e;

  localparam logic [7:0] CmdX = 8'h58, CmdF = 8'h46, CmdQ = 8'h51, CmdO = 8'h4F,
                         CmdR = 8'h52, CmdS = 8'h53;
  localparam logic [1:0] TypX = 2'd1, TypF = 2'd2, TypQ = 2'd3;
  localparam logic [23:0] Region = 24'h20_0000;   // words per colour region: 2^21
  localparam logic [7:0] RepK = 8'h4B, RepE = 8'h45, RepT = 8'h54;

  state_e      state_d, state_q;
  logic [7:0]  cmd_d, cmd_q, sum_d, sum_q;
  logic [55:0] hdr_d, hdr_q;             // header bytes, last one in [7:0]
  logic [2:0]  left_d, left_q;           // header bytes still to come
  logic [23:0] addr_d, addr_q;
  logic [15:0] nw_d, nw_q;
  logic [23:0] wsh_d, wsh_q;             // first three bytes of the current word
  logic [1:0]  wb_d, wb_q;               // byte of the current word
  logic        bad_d, bad_q;             // field or framing error in this command
  logic [TimeoutBits-1:0] idle_d, idle_q;
  logic [2:0]  shift_d, shift_q;
  logic        sat_d, sat_q;
  logic [13:0] raddr_d, raddr_q;
  logic [1:0]  rwait_d, rwait_q;
  logic [15:0] ferr_d, ferr_q, cerr_d, cerr_q, kerr_d, kerr_q, frames_d, frames_q;
  // Reply: up to 16 bytes, first byte in [127:120].
  logic [127:0] rep_d, rep_q;
  logic [4:0]   rep_n_d, rep_n_q;
  logic         scv_d, scv_q;
  logic [56:0]  sc_d, sc_q;
  logic         sc_ok;                  // the command FIFO takes an entry now

  function automatic logic [15:0] sat_inc(logic [15:0] v);
    return (v == 16'hFFFF) ? v : v + 16'd1;
  endfunction

  logic [7:0] b;
  logic       want_rep;
  logic [127:0] rep_new;
  logic [4:0]   rep_new_n;

  always_comb begin
    state_d  = state_q;
    cmd_d    = cmd_q;
    sum_d    = sum_q;
    hdr_d    = hdr_q;
    left_d   = left_q;
    addr_d   = addr_q;
    nw_d     = nw_q;
    wsh_d    = wsh_q;
    wb_d     = wb_q;
    bad_d    = bad_q;
    shift_d  = shift_q;
    sat_d    = sat_q;
    raddr_d  = raddr_q;
    rwait_d  = rwait_q;
    ferr_d   = ferr_q;
    cerr_d   = cerr_q;
    kerr_d   = kerr_q;
    frames_d = frame_i ? frames_q + 16'd1 : frames_q;
    scv_d    = 1'b0;
    sc_d     = sc_q;
    sc_ok    = sd_cmd_ready_i && !scv_q;
    want_rep = 1'b0;
    rep_new  = '0;
    rep_new_n = 5'd0;
    b        = rx_data_i;

    // Idle timer: only while a command is incomplete.
    idle_d = (state_q == SCmd || rx_valid_i) ? '0 : idle_q + 1'b1;

    if (rx_ferr_i) begin
      ferr_d = sat_inc(ferr_q);
      if (state_q != SCmd) bad_d = 1'b1;
    end

    unique case (state_q)
      SCmd: begin
        if (rx_valid_i) begin
          cmd_d = b;
          sum_d = b;
          bad_d = 1'b0;
          hdr_d = '0;
          unique case (b)
            CmdX: begin state_d = SHdr; left_d = 3'd6; end
            CmdF: begin state_d = SHdr; left_d = 3'd7; end
            CmdQ: begin state_d = SHdr; left_d = 3'd4; end
            CmdO: begin state_d = SHdr; left_d = 3'd2; end
            CmdR: begin state_d = SHdr; left_d = 3'd2; end
            CmdS: begin state_d = SChk; end
            default: kerr_d = sat_inc(kerr_q);   // not a command byte: skip it
          endcase
        end
      end
      SHdr: begin
        if (rx_valid_i) begin
          sum_d  = sum_q + b;
          hdr_d  = {hdr_q[47:0], b};
          left_d = left_q - 3'd1;
          if (left_q == 3'd1) begin
            if (cmd_q == CmdX) begin
              // hdr_d[47:0] = ch o2 o1 o0 n1 n0
              addr_d  = hdr_d[39:16];
              nw_d    = hdr_d[15:0];
              wb_d    = 2'd0;
              if (hdr_d[47:40] > 8'd2 || hdr_d[39:16] >= Region || hdr_d[15:0] == 16'd0 ||
                  hdr_d[15:0] > 16'd1024) bad_d = 1'b1;
              state_d = (hdr_d[15:0] == 16'd0) ? SChk : SData;
            end else begin
              state_d = SChk;
            end
          end
        end
      end
      SData: begin
        if (rx_valid_i) begin
          sum_d = sum_q + b;
          wsh_d = {wsh_q[15:0], b};
          wb_d  = wb_q + 2'd1;
          if (wb_q == 2'd3) begin
            // Write the word unless the command is already known to be bad or the
            // address is outside the region.
            if (!bad_q && addr_q < Region && sc_ok) begin
              scv_d = 1'b1;
              sc_d  = {TypX, hdr_q[41:40], addr_q[20:0], wsh_q, b};
            end else begin
              bad_d = 1'b1;
            end
            addr_d  = addr_q + 24'd1;
            nw_d    = nw_q - 16'd1;
            if (nw_q == 16'd1) state_d = SChk;
          end
        end
      end
      SChk: begin
        if (rx_valid_i) begin
          state_d  = SCmd;
          want_rep = 1'b1;
          rep_new_n = 5'd1;
          if (sum_q + b != 8'd0) begin
            cerr_d  = sat_inc(cerr_q);
            rep_new = {RepE, 120'd0};
          end else if (bad_q || rx_ferr_i) begin
            kerr_d  = sat_inc(kerr_q);
            rep_new = {RepE, 120'd0};
          end else begin
            rep_new = {RepK, 120'd0};
            unique case (cmd_q)
              CmdF: begin
                // hdr_q[55:0] = ch slot t2 t1 t0 win flags
                if (hdr_q[55:48] > 8'd2 || hdr_q[47:40] > 8'd63 || hdr_q[39:16] >= Region ||
                    hdr_q[17:16] != 2'd0 || hdr_q[15:8] > 8'd4 || hdr_q[7:1] != 7'd0 ||
                    !sc_ok) begin
                  kerr_d  = sat_inc(kerr_q);
                  rep_new = {RepE, 120'd0};
                end else begin
                  scv_d = 1'b1;
                  sc_d  = {TypF, hdr_q[49:48], hdr_q[45:40], hdr_q[36:16], hdr_q[10:8],
                           hdr_q[0], 22'd0};
                end
              end
              CmdQ: begin
                // hdr_q[31:0] = first count hold loop
                if (hdr_q[31:24] > 8'd63 || hdr_q[23:16] == 8'd0 || hdr_q[23:16] > 8'd64 ||
                    9'(hdr_q[31:24]) + 9'(hdr_q[23:16]) > 9'd64 || hdr_q[15:8] == 8'd0 ||
                    hdr_q[7:0] > 8'd1 || !sc_ok) begin
                  kerr_d  = sat_inc(kerr_q);
                  rep_new = {RepE, 120'd0};
                end else begin
                  scv_d = 1'b1;
                  sc_d  = {TypQ, 2'd0, hdr_q[29:24], hdr_q[22:16], hdr_q[15:8], hdr_q[0],
                           31'd0};
                end
              end
              CmdO: begin
                if (hdr_q[15:8] > 8'd4 || hdr_q[7:1] != 7'd0) begin
                  kerr_d  = sat_inc(kerr_q);
                  rep_new = {RepE, 120'd0};
                end else begin
                  shift_d = hdr_q[10:8];
                  sat_d   = hdr_q[0];
                end
              end
              CmdR: begin
                // The register port answers one clock after the address: wait for it.
                raddr_d  = hdr_q[13:0];
                rwait_d  = 2'd2;
                want_rep = 1'b0;
                state_d  = SReg;
              end
              CmdS: begin
                rep_new_n = 5'd16;
                rep_new = {CmdS, 8'd2, 8'(NumChips), 8'd21,
                           ferr_q, cerr_q, kerr_q, frames_q,
                           3'b000, pending_i, pix_collision_i, align_err_i,
                           4'd0, sat_q, shift_q, malformed_i, late_i};
              end
              default: ;
            endcase
          end
        end
      end
      SReg: begin
        rwait_d = rwait_q - 2'd1;
        if (rwait_q == 2'd1) begin
          state_d   = SCmd;
          want_rep  = 1'b1;
          rep_new_n = 5'd5;
          rep_new   = {CmdR, reg_rdata_i, 88'd0};
        end
      end
      default: state_d = SCmd;
    endcase

    // A command that stopped arriving is abandoned.
    if (state_q != SCmd && state_q != SReg && &idle_q) begin
      state_d   = SCmd;
      kerr_d    = sat_inc(kerr_q);
      want_rep  = 1'b1;
      rep_new_n = 5'd1;
      rep_new   = {RepT, 120'd0};
    end

    // Reply sequencer.
    rep_d   = rep_q;
    rep_n_d = rep_n_q;
    if (rep_n_q != 5'd0 && tx_ready_i) begin
      rep_d   = {rep_q[119:0], 8'd0};
      rep_n_d = rep_n_q - 5'd1;
    end
    if (want_rep) begin
      if (rep_n_d == 5'd0) begin
        rep_d   = rep_new;
        rep_n_d = rep_new_n;
      end else begin
        kerr_d = sat_inc(kerr_q);   // the host did not wait for the previous reply
      end
    end
  end

  always_ff @(posedge clk_i) begin
    if (rst_i) begin
      state_q  <= SCmd;
      cmd_q    <= 8'd0;
      sum_q    <= 8'd0;
      hdr_q    <= '0;
      left_q   <= 3'd0;
      addr_q   <= 24'd0;
      nw_q     <= 16'd0;
      wsh_q    <= 24'd0;
      wb_q     <= 2'd0;
      bad_q    <= 1'b0;
      idle_q   <= '0;
      shift_q  <= 3'd0;
      sat_q    <= 1'b1;
      raddr_q  <= 14'd0;
      rwait_q  <= 2'd0;
      ferr_q   <= 16'd0;
      cerr_q   <= 16'd0;
      kerr_q   <= 16'd0;
      frames_q <= 16'd0;
      rep_q    <= '0;
      rep_n_q  <= 5'd0;
      scv_q    <= 1'b0;
      sc_q     <= '0;
    end else begin
      state_q  <= state_d;
      cmd_q    <= cmd_d;
      sum_q    <= sum_d;
      hdr_q    <= hdr_d;
      left_q   <= left_d;
      addr_q   <= addr_d;
      nw_q     <= nw_d;
      wsh_q    <= wsh_d;
      wb_q     <= wb_d;
      bad_q    <= bad_d;
      idle_q   <= idle_d;
      shift_q  <= shift_d;
      sat_q    <= sat_d;
      raddr_q  <= raddr_d;
      rwait_q  <= rwait_d;
      ferr_q   <= ferr_d;
      cerr_q   <= cerr_d;
      kerr_q   <= kerr_d;
      frames_q <= frames_d;
      rep_q    <= rep_d;
      rep_n_q  <= rep_n_d;
      scv_q    <= scv_d;
      sc_q     <= sc_d;
    end
  end

  assign tx_valid_o      = (rep_n_q != 5'd0);
  assign tx_data_o       = rep_q[127:120];
  assign sd_cmd_valid_o  = scv_q;
  assign sd_cmd_o        = sc_q;
  assign out8_shift_o    = shift_q;
  assign out8_sat_o      = sat_q;
  assign reg_addr_o      = raddr_q;
  assign rx_ferr_count_o = ferr_q;
  assign chk_err_count_o = cerr_q;
  assign cmd_err_count_o = kerr_q;
endmodule

`default_nettype wire
