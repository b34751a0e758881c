// The board's SDRAM pins as one value (docs/sdram.md §2), and the commands on them: what
// de_sdram_ctrl drives, and what de_sdram_frames, de_board_core and the ULX3S shell pass
// on to the I/O buffers, registered in the controller. The part's geometry is the
// ULX3S's MT48LC16M16A2 (4 banks, 13 row bits). DQ comes back as a plain 16-bit input
// (sd_dq_i): the shell's BB buffers join dq, dq_oe and the pins' input at the DQ pins.
`default_nettype none

package de_sdram_pkg;
  localparam int unsigned SdBankBits = 2;
  localparam int unsigned SdRowBits  = 13;   // also the address pins' width
  localparam int unsigned SdDqW      = 16;

  typedef struct packed {
    logic                  cke;
    logic                  cs_n;
    logic                  ras_n;
    logic                  cas_n;
    logic                  we_n;
    logic [SdBankBits-1:0] ba;
    logic [SdRowBits-1:0]  a;
    logic [SdDqW/8-1:0]    dqm;
    logic [SdDqW-1:0]      dq;      // write data, driven when dq_oe
    logic                  dq_oe;
  } sdram_out_t;

  // The commands on {cs_n, ras_n, cas_n, we_n} (the part's truth table; BURST TERMINATE
  // is not used).
  typedef enum logic [3:0] {
    CmdLmr = 4'b0000, CmdRef = 4'b0001, CmdPre = 4'b0010, CmdAct = 4'b0011,
    CmdWrite = 4'b0100, CmdRead = 4'b0101, CmdNop = 4'b0111
  } sdram_cmd_e;
endpackage

`default_nettype wire
