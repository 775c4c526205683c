"""servoctl ui's doorman (servoctl.ui.doorman) under a flood of
connections without the token that each send a byte: a browser's new
connection, silent for the moment its request takes to come, was the
first closed (the oldest silent one), so a quarter of page loads and
reconnects failed beside six flooders. Now the oldest goes first, and a
silent one only once it has been silent for SILENT_S."""
import asyncio

from servoctl.ui.doorman import Doorman


class Transport:
    def __init__(self, name):
        self.name, self.aborted = name, False

    def abort(self):
        self.aborted = True


def run(body):
    async def main():
        return body(Doorman(lambda: None, untrusted_max=4))
    return asyncio.run(main())


def test_a_new_silent_connection_outlives_a_flood_that_sends_a_byte():
    def body(door):
        flood = [Transport(f"flood{k}") for k in range(4)]
        for t in flood:
            door.admit(t)
            door.heard(t)  # "G"
        browser = Transport("browser")
        door.admit(browser)  # silent for now: its request is on its way
        more = Transport("flood4")
        door.admit(more)
        door.heard(more)
        return flood, browser
    flood, browser = run(body)
    assert not browser.aborted
    assert flood[0].aborted and flood[1].aborted and not flood[2].aborted


def test_a_connection_silent_for_long_goes_first():
    def body(door):
        idle = Transport("idle")
        door.admit(idle)
        door.silent[idle] -= 1.0  # opened a second ago, nothing sent since
        busy = [Transport(f"busy{k}") for k in range(3)]
        for t in busy:
            door.admit(t)
            door.heard(t)
        door.admit(Transport("new"))
        return idle, busy
    idle, busy = run(body)
    assert idle.aborted and not any(t.aborted for t in busy)
