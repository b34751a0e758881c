// UART loader of the board top: the host's command protocol (docs/board.md §3).
//
// Every command is a command byte, fixed header bytes, (for 'W') 4*N data bytes, and a
// checksum byte chosen so that all the command's bytes sum to 0 mod 256. Multi-byte
// fields are big-endian. Every complete command gets a reply:
//
//   'W' ch a1 a0 n1 n0 {4 bytes per word}*N ck  write N words at a (frame store ch) -> K/E
//   'P' ch b1 b0 l1 l0 win flags ck             image descriptor of ch (next frame)  -> K/E
//   'O' shift sat ck                            8-bit output window of the DVI pixels -> K/E
//   'R' a1 a0 ck                                read display-controller register a  -> 'R' d3..d0 / E
//   'S' ck                                      status                              -> 'S' + 15 bytes
//
// Replies: 'K' done; 'E' checksum wrong, a field out of range, or a UART framing error
// inside the command; 'T' the command stopped arriving (no byte for 2^TimeoutBits clocks;
// it is abandoned). Words of a 'W' are written as they arrive (the frame store has no
// room for a staging copy), so after an 'E' the host re-sends the command; a framing
// error stops the writes of the rest of its command. Bytes that are not a command byte
// are counted and skipped (resynchronisation). The host waits for each reply: a reply
// due while the previous one is still being sent is dropped and counted.
`default_nettype none

module de_loader #(
  parameter int unsigned FsDepth     = 1024,
  parameter int unsigned NumChips    = 1,
  parameter int unsigned TimeoutBits = 22,    // 2^22 clocks = 168 ms at 25 MHz
  localparam int unsigned AW = $clog2(FsDepth)
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
  // Frame stores (one write port per colour).
  output logic [2:0]    fs_we_o,
  output logic [AW-1:0] fs_addr_o,
  output logic [31:0]   fs_wdata_o,
  // Image descriptors.
  output logic [2:0]    desc_set_o,
  output logic [15:0]   desc_base_o,
  output logic [15:0]   desc_len_o,
  output logic [2:0]    desc_window_o,
  output logic          desc_comp_o,
  // Output window and display-controller register port.
  output logic [2:0]    out8_shift_o,
  output logic          out8_sat_o,
  output logic [13:0]   reg_addr_o,
  input  logic [31:0]   reg_rdata_i,
  // Status sources.
  input  logic          frame_i,          // a frame played (colour R's player)
  input  logic [2:0]    pending_i,
  input  logic          align_err_i,
  input  logic [2:0]    pix_collision_i,
  output logic [15:0]   rx_ferr_count_o,
  output logic [15:0]   chk_err_count_o,
  output logic [15:0]   cmd_err_count_o
);
  if (TimeoutBits < 4 || TimeoutBits > 30) begin : g_bad_timeout
    $fatal(1, "de_loader: TimeoutBits must be 4..30");
  end

  typedef enum logic [2:0] {SCmd, SHdr, SData, SChk, SReg} state_e;

  localparam logic [7:0] CmdW = 8'h57, CmdP = 8'h50, CmdO = 8'h4F, CmdR = 8'h52,
                         CmdS = 8'h53;
  localparam logic [7:0] RepK = 8'h4B, RepE = 8'h45, RepT = 8'h54;

  state_e      state_d, state_q;
  logic [7:0]  cmd_d, cmd_q, sum_d, sum_q;
  logic [55:0] hdr_d, hdr_q;             // header bytes, last one in [7:0]
  logic [2:0]  left_d, left_q;           // header bytes still to come
  logic [15:0] addr_d, addr_q, nw_d, nw_q;
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
  logic [2:0]   we_d, we_q, dset_d, dset_q;
  logic [AW-1:0] waddr_d, waddr_q;
  logic [31:0]  wdata_d, wdata_q;
  logic [15:0]  dbase_d, dbase_q, dlen_d, dlen_q;
  logic [2:0]   dwin_d, dwin_q;
  logic         dcomp_d, dcomp_q;

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
    we_d     = 3'b000;
    waddr_d  = waddr_q;
    wdata_d  = wdata_q;
    dset_d   = 3'b000;
    dbase_d  = dbase_q;
    dlen_d   = dlen_q;
    dwin_d   = dwin_q;
    dcomp_d  = dcomp_q;
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
            CmdW: begin state_d = SHdr; left_d = 3'd5; end
            CmdP: begin state_d = SHdr; left_d = 3'd7; end
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
            if (cmd_q == CmdW) begin
              // hdr_d[39:0] = ch a1 a0 n1 n0
              addr_d  = hdr_d[31:16];
              nw_d    = hdr_d[15:0];
              wb_d    = 2'd0;
              if (hdr_d[39:32] > 8'd2) bad_d = 1'b1;
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
            // address is outside the frame store.
            if (!bad_q && hdr_q[39:32] <= 8'd2 && 32'(addr_q) < 32'(FsDepth)) begin
              we_d[hdr_q[33:32]] = 1'b1;
            end else begin
              bad_d = 1'b1;
            end
            waddr_d = AW'(addr_q);
            wdata_d = {wsh_q, b};
            addr_d  = addr_q + 16'd1;
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
              CmdP: begin
                // hdr_q[55:0] = ch b1 b0 l1 l0 win flags
                if (hdr_q[55:48] > 8'd2 || hdr_q[15:8] > 8'd4 || hdr_q[7:1] != 7'd0) begin
                  kerr_d  = sat_inc(kerr_q);
                  rep_new = {RepE, 120'd0};
                end else begin
                  dset_d[hdr_q[49:48]] = 1'b1;
                  dbase_d = hdr_q[47:32];
                  dlen_d  = hdr_q[31:16];
                  dwin_d  = hdr_q[10:8];
                  dcomp_d = hdr_q[0];
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
                rep_new = {CmdS, 8'd1, 8'(NumChips), 8'(AW),
                           ferr_q, cerr_q, kerr_q, frames_q,
                           1'b0, pending_i, pix_collision_i, align_err_i,
                           4'd0, sat_q, shift_q, 16'd0};
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
      addr_q   <= 16'd0;
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
      we_q     <= 3'b000;
      waddr_q  <= '0;
      wdata_q  <= 32'd0;
      dset_q   <= 3'b000;
      dbase_q  <= 16'd0;
      dlen_q   <= 16'd0;
      dwin_q   <= 3'd0;
      dcomp_q  <= 1'b0;
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
      we_q     <= we_d;
      waddr_q  <= waddr_d;
      wdata_q  <= wdata_d;
      dset_q   <= dset_d;
      dbase_q  <= dbase_d;
      dlen_q   <= dlen_d;
      dwin_q   <= dwin_d;
      dcomp_q  <= dcomp_d;
    end
  end

  assign tx_valid_o      = (rep_n_q != 5'd0);
  assign tx_data_o       = rep_q[127:120];
  assign fs_we_o         = we_q;
  assign fs_addr_o       = waddr_q;
  assign fs_wdata_o      = wdata_q;
  assign desc_set_o      = dset_q;
  assign desc_base_o     = dbase_q;
  assign desc_len_o      = dlen_q;
  assign desc_window_o   = dwin_q;
  assign desc_comp_o     = dcomp_q;
  assign out8_shift_o    = shift_q;
  assign out8_sat_o      = sat_q;
  assign reg_addr_o      = raddr_q;
  assign rx_ferr_count_o = ferr_q;
  assign chk_err_count_o = cerr_q;
  assign cmd_err_count_o = kerr_q;
endmodule

`default_nettype wire
