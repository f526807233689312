"""The firmware's receive path fuzzed under AddressSanitizer and UndefinedBehaviorSanitizer.

ctypes shows what the C answers, not whether it read past a buffer on the
way.  Here the same firmware sources are compiled with
``-fsanitize=address,undefined`` into a small program (``fuzz_rx.c``) that
takes fuzz cases on its standard input; any out-of-bounds access or
undefined behaviour kills it with a report, which fails the test.  Its
counts must equal the PC's decoder's, as in test_link.py.
"""

from __future__ import annotations

import logging
import shutil
import struct
import subprocess
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from test_link import _framing, _segments, broken_streams  # tests/hardware is on sys.path (rootdir-less)

from ttt_sm.hardware import firmware
from ttt_sm.hardware import link as L

R = L.Reason
FLAGS = ["-fsanitize=address,undefined", "-fno-sanitize-recover=all", "-g", "-O1"]


@pytest.fixture(scope="module")
def fuzzer(tmp_path_factory):
    cc = firmware.compiler()
    root = firmware.firmware_root()
    exe = tmp_path_factory.mktemp("fuzz") / "fuzz_rx"
    std = [f for f in firmware.CFLAGS if not f.startswith("-O")]
    command = [cc, *std, *FLAGS, f"-I{root / 'include'}", *map(str, firmware.sources(root)),
               str(Path(__file__).with_name("fuzz_rx.c")), "-o", str(exe)]
    done = subprocess.run(command, capture_output=True, text=True, check=False)
    if done.returncode != 0 and "asan" in done.stderr.lower() and shutil.which(cc):
        pytest.skip(f"no sanitizer runtime for {cc}: {done.stderr.strip()[:200]}")
    assert done.returncode == 0, done.stderr
    proc = subprocess.Popen([str(exe)], stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    yield proc
    proc.stdin.close()  # type: ignore[union-attr]
    proc.wait(10)
    assert proc.returncode == 0, proc.stderr.read().decode()  # type: ignore[union-attr]


def _run(proc, data: bytes, cut: int) -> tuple[int, dict[R, int]]:
    proc.stdin.write(struct.pack("<IB", len(data), cut & 0xFF) + data)
    proc.stdin.flush()
    line = proc.stdout.readline()
    if not line:
        proc.wait(10)
        pytest.fail(f"the sanitized firmware died:\n{proc.stderr.read().decode()[-3000:]}")
    ok, *counts = map(int, line.split())
    return ok, {R(r): n for r, n in enumerate(counts)}


def _pc(data: bytes) -> tuple[list[L.Message], L.Receiver]:
    pc = L.Receiver(accepts=L.TO_FIRMWARE)
    logging.getLogger("ttt_sm.link").disabled = True
    try:
        return pc.feed(data), pc
    finally:
        logging.getLogger("ttt_sm.link").disabled = False


@settings(max_examples=500, deadline=None)
@given(data=st.binary(max_size=3000), cut=st.integers(0, 255))
def test_any_bytes_under_the_sanitizers(fuzzer, data, cut):
    ok, counts = _run(fuzzer, data, cut)
    messages, pc = _pc(data)
    assert ok + sum(counts.values()) == _segments(data)
    assert _framing(counts) == _framing(pc.rejections)


@settings(max_examples=500, deadline=None)
@given(data=broken_streams(), cut=st.integers(0, 255))
def test_broken_streams_under_the_sanitizers(fuzzer, data, cut):
    ok, counts = _run(fuzzer, data, cut)
    messages, pc = _pc(data)
    assert _framing(counts) == _framing(pc.rejections)
    assert ok + counts[R.REFUSED] + counts[R.LATE] + counts[R.VALUE] == len(messages) + pc.rejections.get(R.VALUE, 0)
