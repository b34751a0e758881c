"""Benchmarks and the reports made from them. Every benchmark (`diffengine bench NAME`)
measures, then `record.save` writes out/bench/NAME.json (the command, date, load average,
revision and the figures); `render` writes the docs/performance.md section between the
markers `<!-- bench:NAME:begin -->` and `<!-- bench:NAME:end -->` from that JSON, with the
benchmark's own `render(record)`. Benchmarks: `model` (golden model speed), `yproc`
(commands per line, host time, scaling), `hsr` (Table 5.2, Fig 5.30), `array` (Verilated
array speed), `span` (span-serial clocks per line); `recon` writes
docs/reconstruction.md and `recon_images` the test images in sw/images.
"""
