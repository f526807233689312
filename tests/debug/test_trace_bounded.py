"""The debugger's trace is bounded in memory (the newest transitions) and whole in its trace file."""

from __future__ import annotations

import io

from ttt_sm.debug.debugger import Debugger
from ttt_sm.debug.shell import DebugShell
from ttt_sm.params import load_params
from ttt_sm.runtime.listeners import Trace
from ttt_sm.runtime.recordfile import read_lines
from ttt_sm.web.frames import ACTIONS_SHOWN
from ttt_sm.web.session import Session

P = load_params()


def test_the_trace_keeps_the_newest_transitions_and_streams_them_all(tmp_path) -> None:
    whole = Debugger.build(P, seed=3)
    whole.run(12.0)
    assert len(whole.trace.records) > 6  # the drives' initialisation: enough transitions to drop some
    path = tmp_path / "trace.jsonl"
    dbg = Debugger(whole.recipe.build(), whole.recipe, trace_path=path, trace_keep=4)
    stop = dbg.run(12.0)
    assert dbg.trace.count == len(whole.trace.records)
    assert dbg.trace.records == whole.trace.records[-4:] and dbg.trace.dropped == dbg.trace.count - 4
    assert list(stop.transitions) == whole.trace.records[-4:]  # what the run saw, as far as it is kept
    assert Trace.read_jsonl(path) == whole.trace.records  # the file has every one, flushed as it happened
    # `trace save` writes what is kept, and says where the rest is
    out = io.StringIO()
    DebugShell(dbg, stdout=out).onecmd(f"trace save {tmp_path / 'kept.jsonl'}")
    assert Trace.read_jsonl(tmp_path / "kept.jsonl") == whole.trace.records[-4:]
    assert f"4 transitions written to {tmp_path / 'kept.jsonl'} (the newest; " in out.getvalue()
    assert str(path) in out.getvalue()
    # a replay is a mark in the file, not the replayed transitions again; the end says where the session stood
    dbg.replay(10)
    dbg.end_trace("finished")
    lines = read_lines(path)
    assert lines[0]["event"] == "trace" and lines[0]["seed"] == 3
    assert lines[-2]["event"] == "replay" and lines[-2]["tick"] == 10
    assert lines[-1] == {"event": "finished", "tick": 10, "steps": dbg.robot.steps, "t": round(dbg.robot.t, 6),
                         "transitions": dbg.trace.count}
    assert sum(1 for e in lines if "event" not in e) == len(whole.trace.records)


def test_a_frame_lists_the_newest_actions_only() -> None:
    session = Session(Debugger.build(P, seed=0), speed=None, running=False)
    for k in range(ACTIONS_SHOWN + 10):
        session.debugger.set_input("DriveInit1", "stop", "1" if k % 2 else "0")
    frame = session.frames.state(stop=None)  # what a frame carries
    assert len(session.debugger.actions) == ACTIONS_SHOWN + 10  # all kept: a replay re-applies them
    assert frame["actions"] == [a.describe() for a in session.debugger.actions[-ACTIONS_SHOWN:]]
