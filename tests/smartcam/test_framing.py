"""The framer: sentences out of arbitrary chunks, garbage and cut lines reported, resync at the next '$'."""

from __future__ import annotations

from hypothesis import given, settings
from hypothesis import strategies as st

from ttt_sm.smartcam import MAX_SENTENCE_BYTES, LineFramer, Reason, Rejection, encode_frame

LINE = encode_frame(1, [12.5] * 25)
LINE2 = encode_frame(2, [0.0] * 25)

# Reproducible (derandomized) and without per-example deadlines: a loaded machine is slow, not wrong.
PROPERTY = settings(derandomize=True, max_examples=150, deadline=None)


def feed_all(chunks) -> list[bytes | Rejection]:
    framer = LineFramer()
    out: list[bytes | Rejection] = []
    for chunk in chunks:
        out += framer.feed(chunk)
    return out + framer.flush()


def kinds(out) -> list[str]:
    return ["line" if isinstance(x, bytes) else x.reason.value for x in out]


def test_whole_lines_come_out_whole():
    assert feed_all([LINE + LINE2]) == [LINE, LINE2]


def test_byte_by_byte_is_the_same():
    data = LINE + LINE2
    assert feed_all([data[i:i + 1] for i in range(len(data))]) == [LINE, LINE2]


def test_blank_lines_between_sentences_are_not_garbage():
    assert feed_all([b"\r\n" + LINE + b"\r\n\n" + LINE2]) == [LINE, LINE2]


def test_garbage_before_a_sentence_is_one_rejection_per_run():
    out = feed_all([b"\x00\xffnoise" + LINE + b"more\r\nnoise again\n" + LINE2])
    assert kinds(out) == ["garbage", "line", "garbage", "garbage", "line"]
    assert out[0].size == 7 and out[0].snippet == b"\x00\xffnoise"


def test_a_new_dollar_cuts_the_sentence_before_it():
    out = feed_all([LINE[:40] + LINE])
    assert kinds(out) == ["truncated", "line"]
    assert out[0].snippet == LINE[:40]


def test_a_runaway_line_is_overlong_and_the_next_sentence_still_comes():
    runaway = b"$TTT," + b"9" * 1000
    out = feed_all([runaway + b"\r\n" + LINE, runaway + LINE2])
    assert kinds(out) == ["overlong", "line", "overlong", "line"]
    assert out[0].size == len(runaway) + 2 and out[2].size == len(runaway)
    assert len(out[0].snippet) <= 64


def test_the_longest_valid_sentence_is_not_overlong():
    longest = encode_frame(65535, [100.0] * 25)
    assert len(longest) == MAX_SENTENCE_BYTES
    assert feed_all([longest]) == [longest]
    one_more = longest[:-2] + b"0\r\n"
    assert kinds(feed_all([one_more])) == ["overlong"]


def test_flush_reports_an_unfinished_sentence_as_truncated():
    framer = LineFramer()
    assert framer.feed(LINE[:50]) == [] and framer.pending == 50
    (rej,) = framer.flush("the link went down")
    assert rej.reason is Reason.TRUNCATED and "went down" in rej.detail and framer.pending == 0
    assert framer.feed(LINE) == [LINE]


pieces = st.lists(st.sampled_from([LINE, LINE2, LINE[:30], b"noise", b"\r\n", b"$", b"$" + b"7" * 300, b"\xff"]),
                  max_size=12)


@PROPERTY
@given(pieces, st.lists(st.integers(min_value=1, max_value=200), min_size=1, max_size=30))
def test_chunking_never_changes_the_output(parts, cuts):
    data = b"".join(parts)
    chunks, i, k = [], 0, 0
    while i < len(data):
        step = cuts[k % len(cuts)]
        chunks.append(data[i:i + step])
        i, k = i + step, k + 1
    assert feed_all(chunks) == feed_all([data])


@PROPERTY
@given(st.binary(max_size=500))
def test_after_any_garbage_the_next_sentence_is_found(garbage):
    out = feed_all([garbage + LINE])
    assert out[-1] == LINE


@PROPERTY
@given(st.binary(max_size=500))
def test_every_byte_is_accounted_for(data):
    # Each byte ends up in a sentence, a rejection, or is a blank line end: nothing vanishes silently.
    out = feed_all([data])
    covered = sum(len(x) if isinstance(x, bytes) else x.size for x in out)
    blank = len(data) - covered
    assert 0 <= blank <= data.count(b"\n") + data.count(b"\r")


def test_after_resync_the_tail_of_a_line_is_skipped_not_garbage():
    framer = LineFramer()
    framer.resync()
    assert framer.feed(LINE[60:] + LINE) == [LINE]
    assert framer.skipped == len(LINE) - 60
    assert kinds(framer.feed(b"noise\r\n" + LINE)) == ["garbage", "line"]  # only the first tail


def test_after_resync_a_tail_is_at_most_one_sentence_long():
    framer = LineFramer()
    framer.resync()
    out = framer.feed(b"\x7f" * 1000 + LINE)
    assert framer.skipped == MAX_SENTENCE_BYTES
    assert kinds(out) == ["garbage", "line"] and out[0].size == 1000 - MAX_SENTENCE_BYTES


@PROPERTY
@given(st.binary(max_size=400), st.integers(min_value=1, max_value=50))
def test_resync_is_chunking_invariant_too(data, step):
    def run(chunks):
        framer = LineFramer()
        framer.resync()
        out = []
        for c in chunks:
            out += framer.feed(c)
        return out + framer.flush(), framer.skipped
    assert run([data[i:i + step] for i in range(0, len(data), step)]) == run([data])
