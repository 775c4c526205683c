"""The baud rate over a simulator's TCP link (socket://), which carries no
rate of its own: the simulator's control port sets its host's (hostbaud).
--baud is set there given --sim-control, else refused (it did nothing); a
baud change says what to do, or does it; scan reports the rate the servo
speaks, not pyserial's idea of a socket's."""
from servoctl.cli import main


def run(sim, capsys, *args):
    rc = main(["--port", sim.url, *args], clock=sim.clock_s)
    out = capsys.readouterr()
    return rc, out.out, out.err


def test_baud_on_a_socket_is_set_through_the_control_port_or_refused(sim, capsys):
    rc, _, err = run(sim, capsys, "--baud", "1000000", "ping", "1")
    assert rc == 2 and "socket:// carries no baud rate: --baud 1000000 would be ignored" in err, err
    assert "'hostbaud 1000000'" in err and sim.state(1)["host_baud"] == 115200
    control = str(sim.control_port)
    rc, out, err = run(sim, capsys, "--baud", "115200", "--sim-control", control, "ping", "1")
    assert rc == 0, out + err


def test_a_baud_change_on_a_socket_says_what_to_do_or_does_it(sim, capsys):
    rc, out, _ = run(sim, capsys, "config", "set", "1", "baud", "1000000")
    assert rc == 0 and ("servo 1 now speaks 1000000 baud, and socket:// carries no baud rate: on a "
                        "simulator, send 'hostbaud 1000000' to its control port") in out, out
    rc, _, _ = run(sim, capsys, "ping", "1")
    assert rc == 3  # the simulator's host still at 115200: as said
    control = str(sim.control_port)
    rc, out, err = run(sim, capsys, "--baud", "1000000", "--sim-control", control, "config", "set", "1",
                       "baud", "115200")
    assert rc == 0 and sim.state(1)["host_baud"] == 115200, out + err
    assert "the simulator's host rate is set to 115200 too" in out, out
    rc, out, err = run(sim, capsys, "--sim-control", control, "ping", "1")
    assert rc == 0, out + err


def test_scan_reports_the_rate_the_servo_speaks(sim, capsys):
    rc, out, _ = run(sim, capsys, "config", "set", "1", "baud", "1000000")
    assert rc == 0
    sim.control("hostbaud 1000000")
    rc, out, err = run(sim, capsys, "scan", "--last", "2")
    assert rc == 0 and "servo 1 at 1000000 baud, serial 0x51a00001" in out, out + err
    rc, out, _ = run(sim, capsys, "scan", "--last", "2", "--json")
    assert rc == 0 and '"baud": 1000000' in out


def test_no_reply_on_a_socket_names_the_simulators_host_rate(sim, capsys):
    """--sim-control with --baud leaves the simulator's host rate changed
    after servoctl exits: a later plain command's "no reply" says so."""
    control = str(sim.control_port)
    run(sim, capsys, "--baud", "1000000", "--sim-control", control, "ping", "1")  # the servo at 115200
    rc, out, _ = run(sim, capsys, "ping", "1")
    assert rc == 3 and "no reply; if the simulator's host rate was changed" in out, out
    rc, _, err = run(sim, capsys, "info", "1")
    assert rc == 3 and "if the simulator's host rate was changed" in err, err
    rc, _, err = run(sim, capsys, "--sim-control", control, "info", "1")
    assert rc == 3 and "the simulator's host rate is 1000000 baud: if the servo speaks another" in err, err
    sim.control("hostbaud 115200")
