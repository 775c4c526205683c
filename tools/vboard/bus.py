"""The half-duplex bus wire between the host and the virtual boards, in
simulated time (as servo_sim's, firmware/boards/host_sim/sim_bus.h).

A byte takes 10 bit times at its sender's rate and reaches every receiver
(the sender's own USART too: it hears itself unless its receiver is off)
when its stop bit ends. A byte that overlaps another sender's byte already
on the wire garbles it, by servo_sim's rule (its C, wire_overlap.h): the
receivers, framed on the byte already there, sample the middle of its bits
while the line is low if either drives it low, and get nothing of the later
byte's own framing; two drivers are never in step, a bit apart at least.
`garbled` counts such bytes, `collisions` a board's byte sent over another
board's. The host's bytes go out paced at the
host's rate (115200 until `hostbaud` says otherwise) after whatever is on
the wire; the bus reads the host only while less than 10 ms of its bytes
wait, as behind a real UART. The host is a TCP client (pyserial
socket://) or a pseudo-terminal, behind a USB-serial adapter (usb.py) that
hands it the bytes off the wire in USB packets."""
import heapq
import os
import pty
import select
import socket
import tty

from servoctl.codec import ANSWER_FRAME_MAX

from .native import wire_overlap
from .usb import Adapter

FRAME_BITS = 10
HOST = -1
BACKLOG_S = 0.01
# The fastest a host answers a byte it has been handed (usb.py): its next
# request goes out at the next high-speed microframe, 125 us (USB 2.0). A
# host faster than the servo's turnaround (its receiver back on a few us
# after its last stop bit) would not exist; without this the runner, ahead
# of the wall clock, stamped a reply at the very instant the answer ended.
HOST_TURNAROUND_S = 125e-6
# A second TCP client while one holds the bus is told so (servo_sim's
# words, which servoctl recognises) and ignored until it leaves.
BUS_IN_USE = b"vboard: the bus is in use by another client\n"
# A client taken in place of one that left hears no servo byte that began
# before its own first byte, up to the longest answer's time after what
# the wire holds (sim_bus.c, sim_bus_new_host): that answers the one that
# left: the longest answer's time, and 5 ms.
ANSWER_SLACK_S = 0.005


class Bus:
    def __init__(self, host_link: str = "usb"):
        self.adapter = Adapter(host_link)  # ValueError: a mode that is none
        self.stations = []        # USART models
        self.events = []          # (end_s, seq, byte, baud, sender)
        self.seq = 0
        self.wire_until_s = 0.0
        self.last_sender = None
        self.host_baud = 115200
        self.host_queue_until_s = 0.0
        self.to_host = bytearray()
        self.collisions = 0
        self.garbled = 0
        self.last_activity_s = -1.0   # end of the last byte queued
        self.heard_by_host_s = -1.0   # when the host was last handed bytes (HOST_TURNAROUND_S)
        self.last_sent_s = {}         # station -> when its last byte started
        self.host_bytes = 0           # bytes handed to the host so far
        self.host_bytes_then = 0      # ... when the host last sent bytes itself
        self.host_read = 0            # bytes read from the host in all (a paced host's offset 16)
        self.paced = False            # read the host's bytes at once (run.py, --clock paced)
        self.host_fd = None
        self.listen = None
        self.master_fd = None
        self.link_path = None
        self.refused = []
        self._next = None  # a client come while the last one leaves (_in_place_of_one_leaving)
        self.deaf_before_s = -1.0  # a servo byte begun before this is not the connected client's

    def attach(self, usart) -> int:
        self.stations.append(usart)
        return len(self.stations) - 1

    # ---- the host's side ----------------------------------------------------
    def serve_tcp(self, port: int) -> str:
        self.listen = socket.socket()
        self.listen.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        self.listen.bind(("127.0.0.1", port))
        self.listen.listen(1)
        self.listen.setblocking(False)
        return f"socket://127.0.0.1:{self.listen.getsockname()[1]}"

    def serve_pty(self, link=None) -> str:
        master, slave = pty.openpty()
        tty.setraw(slave)
        os.set_blocking(master, False)
        self.master_fd, self.host_fd = master, master
        name = os.ttyname(slave)
        self._slave = slave
        if link:
            if os.path.lexists(link):
                os.unlink(link)
            os.symlink(name, link)
            self.link_path = link
        return name

    def fds(self) -> list:
        """What to wait on for the host."""
        out = [] if self.host_fd is None else [self.host_fd]
        if self.listen is not None:
            out.append(self.listen)
        return out + self.refused

    def _refused_leave(self) -> None:
        """A refused client is told again at every request it sends (one
        that flushes its input as it opens missed the first telling), and
        forgotten when it leaves."""
        for conn in list(self.refused):
            try:
                if conn.recv(256) != b"":
                    conn.send(BUS_IN_USE)
                    continue
            except BlockingIOError:
                continue
            except OSError:
                pass
            conn.close()
            self.refused.remove(conn)

    def poll_host(self, now_s: float) -> None:
        """Reads what the wire can take; takes a client, or tells a second
        one the bus is in use; writes what has reached the host."""
        self._refused_leave()
        if self.host_fd is not None:
            self._read_host(now_s)
        if self.listen is not None:
            try:
                conn, _ = self.listen.accept()
            except BlockingIOError:
                conn = None
            if conn is not None and self.host_fd is not None and self._in_place_of_one_leaving(conn):
                conn = None
            if conn is not None and self.host_fd is not None:
                conn.setblocking(False)
                try:
                    conn.send(BUS_IN_USE)
                except OSError:
                    pass
                self.refused.append(conn)
            elif conn is not None:
                self._take(conn, now_s)
        self.flush_to_host(now_s)

    def _take(self, conn, now_s: float) -> None:
        conn.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        conn.setblocking(False)
        self._conn = conn
        self.host_fd = conn.fileno()
        self.to_host.clear()
        self.adapter.held.clear()  # the answers to one that left are not its
        longest = ANSWER_FRAME_MAX * FRAME_BITS / self.host_baud + ANSWER_SLACK_S
        self.deaf_before_s = max(self.wire_until_s, now_s) + longest

    def _in_place_of_one_leaving(self, conn) -> bool:
        """A client that came while the one on the bus has hung up, its last
        bytes still unread (a loaded PC held this process up while one
        servoctl sent a request and left and the next started): kept, and
        taken once those bytes are read and the leaving seen, not told the
        bus is in use. False for any other (refused)."""
        if self._next is not None:
            return False
        hung_up = select.poll()
        hung_up.register(self.host_fd, select.POLLRDHUP)
        if not hung_up.poll(0):
            return False
        self._next = conn
        return True

    def _read_host(self, now_s: float) -> None:
        # Paced, the boards wait until they have read all the host sent.
        if self.paced or self.host_queue_until_s - now_s < BACKLOG_S:
            try:
                data = os.read(self.host_fd, 256)
            except BlockingIOError:
                data = None
            except OSError:
                data = b""
            if data == b"" and self.listen is not None:
                self._drop_client(now_s)
                return
            if data:
                self.host_bytes_then = self.host_bytes
                self.host_read += len(data)
            for byte in data or b"":
                self.queue_host(byte, max(now_s, self.heard_by_host_s + HOST_TURNAROUND_S))

    def flush_to_host(self, now_s: float) -> None:
        """Writes what the adapter has handed over by now_s."""
        data, at_s = self.adapter.take(now_s)
        if at_s is not None:
            self.to_host += data
            self.heard_by_host_s = at_s
            self.host_bytes += len(data)
        if self.to_host and self.host_fd is not None:
            try:
                n = os.write(self.host_fd, bytes(self.to_host))
                del self.to_host[:n]
            except (BlockingIOError, OSError):
                pass

    def _drop_client(self, now_s: float) -> None:
        self._conn.close()
        self.host_fd = None
        self.to_host.clear()
        self.adapter.held.clear()
        if self._next is not None:
            self._next, conn = None, self._next
            self._take(conn, now_s)

    def queue_host(self, byte: int, now_s: float) -> None:
        """A host byte on the wire from now_s, after the host's earlier
        bytes and whatever is on the wire."""
        start = max(now_s, self.host_queue_until_s, self.wire_until_s)
        self.deaf_before_s = min(self.deaf_before_s, start)  # from its first byte, answers may be its
        end = start + FRAME_BITS / self.host_baud
        self.host_queue_until_s = end
        self.wire_until_s = max(self.wire_until_s, end)
        self._push(start, end, byte, self.host_baud, HOST)

    # ---- the boards' side -------------------------------------------------
    def send(self, station: int, byte: int, baud: int, start_s: float) -> None:
        end = start_s + FRAME_BITS / baud
        busy = start_s < self.wire_until_s - 1e-9
        self.wire_until_s = max(self.wire_until_s, end)
        self.last_sender = station
        self.last_sent_s[station] = start_s
        if busy and self._garble(start_s, end, byte, station):
            self.last_activity_s = max(self.last_activity_s, end)
        else:
            self._push(start_s, end, byte, baud, station)

    def _garble(self, start_s, end_s, byte, sender) -> bool:
        """The wire's rule (sim_bus.c, garble): a byte overlapping another
        sender's byte on the wire garbles it and is not heard itself."""
        hit = [e for e in self.events if e[4] != sender and e[5] < end_s - 1e-9 and e[0] > start_s + 1e-9]
        for e in hit:
            e[2] = wire_overlap(e[2], byte, start_s - e[5], e[0] - e[5])
        self.garbled += bool(hit)
        self.collisions += sender != HOST and any(e[4] != HOST for e in hit)
        return bool(hit)

    def _push(self, start_s, end_s, byte, baud, sender) -> None:
        self.last_activity_s = max(self.last_activity_s, end_s)
        self.seq += 1
        heapq.heappush(self.events, [end_s, self.seq, byte, baud, sender, start_s])

    def host_answered(self, host_received: int = 0) -> bool:
        """The host has been handed bytes since it last sent any, more than
        it says it has read (a paced host, else 0), and the wire and the
        adapter hold none (servo_sim's host_answered)."""
        return (self.host_bytes != self.host_bytes_then and self.host_bytes > host_received
                and not self.events and not self.adapter.held)

    def next_event_s(self) -> float:
        """The next byte's end on the wire, or the adapter's next hand-over."""
        wire = self.events[0][0] if self.events else float("inf")
        return min(wire, self.adapter.due_s())

    def deliver_until(self, t_s: float) -> None:
        while self.events and self.events[0][0] <= t_s:
            end_s, _, byte, baud, sender, start_s = heapq.heappop(self.events)
            for usart in self.stations:
                usart.receive(byte, baud)
            if sender != HOST and abs(baud - self.host_baud) <= 0.03 * self.host_baud and \
                    start_s >= self.deaf_before_s:
                self.adapter.hold(byte, end_s, baud)

    def close(self) -> None:
        if self.link_path and os.path.lexists(self.link_path):
            os.unlink(self.link_path)
