"""Who may reach the cockpit: its token, the Host names it answers to, the address it prints.

As Jupyter does: every start makes a token (loopback included), printed in the
URL (``http://HOST:PORT/charts?token=...``) and given to ``--open``; a request
without it is refused (the first visit with it sets a cookie, so the pages'
later requests and their WebSocket carry it).  The ``Host`` header must name
this server by one of the addresses or names it listens on (no DNS
rebinding): :func:`allowed_hosts`.  Listening on every interface (``--host
0.0.0.0``), the URL names an address another machine reaches:
:func:`reachable_host`.

Only what is the same for everyone is public: the pages' scripts and styles
under ``/static/`` (they hold nothing of the session).  The HTML pages, the
diagrams, the trace, the pictures and the WebSocket need the token.
"""

from __future__ import annotations

import contextlib
import ipaddress
import socket
import struct
from collections.abc import Iterable

#: The names a loopback listener answers to.
LOOPBACK_NAMES = ("127.0.0.1", "localhost", "::1")
#: Paths anyone may fetch (the pages' scripts and styles: nothing of the session).
PUBLIC_PREFIXES = ("/static/",)


def cookie_name(port: int | None) -> str:
    """The token's cookie, one per port: cookies are not kept apart by port, two cockpits on one machine are."""
    return "ttt_sm_token" if not port else f"ttt_sm_token_{port}"


def port_of(host_header: str) -> int:
    """The port a ``Host`` header names (``127.0.0.1:8765``, ``[::1]:8765``), 80 when it names none."""
    if host_header.startswith("["):
        rest = host_header[host_header.find("]") + 1:]
        return int(rest[1:]) if rest.startswith(":") and rest[1:].isdigit() else 80
    head, colon, tail = host_header.rpartition(":")
    return int(tail) if colon and ":" not in head and tail.isdigit() else 80


def is_wildcard(host: str) -> bool:
    """``0.0.0.0``, ``::`` or empty: every interface."""
    return host in ("", "0.0.0.0", "::")


def is_loopback(host: str) -> bool:
    if host in LOOPBACK_NAMES:
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


def bracket(host: str) -> str:
    """An address as it stands in a URL or a Host header (IPv6 in brackets)."""
    return f"[{host}]" if ":" in host and not host.startswith("[") else host


def machine_addresses(ipv6: bool = True) -> set[str]:
    """The addresses of this machine's interfaces (Linux: each interface's IPv4 address and every IPv6 one),
    and what its host names resolve to."""
    found: set[str] = set()
    for _, name in _interfaces():
        with contextlib.suppress(OSError):
            found.add(_ipv4_of(name))
    if ipv6:
        with contextlib.suppress(OSError), open("/proc/net/if_inet6", encoding="ascii") as f:
            for line in f:
                raw = line.split()[0]
                if len(raw) == 32:
                    found.add(str(ipaddress.IPv6Address(bytes.fromhex(raw))))
    for name in machine_names():
        with contextlib.suppress(OSError, UnicodeError):
            for *_, sockaddr in socket.getaddrinfo(name, None):
                found.add(str(sockaddr[0]).split("%")[0])
    found.add(outward_address())
    return {a for a in found if a and (ipv6 or ":" not in a)}


def machine_names() -> set[str]:
    """This machine's host names (short and fully qualified)."""
    names = {socket.gethostname()}
    with contextlib.suppress(OSError):
        names.add(socket.getfqdn())
    return {n.lower() for n in names if n}


def outward_address() -> str:
    """The address this machine reaches others from (its default route's; no packet is sent), or 127.0.0.1."""
    with contextlib.suppress(OSError), socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.connect(("192.0.2.1", 9))  # TEST-NET-1: only routing is looked up
        return str(s.getsockname()[0])
    return "127.0.0.1"


def reachable_host(bind: str) -> str:
    """The host to print in the URL for a listener on ``bind``: itself, or for every interface an address
    another machine reaches (loopback when the machine has no other)."""
    if not is_wildcard(bind):
        return bind
    address = outward_address()
    if is_loopback(address):
        others = sorted(a for a in machine_addresses(ipv6=bind == "::") if not is_loopback(a)
                        and not ipaddress.ip_address(a).is_link_local)
        address = others[0] if others else "127.0.0.1"
    return address


def allowed_hosts(bind: str, port: int) -> list[str]:
    """The ``Host`` header values a listener on ``bind``:``port`` answers to: loopback's names, and the
    addresses and names of the interfaces it listens on; each as ``host:port``, and bare on port 80 (a
    browser leaves the default port out)."""
    names: set[str] = set(LOOPBACK_NAMES)
    if is_wildcard(bind):
        names |= machine_addresses(ipv6=bind == "::") | machine_names()
    else:
        names.add(bind.strip("[]").lower())
        with contextlib.suppress(OSError, UnicodeError):
            bound = {str(sa[0]).split("%")[0] for *_, sa in socket.getaddrinfo(bind.strip("[]"), None)}
            names |= bound
            for name in machine_names():  # this machine's names, when they resolve to the address bound
                with contextlib.suppress(OSError, UnicodeError):
                    if bound & {str(sa[0]) for *_, sa in socket.getaddrinfo(name, None)}:
                        names.add(name)
    return host_values(names, port)


def host_values(names: Iterable[str], port: int) -> list[str]:
    """``host:port`` for each name (IPv6 in brackets), and the bare name too on port 80."""
    out: list[str] = []
    for name in sorted(set(names)):
        shown = bracket(name.lower())
        out.append(f"{shown}:{port}")
        if port == 80:
            out.append(shown)
    return out


def _interfaces() -> list[tuple[int, str]]:
    try:
        return socket.if_nameindex()
    except OSError:
        return []


def _ipv4_of(name: str) -> str:
    import fcntl  # Linux (and the BSDs); elsewhere the names' addresses only

    siocgifaddr = 0x8915
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        packed = fcntl.ioctl(s.fileno(), siocgifaddr, struct.pack("256s", name.encode()[:15]))
    return socket.inet_ntoa(packed[20:24])
