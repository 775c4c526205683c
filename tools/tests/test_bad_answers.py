"""Every failure is one line and an exit code, never a traceback: a servo
whose answers are short (with a good checksum: garbled, another firmware,
two servos on one ID), and a link that drops in a way pyserial reports as
termios.error, which is not an OSError."""
import termios
import threading

import pytest

from servoctl import protocol as p
from servoctl.cli import main

from .launchers import FakeServo


class ShortAnswers(FakeServo):
    """A servo on a TCP socket that answers every request to it with its ID
    alone: a frame whose checksum is right and whose content is short."""

    def __init__(self):
        super().__init__(backlog=4)

    def _serve(self):
        while True:
            try:
                peer, _ = self.server.accept()
            except OSError:
                return
            threading.Thread(target=self._answer, args=(peer,), daemon=True).start()

    @staticmethod
    def _answer(peer):
        buf = b""
        with peer:
            while data := peer.recv(4096):
                buf += data
                while (start := buf.find(p.REQUEST_HEADER)) >= 0 and len(buf) >= start + 5:
                    length = buf[start + 3]
                    end = start + 4 + length + 1
                    if len(buf) < end:
                        break
                    code, content = buf[start + 2], buf[start + 4:end - 1]
                    buf = buf[end:]
                    if content:
                        peer.sendall(p.response_frame(code, content[:1]))


@pytest.fixture
def short():
    servo = ShortAnswers()
    yield servo
    servo.close()


@pytest.mark.parametrize("argv", [
    ["info", "1"], ["config", "get", "1", "angle_max"], ["config", "dump", "1"], ["move", "1", "10"],
    ["monitor", "1", "--count", "1", "--json"], ["store", "1"], ["backup", "{tmp}/b.json", "--ids", "1"],
    ["record", "1", "10", "--out", "{tmp}/rec"], ["stop", "1"],
])
def test_a_short_answer_is_one_line(short, capsys, tmp_path, argv):
    argv = [a.replace("{tmp}", str(tmp_path)) for a in argv]
    # A host-side fake servo: a loaded machine may not run it for a while.
    rc = main(["--port", short.url, "--timeout", "3", *argv])
    err = capsys.readouterr().err
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1, err
    assert rc == 3 and "servo 1: a " in err and " answer of 1 bytes" in err, err


def test_a_link_that_fails_in_termios_is_a_link_error(monkeypatch, capsys):
    """A dropped pty: pyserial raises termios.error from its flush."""
    import serial
    import serial.urlhandler.protocol_loop

    def gone(self):
        raise termios.error(5, "Input/output error")

    monkeypatch.setattr(serial.urlhandler.protocol_loop.Serial, "reset_input_buffer", gone)
    rc = main(["--port", "loop://", "ping", "1"])
    err = capsys.readouterr().err
    assert rc == 4 and "loop://" in err and "Input/output error" in err, err
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1, err
