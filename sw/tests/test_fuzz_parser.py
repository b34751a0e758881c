"""Fuzz the readers: whatever the input, the only exception is AsmError (a ValueError)
whose every line is `file:where: message`."""
import re

from hypothesis import HealthCheck, given, settings, strategies as st

from diffengine.formats import binfmt
from diffengine import isa
from diffengine.formats.asm import AsmError, format_command, parse_text
from test_binfmt import commands_st

NAME = "fz.cmd"
LOC = re.compile(r"^fz\.cmd:(\d+|byte \d+|slot \d+|command \d+): \S")
FUZZ = settings(max_examples=250, deadline=None,
                suppress_health_check=[HealthCheck.too_slow])

TOKENS = ["Eval0", "Eval1", "Eval3", "Eval8", "Eval9", "SetI", "Setddi", "SetPdI", "Dis",
          "Acc_mode", "Refresh", "Nop", "(", ")", ",", ";", " ", "\n", "#", "//", ".unit",
          "dac", "pixel", "0", "1", "-1", "4095", "4096", "0.5", "-0.0078125", "1e300",
          "0.9375.0", "0xfff.c00000", "0x7ff.ffffff", "0x1", "2047.9999999999", "-2048",
          "nan", "inf", "\t", "\x00", "é", "\r\n", "1_000", "٣"]


def check(err: AsmError):
    lines = str(err).splitlines()
    assert lines and all(LOC.match(ln) for ln in lines), str(err)


def parse_or_check(text):
    try:
        cmds = parse_text(text, NAME)
    except AsmError as e:
        check(e)
        return None
    for c in cmds:  # whatever parses is valid and prints back exactly
        c.validate()
        assert parse_text(format_command(c)) == [c]
    return cmds


@FUZZ
@given(st.text())
def test_random_text(text):
    parse_or_check(text)


@FUZZ
@given(st.lists(st.sampled_from(TOKENS), max_size=40).map("".join))
def test_token_soup(text):
    parse_or_check(text)


@FUZZ
@given(st.lists(commands_st(), min_size=1, max_size=6), st.data())
def test_mutated_valid_files(cmds, data):
    text = "\n".join(format_command(c) for c in cmds)
    pos = data.draw(st.integers(0, len(text)))
    junk = data.draw(st.sampled_from(TOKENS) | st.text(max_size=3))
    cut = data.draw(st.integers(0, 3))
    parse_or_check(text[:pos] + junk + text[pos + cut:])


def load_or_check(blob):
    try:
        binfmt.load_commands(blob, NAME)
    except AsmError as e:
        check(e)


@FUZZ
@given(st.binary(max_size=64))
def test_random_bytes(blob):
    load_or_check(blob)


HEADERS = [b"DE48\0\x01\0\0", b"DE32\0\x01\x00\x00", b"DE32\0\x01\x04\x01", b"DE32\0\x01\x02\x03",
           b"DE48\0\x02\0\0", b"DE4", b""]


@FUZZ
@given(st.sampled_from(HEADERS), st.binary(max_size=120))
def test_random_bodies_behind_headers(head, body):
    load_or_check(head + body)


@FUZZ
@given(st.lists(st.tuples(st.sampled_from(sorted(isa.ID_NAME) + [0x123, 0xFFF]),
                          st.sampled_from([0, 1, 1 << 24, isa.WORD_MASK])), max_size=14))
def test_random_slot_streams(slots):
    try:
        cmds = binfmt.deserialise(slots, NAME)
    except AsmError as e:
        check(e)
    else:
        assert isa.serialise(cmds) == slots  # anything accepted re-serialises identically


@FUZZ
@given(st.lists(st.integers(0, 0xFFFFFFFF), max_size=16), st.integers(0, 4), st.booleans())
def test_random_framestore_words(words, w, comp):
    try:
        cmds = binfmt.deserialise(binfmt.framestore_slots(words, w, comp), NAME)
    except AsmError as e:
        check(e)
        return
    for c in cmds:
        c.validate()
