"""Formats: how commands and frames are written down. The command-file text (`asm`: the
source's syntax, parser and printer; `disasm`: streams back to text), the binary
instruction streams and frame-store words (`binfmt`: .de48, .de32, the data mapper), and
frames on disk (`frame`: 16-bit PNG, the display controller's .dcf, text frames, small
PNGs for HTML pages). A new file format for commands or frames goes here; the meaning of
the commands themselves is `diffengine.isa`.
"""
