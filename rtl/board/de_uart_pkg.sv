// The UART's bit period (docs/board.md §3): clocks per bit, rounded to nearest, and its
// error against ClkHz / Baud in per mille; de_uart_link refuses to elaborate at 20 per
// mille (2 %) or more and gives its receiver and transmitter the clocks per bit.
`default_nettype none

package de_uart_pkg;
  function automatic int unsigned clk_per_bit(int unsigned clk_hz, int unsigned baud);
    return (clk_hz + baud / 2) / baud;
  endfunction

  function automatic longint unsigned err_permille(int unsigned clk_hz, int unsigned baud);
    longint unsigned ideal = longint'(clk_hz);
    longint unsigned got   = longint'(clk_per_bit(clk_hz, baud)) * longint'(baud);
    return ((got > ideal) ? got - ideal : ideal - got) * 64'd1000 / ideal;
  endfunction
endpackage

`default_nettype wire
