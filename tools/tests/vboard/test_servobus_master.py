"""servobus's bus master for the reference board (tools/servobus/examples/mcu,
the arm preset's servobus_master.img) runs on a virtual STM32F103 behind
its bootloader, and moves a servo of servo_sim through the callback
transport: the board's USART1 is joined to servo_sim's bus by a bridge
that carries bytes between the two simulators' host ports (each a TCP
port; raw host links, each byte as it ends on its wire). It pings, reads
and moves servo 1 between -45 and +45 degrees; the test waits, on
servo_sim's clock, until the servo has been at both."""
import select
import socket
import threading

import pytest

from servoctl.servo import Servo
from servoctl.sim import Simulator

from ..launchers import REPO

IMAGE = REPO / "build" / "arm" / "tools" / "servobus" / "examples" / "mcu" / "servobus_master.img"


def _connect(url: str) -> socket.socket:
    host, port = url.removeprefix("socket://").rsplit(":", 1)
    s = socket.create_connection((host, int(port)), timeout=5)
    s.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
    return s


class Bridge(threading.Thread):
    """Bytes from each simulator's host port to the other's, until stopped."""

    def __init__(self, a: str, b: str):
        super().__init__(daemon=True)
        self.a, self.b = _connect(a), _connect(b)
        self.stopped = threading.Event()

    def run(self):
        peer = {self.a: self.b, self.b: self.a}
        while not self.stopped.is_set():
            ready, _, _ = select.select(list(peer), [], [], 0.05)
            for s in ready:
                data = s.recv(4096)
                if not data:
                    return
                peer[s].sendall(data)

    def stop(self):
        self.stopped.set()
        self.join(timeout=5)
        self.a.close()
        self.b.close()


def test_the_bus_master_moves_a_servo_of_servo_sim(tmp_path):
    if not IMAGE.exists():
        pytest.fail(f"{IMAGE} is not built: cmake --preset arm && cmake --build --preset arm")
    with Simulator(ids=[1], state_dir=str(tmp_path / "sim"), host_link="raw") as sim:
        with sim.bus(timeout=0.2) as bus:
            Servo(bus, 1).write("soft_start_on", 0)
        with Simulator(ids=[9], state_dir=str(tmp_path / "board"), board="stm32f103", app_image=IMAGE,
                       host_link="raw") as board:
            bridge = Bridge(sim.url, board.url)
            bridge.start()
            try:
                seen = set()

                def at_both():
                    angle = sim.state(1)["angle"]
                    seen.update(side for side, near in ((1, angle > 44.0), (-1, angle < -44.0)) if near)
                    return seen == {1, -1}

                # On the board's clock: the master runs on it, and a loaded PC slows the emulated
                # board while servo_sim keeps to the wall clock.
                board.wait_until(at_both, timeout_s=60.0, step_s=0.05)
            finally:
                bridge.stop()
