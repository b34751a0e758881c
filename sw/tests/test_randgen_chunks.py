"""randgen.chunks (the long scoreboard streams of make test-long): the pieces are the
stream itself, cut at line ends, and each piece's golden frame is its rows of the whole
frame, so the scoreboard may model and compare a 10^7-command stream piece by piece."""
import numpy as np
import pytest

from diffengine.formats import binfmt
from diffengine.model import functional
from diffengine import isa
from diffengine.regress import randgen


@pytest.mark.parametrize("chunk", [1, 50, 700, 10**6])
def test_chunks_join_to_the_stream(chunk):
    whole = randgen.stream(11, 3000, 27, (1, 40))
    pieces = list(randgen.chunks(11, 3000, 27, (1, 40), chunk))
    assert [c for p in pieces for c in p] == whole
    assert all(p[-1].op == "REFRESH" for p in pieces)


def test_a_stream_of_one_line_is_one_chunk():
    pieces = list(randgen.chunks(2, 1, 9, (1, 3), 100))
    assert len(pieces) == 1 and pieces[0][-1].op == "REFRESH"


@pytest.mark.parametrize("bug", [False, True])
def test_piecewise_model_and_words_equal_the_whole(bug):
    whole = randgen.stream(5, 2000, 27, (1, 40))
    pieces = list(randgen.chunks(5, 2000, 27, (1, 40), 300))
    assert len(pieces) > 3
    frame = np.concatenate([functional.render(p, 27, carry_bug=bug) for p in pieces])
    assert np.array_equal(frame, functional.render(whole, 27, carry_bug=bug))
    body = b"".join(binfmt.encode_de48(isa.serialise(p))[binfmt.HEADER_LEN:] for p in pieces)
    assert binfmt.encode_de48([]) + body == binfmt.encode_de48(isa.serialise(whole))
