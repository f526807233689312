"""Not only ptys: a camera behind a serial-to-Ethernet converter, read as ``socket://host:port``.

The converter drops the connection (EOF: pyserial raises "socket disconnected"); the reader reconnects
by the same URL and carries on.  Loopback TCP only.
"""

from __future__ import annotations

import socket
import threading

from ttt_sm.smartcam import encode_frame


def converter(server: socket.socket, stop: threading.Event, values) -> None:
    """First connection: 5 frames, then hang up.  Second: frames until stopped."""
    seq = 0
    for connection in range(2):
        server.settimeout(30)
        try:
            conn, _ = server.accept()
        except OSError:
            return
        with conn:
            sent = 0
            while not stop.wait(0.02) and (connection == 1 or sent < 5):
                try:
                    conn.sendall(encode_frame(seq, values(seq)))
                except OSError:
                    break
                seq, sent = seq + 1, sent + 1


def test_a_socket_url_reconnects_after_the_peer_hangs_up(open_reader, values, read_until):
    server = socket.create_server(("127.0.0.1", 0))
    stop = threading.Event()
    thread = threading.Thread(target=converter, args=(server, stop, values), daemon=True)
    thread.start()
    try:
        reader = open_reader(f"socket://127.0.0.1:{server.getsockname()[1]}")
        read_until(reader, lambda: reader.stats.reconnects == 1)
        n = reader.stats.frames_ok
        frames = read_until(reader, lambda: reader.stats.frames_ok >= n + 3)
        assert all(f.percentages == tuple(values(f.seq)) for f in frames)
        assert reader.stats.disconnects == 1 and reader.stats.rejected == {}
    finally:
        stop.set()
        server.close()
        thread.join(30)
