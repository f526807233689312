"""An emulated device's loop in a background thread, and the flag that ends it.

Each emulator (the camera's, the arm's) runs its device in a daemon thread
beside the program that talks to it over the pty.  :class:`DeviceThread` is
that thread's life: :meth:`~DeviceThread.start` once, :meth:`~DeviceThread.stop`
sets :attr:`~DeviceThread.stopping` and waits for the loop to see it.
"""

from __future__ import annotations

import threading
from collections.abc import Callable


class DeviceThread:
    """Runs `loop` in a daemon thread named `name` until :meth:`stop`.

    The loop ends when :attr:`stopping` is set: it checks the flag each turn
    and waits on it (``stopping.wait(seconds)``) rather than sleeping, so a
    stop is seen at once.  Started again after a stop, the loop runs anew.
    """

    def __init__(self, loop: Callable[[], None], name: str) -> None:
        self._loop = loop
        self.name = name
        #: Set by :meth:`stop`: the loop returns when it sees it.
        self.stopping = threading.Event()
        self._thread: threading.Thread | None = None

    @property
    def started(self) -> bool:
        """Started and not stopped since (the loop may have returned on its own)."""
        return self._thread is not None

    @property
    def running(self) -> bool:
        """The loop is running now."""
        return self._thread is not None and self._thread.is_alive()

    def start(self) -> None:
        """Run the loop in a new daemon thread; nothing if it was started already."""
        if self._thread is not None:
            return
        self.stopping.clear()
        self._thread = threading.Thread(target=self._loop, name=self.name, daemon=True)
        self._thread.start()

    def stop(self, timeout_s: float = 5.0) -> bool:
        """Tell the loop to end and wait for it at most `timeout_s`; False if it is still running then."""
        self.stopping.set()
        thread, self._thread = self._thread, None
        if thread is None:
            return True
        thread.join(timeout_s)
        return not thread.is_alive()


__all__ = ["DeviceThread"]
