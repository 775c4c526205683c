"""servoctl ui's first line is an address a browser opens, whatever
--bind says (no browser here: urllib asks for the page)."""
import urllib.request

from servoctl.sim import Simulator
from ..ui_launch import UiProcess


def test_the_address_of_an_ipv6_bind_opens_the_page():
    """--bind ::1 printed http://::1:PORT/?token=..., which no browser
    opens: an IPv6 address goes in brackets."""
    with Simulator(ids=[1], fast=True) as sim, UiProcess(sim, ["--bind", "::1"]) as ui:
        assert ui.url.startswith("http://[::1]:"), ui.first_line
        with urllib.request.urlopen(ui.url, timeout=10) as r:
            assert r.status == 200 and b"STOP ALL" in r.read()
