"""A signal that lands inside numba's compiler (code that calls back into Python from C, where an
exception is swallowed) waits until that code returns, then stops the command."""

from __future__ import annotations

import os
import signal
import time
import weakref

import pytest

from ttt_sm.cli.common import Interrupted, terminate_interrupts

# A stand-in for code of numba's compiler: a function whose module is named as a numba module.
FOREIGN = '''
def compile_something(steps, kill):
    done = 0
    kill()
    for _ in range(steps):
        done += 1
        sum(range(200))
    return done
'''


@pytest.mark.parametrize("signum, raised", [(signal.SIGTERM, Interrupted), (signal.SIGINT, KeyboardInterrupt)])
def test_a_signal_inside_foreign_code_waits_for_it_to_return_then_stops(signum, raised) -> None:
    namespace: dict = {"__name__": "numba.core.fake_compiler"}
    exec(compile(FOREIGN, "<numba stand-in>", "exec"), namespace)  # noqa: S102
    before = {sig: signal.getsignal(sig) for sig in (signal.SIGTERM, signal.SIGINT, signal.SIGALRM)}
    restore = terminate_interrupts()
    try:
        with pytest.raises(raised) as info:
            done = namespace["compile_something"](20_000, lambda: os.kill(os.getpid(), signum))
            assert done == 20_000  # the foreign code ran to its end: the signal did not break into it
            deadline = time.monotonic() + 30.0  # the signal's next look comes 50 ms later
            while time.monotonic() < deadline:
                sum(range(200))
        assert info.type is raised
        if signum == signal.SIGTERM:
            assert info.value.signal == "SIGTERM"
    finally:
        restore()
    assert {sig: signal.getsignal(sig) for sig in before} == before  # the handlers the process had are back


def test_a_signal_in_plain_code_stops_at_once() -> None:
    restore = terminate_interrupts()
    try:
        with pytest.raises(Interrupted):
            os.kill(os.getpid(), signal.SIGTERM)
            for _ in range(1_000_000):  # the handler runs at the next bytecode
                pass
            raise AssertionError("SIGTERM did not stop the loop")
    finally:
        restore()


def test_a_signal_inside_a_weakref_callback_of_the_import_system_stops_once_it_returns() -> None:
    """Seen in CI: SIGTERM landed in importlib's module-lock callback; raised there it was only printed
    ('Exception ignored in: <function _get_module_lock.<locals>.cb>') and the command finished."""
    namespace: dict = {"__name__": "importlib._bootstrap",
                       "kill": lambda: os.kill(os.getpid(), signal.SIGTERM)}
    source = "def cb(ref):\n    kill()\n    for _ in range(20_000):\n        sum(range(200))\n"
    exec(compile(source, "<frozen importlib._bootstrap>", "exec"), namespace)  # noqa: S102

    class ModuleLock:
        pass

    restore = terminate_interrupts()
    try:
        with pytest.raises(Interrupted):
            lock = ModuleLock()
            ref = weakref.ref(lock, namespace["cb"])
            del lock  # the callback runs here, as the import system's does when a module lock is freed
            assert ref() is None
            deadline = time.monotonic() + 30.0
            while time.monotonic() < deadline:
                sum(range(200))
    finally:
        restore()
