"""An emulator's loop in a daemon thread: started once, stopped by its flag, started again."""

from __future__ import annotations

import threading

from ttt_sm.ptylink import DeviceThread


def test_a_loop_runs_until_stopped_and_can_run_again():
    turns: list[str] = []
    ran = threading.Event()

    def loop() -> None:
        while not device.stopping.is_set():
            turns.append(threading.current_thread().name)
            ran.set()
            device.stopping.wait(0.001)

    device = DeviceThread(loop, "a-device /tmp/dev")
    assert not device.started and not device.running
    device.start()
    assert ran.wait(5.0) and device.started and device.running
    first = threading.enumerate()
    device.start()  # started already: no second thread
    assert len(threading.enumerate()) == len(first)
    assert device.stop(5.0) and not device.started and not device.running
    assert set(turns) == {"a-device /tmp/dev"}
    ran.clear()
    device.start()  # the flag is cleared: the loop runs anew
    assert ran.wait(5.0) and device.running
    assert device.stop(5.0)


def test_a_stop_says_when_the_loop_did_not_end_in_time():
    release = threading.Event()
    device = DeviceThread(lambda: release.wait(10.0), "stuck")  # ignores the flag
    device.start()
    assert device.stop(0.05) is False and device.stopping.is_set()
    release.set()
    assert DeviceThread(lambda: None, "never started").stop() is True
