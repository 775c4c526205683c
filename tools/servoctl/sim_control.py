"""servo_sim's control port (and a virtual board's), from the host: one
line, its reply (docs/simulator.md, "Control commands"); Simulator's and
link_rate's."""
import socket

from .errors import LinkError, ServoError


def fields(line: str) -> dict:
    """key=value pairs of a control reply: numbers as numbers."""
    out = {}
    for pair in line.split():
        key, value = pair.split("=", 1)
        try:
            out[key] = float(value) if "." in value else int(value, 0)
        except ValueError:
            out[key] = value
    return out


def control_command(port: int, line: str, timeout: float = 2.0) -> str:
    """One line to servo_sim's control port on 127.0.0.1:port; its reply.
    An "error: ..." reply raises ServoError."""
    try:
        with socket.create_connection(("127.0.0.1", port), timeout=timeout) as s:
            s.sendall(line.encode() + b"\n")
            s.shutdown(socket.SHUT_WR)
            reply = b""
            while chunk := s.recv(4096):
                reply += chunk
    except OSError as e:
        raise LinkError(f"servo_sim's control port 127.0.0.1:{port}: {e.strerror or e} "
                        f"(has the simulator stopped?)") from None
    text = reply.decode()
    if text.startswith("error"):
        raise ServoError(f"servo_sim: {text.strip()}")
    return text
