// Dual-clock FIFO (docs/board.md §4): the board's prefetch FIFOs (SDRAM clock -> pixel
// clock, Width 36, Depth 2048: four DP16KD in 2048 x 9) and the loader's command FIFO
// (pixel clock -> SDRAM clock, a few entries).
//
// Pointers are Depth-wrapping binary counters with one extra bit, each mirrored in Gray
// code in a register of its own domain; the other domain sees the Gray pointer through
// two flip-flops (ASYNC_REG), so a pointer in flight is either its old or its new value
// and full / empty are conservative, never wrong.
//
// Write side: wready_o = not full (a register, conservative for a clock); wfree_o = free
// entries, registered and conservative: it counts every push up to this clock as if one
// more came in this clock, and pops only once they have crossed (it does not wait for
// this clock's push, so the push decision and the pointer arithmetic are in different
// clocks); de_sdram_frames uses it to see its X FIFO drained (its prefetch FIFOs' credit
// is kept on the read side's clock).
// Read side: show-ahead (rvalid_o / rdata_o / rready_o). The memory is read only when
// the synchronised write pointer says the entry is written, at least one read clock after
// the synchroniser saw it, into the output register, so the two ports never touch the
// same entry in the same clock: a dual-clock block RAM with a registered read.
`default_nettype none

module de_async_fifo #(
  parameter int unsigned Width = 36,
  parameter int unsigned Depth = 2048,     // a power of two, >= 4
  localparam int unsigned AW = $clog2(Depth)
) (
  // Write side.
  input  logic             wclk_i,
  input  logic             wrst_i,        // synchronous to wclk_i
  input  logic             wvalid_i,
  output logic             wready_o,
  input  logic [Width-1:0] wdata_i,
  output logic [AW:0]      wfree_o,
  // Read side.
  input  logic             rclk_i,
  input  logic             rrst_i,        // synchronous to rclk_i
  output logic             rvalid_o,
  input  logic             rready_i,
  output logic [Width-1:0] rdata_o
);
  if (Depth < 4 || Depth > 65536 || (Depth & (Depth - 1)) != 0) begin : g_bad_depth
    $fatal(1, "de_async_fifo: Depth must be a power of two, 4..65536, got %0d", Depth);
  end
  if (Width < 1) begin : g_bad_width
    $fatal(1, "de_async_fifo: Width must be >= 1");
  end

  typedef logic [AW:0] ptr_t;
  localparam int unsigned HB = (AW + 1) / 2;   // the pointer's bottom half (Gray decode)

  function automatic ptr_t bin2gray(ptr_t b);
    return b ^ (b >> 1);
  endfunction

  logic [Width-1:0] mem_q [Depth];

  // Write side.
  ptr_t wbin_d, wbin_q, wgray_q, rdec_q, rbin_w_q, wfree_d, wfree_q, used;
  (* ASYNC_REG = "TRUE" *) ptr_t rgray_w1_q, rgray_w2_q;
  logic push, full_d, full_q;
  // Read side.
  ptr_t rbin_d, rbin_q, rgray_q;
  (* ASYNC_REG = "TRUE" *) ptr_t wgray_r1_q, wgray_r2_q;
  logic             empty, load, dout_v_d, dout_v_q;
  logic [Width-1:0] dout_q;

  // ---------------------------------------------------------------- write side

  // The read pointer in binary is registered too, its Gray decode in two registered
  // steps (one more clock of conservatism): the top half first (rdec_q: top half binary,
  // bottom half still Gray), then the bottom half from the top's lowest bit. Each bit is
  // an XOR of at most half the pointer plus one, two LUT levels; decoded in one step, the
  // bits share a chain (b[i] = b[i+1] ^ g[i]) that synthesis keeps 9-11 LUTs deep at
  // Depth 2048, the worst path of the 125 MHz write side.
  // Full is a register (so the push is one gate after flip-flops): what this clock's
  // count and push make it, against the read pointer as it is now (it can only move on:
  // conservative for one clock).
  assign used     = wbin_q - rbin_w_q;                 // 0 .. Depth
  assign wready_o = !full_q;
  assign push     = wvalid_i && !full_q;
  assign full_d   = push ? (used == ptr_t'(Depth - 1)) : used[AW];
  assign wbin_d   = push ? wbin_q + 1'b1 : wbin_q;
  // Depth - 1 - used (a push this clock counted whether or not it comes), 0 when full.
  assign wfree_d  = used[AW] ? '0 : {1'b0, ~used[AW-1:0]};

  always_ff @(posedge wclk_i) begin
    if (push) mem_q[wbin_q[AW-1:0]] <= wdata_i;
  end

  always_ff @(posedge wclk_i) begin
    if (wrst_i) begin
      wbin_q     <= '0;
      wgray_q    <= '0;
      rgray_w1_q <= '0;
      rgray_w2_q <= '0;
      rdec_q     <= '0;
      rbin_w_q   <= '0;
      full_q     <= 1'b0;
      wfree_q    <= ptr_t'(Depth);
    end else begin
      wbin_q     <= wbin_d;
      wgray_q    <= bin2gray(wbin_d);
      rgray_w1_q <= rgray_q;
      rgray_w2_q <= rgray_w1_q;
      for (int i = 0; i <= int'(AW); i++) begin
        rdec_q[i]   <= (i >= int'(HB)) ? ^(rgray_w2_q >> i) : rgray_w2_q[i];
        rbin_w_q[i] <= (i >= int'(HB)) ? rdec_q[i] : rdec_q[HB] ^ (^(rdec_q[HB-1:0] >> i));
      end
      full_q     <= full_d;
      wfree_q    <= wfree_d;
    end
  end
  assign wfree_o = wfree_q;

  // ---------------------------------------------------------------- read side

  assign empty    = (rgray_q == wgray_r2_q);
  // The output register takes the head when it is free or being emptied.
  assign load     = !empty && (!dout_v_q || rready_i);
  assign rbin_d   = load ? rbin_q + 1'b1 : rbin_q;
  assign dout_v_d = load || (dout_v_q && !rready_i);

  always_ff @(posedge rclk_i) begin
    if (load) dout_q <= mem_q[rbin_q[AW-1:0]];
  end

  always_ff @(posedge rclk_i) begin
    if (rrst_i) begin
      rbin_q     <= '0;
      rgray_q    <= '0;
      wgray_r1_q <= '0;
      wgray_r2_q <= '0;
      dout_v_q   <= 1'b0;
    end else begin
      rbin_q     <= rbin_d;
      rgray_q    <= bin2gray(rbin_d);
      wgray_r1_q <= wgray_q;
      wgray_r2_q <= wgray_r1_q;
      dout_v_q   <= dout_v_d;
    end
  end

  assign rvalid_o = dout_v_q;
  assign rdata_o  = dout_q;
endmodule

`default_nettype wire
