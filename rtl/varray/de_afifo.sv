// Dual-clock FIFO: Gray-coded pointers, each synchronised into the other clock domain
// through two flip-flops, storage in block RAM written in the write domain and read
// synchronously in the read domain into an output register (first word fall-through).
//
// The read side fetches a word only after its write pointer has crossed (2-3 read clocks
// after the write), and the memory cell was written before the pointer moved, so the
// read is stable. Full and empty are conservative (a pointer seen late only delays a
// write or a read). One word more than 2^AW can be held: the output register.
// Reset: each side has its own synchronous reset; both must be held together for a few
// clocks of the slower domain.
//
// Why block RAM with a read register (docs/fpga.md 3.5): with 2^AW = 256 words of
// distributed RAM and an asynchronous read, the read pointer fanned out to every RAM
// cell and its 16:1 read mux, which spread the read-pointer logic over the die; on the
// ULX3S board that was the core clock's worst path (routing, 64-73 MHz over seeds
// against 78.125). Here the pointer drives the address of two block RAMs only.
`default_nettype none

module de_afifo #(
  parameter int unsigned W  = 48,
  parameter int unsigned AW = 4           // 2^AW words
) (
  input  logic         wclk_i,
  input  logic         wrst_i,
  input  logic         wvalid_i,
  input  logic [W-1:0] wdata_i,
  output logic         wfull_o,
  input  logic         rclk_i,
  input  logic         rrst_i,
  output logic         rvalid_o,
  input  logic         rready_i,
  output logic [W-1:0] rdata_o
);
  if (AW < 2 || AW > 10) begin : g_bad_aw
    $fatal(1, "de_afifo: AW must be 2..10, got %0d", AW);
  end

  function automatic logic [AW:0] bin2gray(input logic [AW:0] b);
    return b ^ (b >> 1);
  endfunction

  (* ram_style = "block" *) logic [W-1:0] mem [1 << AW];
  logic [AW:0] wgray_q, rgray_q;            // each side's pointer, Gray-coded

  // ---- write domain ----
  logic [AW:0] wbin_d, wbin_q, rgray_w1_q, rgray_w2_q;
  logic        wen;
  // Full: the write pointer is one lap ahead of the read pointer (Gray form: the two
  // top bits differ, the rest agree).
  assign wfull_o = (wgray_q == {~rgray_w2_q[AW:AW-1], rgray_w2_q[AW-2:0]});
  assign wen     = wvalid_i && !wfull_o;
  assign wbin_d  = wbin_q + (AW + 1)'(wen);

  always_ff @(posedge wclk_i) begin
    if (wen) begin
      mem[wbin_q[AW-1:0]] <= wdata_i;
    end
  end

  always_ff @(posedge wclk_i) begin
    if (wrst_i) begin
      wbin_q     <= '0;
      wgray_q    <= '0;
      rgray_w1_q <= '0;
      rgray_w2_q <= '0;
    end else begin
      wbin_q     <= wbin_d;
      wgray_q    <= bin2gray(wbin_d);
      rgray_w1_q <= rgray_q;
      rgray_w2_q <= rgray_w1_q;
    end
  end

  // ---- read domain ----
  // rbin_q: the next word to fetch into the output register (rdata_q, ovalid_q). A word
  // is fetched when the memory holds one and the register is empty or being taken.
  logic [AW:0] rbin_d, rbin_q, wgray_r1_q, wgray_r2_q;
  logic        nonempty, ren, ovalid_d, ovalid_q;
  logic [W-1:0] rdata_q;
  assign nonempty = (rgray_q != wgray_r2_q);
  assign ren      = nonempty && (!ovalid_q || rready_i);
  assign rbin_d   = rbin_q + (AW + 1)'(ren);
  assign ovalid_d = ren || (ovalid_q && !rready_i);
  assign rvalid_o = ovalid_q;
  assign rdata_o  = rdata_q;

  always_ff @(posedge rclk_i) begin
    if (ren) begin
      rdata_q <= mem[rbin_q[AW-1:0]];
    end
  end

  always_ff @(posedge rclk_i) begin
    if (rrst_i) begin
      rbin_q     <= '0;
      rgray_q    <= '0;
      wgray_r1_q <= '0;
      wgray_r2_q <= '0;
      ovalid_q   <= 1'b0;
    end else begin
      rbin_q     <= rbin_d;
      rgray_q    <= bin2gray(rbin_d);
      wgray_r1_q <= wgray_q;
      wgray_r2_q <= wgray_r1_q;
      ovalid_q   <= ovalid_d;
    end
  end
endmodule

`default_nettype wire
