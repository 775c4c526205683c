"""scan and the servos it finds: two servos on one ID are
noticed (their answers arrive twice, or garbled), a servo waiting in its
bootloader is named as such with the command that recovers it, and a
socket:// link, which carries no baud rate, is scanned once."""
import json
import os
import sys

import pytest

from servoctl import protocol as p
from servoctl import update as upd
from servoctl.cli import main
from servoctl.servo import Servo
from servoctl.sim import Simulator

from ..launchers import FakeServo


def run(sim, capsys, *args):
    rc = main(["--port", sim.url, *args], clock=sim.clock_s)
    out = capsys.readouterr()
    return rc, out.out, out.err


def test_two_servos_on_one_id_are_found_out(tmp_path, capsys):
    """Servo 3 is given ID 2 behind servoctl's back (a raw WriteData). Both
    answer at 2 from then on, at once, and their answers garble each other
    on the wire as on a real one (never in step: no answer comes through
    whole). scan says two or more servos hold ID 2, how to learn their
    serial numbers, and exits 1.
    (Not the sim3 fixture: this bus collides on purpose.)"""
    with Simulator(fast=True, ids=[1, 2, 3], state_dir=str(tmp_path / "state")) as sim:
        with sim.bus() as bus:
            Servo(bus, 3).write("servo_id", 2)
        rc, out, err = run(sim, capsys, "scan", "--last", "5")
        assert rc == 1, out + err
        assert "servo 2 at 115200 baud: TWO OR MORE SERVOS hold this ID (0 good and " in out, out
        assert ("garbled answers). Connect them one at a time to learn their serial numbers "
                "('servoctl scan'), then 'servoctl id assign SERIAL N'") in out, out
        assert "servo 1 at 115200 baud, serial 0x51a00001" in out
        assert "at least 3 servo(s) found" in out
        assert "IDs held by two or more servos: 2" in err
        assert sim.state(1)["garbled"] > 0
        rc, out, _ = run(sim, capsys, "scan", "--last", "5", "--json")
        found = {f["id"]: f for f in json.loads(out)}
        assert rc == 1 and found[2]["shared"] and not found[1]["shared"]
        assert found[2]["serials"] == []
        # AssignId reaches one of them by its serial number.
        rc, _, err = run(sim, capsys, "id", "assign", "0x51a00003", "1")
        assert rc == 2 and "ID 1 already answers on this bus" in err, err  # nothing sent
        rc, out, _ = run(sim, capsys, "id", "assign", "0x51a00003", "7")
        assert rc == 0 and "servo serial 0x51a00003 is now ID 7" in out
        rc, out, _ = run(sim, capsys, "scan", "--last", "9", "--json")
        assert rc == 0 and [(f["id"], f["serials"], f["shared"]) for f in json.loads(out)] == [
            (1, [0x51A00001], False), (2, [0x51A00002], False), (7, [0x51A00003], False)]
        sim.control("powercycle")  # durable: still 7 after a restart
        sim.sleep(0.5)
        with sim.bus() as bus:
            assert Servo(bus, 7).read("serial") == 0x51A00003
        rc, _, err = run(sim, capsys, "id", "assign", "0x51a00009", "9")
        assert rc == 3 and "no servo with serial 0x51a00009 answered AssignId" in err, err


def test_bringup_numbers_new_servos_one_at_a_time(tmp_path, capsys):
    """A new servo answers at the factory ID 0; bringup gives it the first
    free ID from --first on (5 is taken) and waits for the next, which,
    here, never comes."""
    with Simulator(fast=True, ids=[0, 5], state_dir=str(tmp_path / "state")) as sim:
        rc, out, _ = run(sim, capsys, "id", "bringup", "--first", "5", "--count", "1")
        assert rc == 0 and "servo serial 0x51a00000 is now ID 6" in out, out
        rc, out, err = run(sim, capsys, "id", "bringup", "--count", "1", "--wait-s", "1")
        assert rc == 3 and "no servo alone at ID 0 within 1 s; 0 numbered" in err, out + err
        with sim.bus() as bus:
            assert Servo(bus, 6).read("serial") == 0x51A00000


class GarbledTwins(FakeServo):
    """Two servos on one ID as a real wire delivers them: their answers
    overlap and arrive as one damaged frame (a bad checksum)."""

    def _serve(self):
        try:
            peer, _ = self.server.accept()
        except OSError:
            return
        with peer:
            while data := peer.recv(4096):
                if data[:2] == p.REQUEST_HEADER and len(data) > 5 and data[4] == 7:
                    frame = bytearray(p.response_frame(data[2], data[4:-1]))
                    frame[-1] ^= 0x55  # two answers on top of each other
                    peer.sendall(bytes(frame))


def test_garbled_answers_at_one_id_are_reported_as_shared(capsys):
    twins = GarbledTwins()
    try:
        rc = main(["--port", twins.url, "--timeout", "1", "scan", "--first", "5", "--last", "9",
                   "--reply-timeout", "0.3"])
    finally:
        twins.close()
    out, err = capsys.readouterr()
    assert rc == 1, out + err
    assert "servo 7 at 115200 baud: TWO OR MORE SERVOS hold this ID" in out and "garbled" in out, out


def test_a_servo_in_its_bootloader_is_named_with_its_cure(sim, capsys):
    """Page 0 of its slot erased (an update cut short): the servo waits in
    its bootloader. scan says so; info, config and move say so instead of
    'no reply', each with the command that recovers it."""
    with sim.bus(timeout=0.2) as bus:
        bus.request(upd.UPDATE_ENTER, bytes([1]))
        upd._wait_for_mode(bus, 1, upd.MODE_BOOTLOADER)
        assert bus.request(upd.UPDATE_ERASE, bytes([1, 0, 0]))[1] == 1
    rc, out, _ = run(sim, capsys, "scan", "--last", "3")
    assert rc == 0 and ("servo 1 at 115200 baud: in its bootloader, no application runs "
                        "(no image): 'servoctl update 1 IMAGE' installs one") in out, out
    for argv in (["info", "1"], ["config", "get", "1", "angle_max"], ["move", "1", "10"]):
        rc, _, err = run(sim, capsys, *argv)
        assert rc == 3 and "servo 1 is in its bootloader, not its application (its slot: no image)" in err, err
        assert "'servoctl update 1 IMAGE'" in err and len(err.strip().splitlines()) == 1


def test_all_bauds_over_a_socket_scans_once(sim, capsys):
    """socket:// has no baud rate: the far end decides. A scan at every
    rate found the one servo at each of them (8 for 1)."""
    rc, out, err = run(sim, capsys, "scan", "--all-bauds", "--last", "3")
    assert rc == 0 and "1 servo(s) found" in out, out
    assert "socket:// carries no baud rate" in err


def test_a_bus_of_new_servos_is_counted_numbered_and_addressed_by_bus_id(tmp_path, capsys):
    """Four servos as they leave the factory, all at ID 0 (servo_sim
    refused an ID given twice). They answer together and their answers
    garble each other on the wire, as on the virtual boards' and a real
    one: scan finds ID 0 shared, and bringup, which needs each new servo's
    serial number, asks for one at a time and fails with the reason. By
    their serial numbers they are numbered one by one (id assign). The
    control port then addresses a servo by the ID it holds now, or by its
    serial number, not by the ID it started with."""
    with Simulator(fast=True, ids=[0, 0, 0, 0], state_dir=str(tmp_path / "state")) as sim:
        serials = [0x51A00000, 0x51A00100, 0x51A00200, 0x51A00300]
        rc, out, err = run(sim, capsys, "scan", "--last", "3")
        assert rc == 1 and "at least 2 servo(s) found" in out and "IDs held by two or more servos: 0" in err, out + err
        rc, out, err = run(sim, capsys, "id", "bringup", "--first", "1", "--count", "4", "--wait-s", "1")
        assert rc == 3 and "connect one new servo at a time" in out, out + err
        assert ("no servo alone at ID 0 within 1 s (two or more answer there at once, and their "
                "answers collide: connect one new servo at a time); 0 numbered") in err, err
        for n, serial in enumerate(serials, 1):
            rc, out, err = run(sim, capsys, "id", "assign", f"0x{serial:08x}", str(n))
            assert rc == 0, out + err
        rc, out, _ = run(sim, capsys, "scan", "--last", "5", "--json")
        found = json.loads(out)
        assert rc == 0 and [f["id"] for f in found] == [1, 2, 3, 4]
        assert sorted(s for f in found for s in f["serials"]) == serials
        for f in found:  # the control port by bus ID and by serial: the same servo
            assert sim.state(f["id"])["serial"] == f["serials"][0]
            assert sim.state(f"0x{f['serials'][0]:08x}")["id"] == f["id"]
        sim.control("powercycle 2")  # the servo that holds 2 now restarts, the others do not
        sim.sleep(0.6)
        with sim.bus() as bus:
            assert all(Servo(bus, i).ping() for i in (1, 2, 3, 4))
        assert [sim.state(i)["resets_power"] for i in (1, 2, 3, 4)] == [1, 2, 1, 1]
        assert sim.state(2)["mode"] == "app"
        with pytest.raises(p.ServoError, match="no servo holds that ID"):
            sim.control("state 0")
        lines = sim.control("state").splitlines()
        assert len(lines) == 4 and all(line.startswith("id=") for line in lines)


def test_state_of_a_full_bus_is_every_line(tmp_path):
    """state with 254 servos stopped at 4095 bytes, mid-line."""
    with Simulator(fast=True, ids=list(range(254)), state_dir=str(tmp_path / "state")) as sim:
        lines = sim.control("state").splitlines()
        assert [int(line.split()[0].split("=")[1]) for line in lines] == list(range(254))
        assert all(line.split()[-1].startswith("serial=") for line in lines)


def test_a_closed_pipe_does_not_cut_bringup_short(tmp_path, monkeypatch):
    """`servoctl id bringup --count 2 | head -1`: the reader goes after the
    first line; bringup still waits for the second servo and its exit code
    (3: none came) is its own, not the closed pipe's 0."""
    read_end, write_end = os.pipe()
    os.close(read_end)

    class ClosedPipe:
        def write(self, text):
            raise BrokenPipeError("the reader closed the pipe")

        def flush(self):
            pass

        def fileno(self):
            return write_end

    with Simulator(ids=[0], state_dir=str(tmp_path / "state")) as sim:
        monkeypatch.setattr(sys, "stdout", ClosedPipe())
        rc = main(["--port", sim.url, "id", "bringup", "--count", "2", "--wait-s", "1"], clock=sim.clock_s)
        monkeypatch.undo()
        os.close(write_end)
        assert rc == 3
        with sim.bus() as bus:
            assert Servo(bus, 1).read("serial") == 0x51A00000


def test_an_absent_servo_is_not_taken_for_the_one_at_its_new_id(tmp_path):
    """Servo 7 is absent and servo 2 answers: writing 7's ID (alone or in
    the user area's block) is unanswered, not read back as taken at 2."""
    with Simulator(ids=[1, 2], state_dir=str(tmp_path / "state")) as sim, sim.bus() as bus:
        block = Servo(bus, 1).read_all()
        for write in (lambda: Servo(bus, 7).write("servo_id", 2),
                      lambda: Servo(bus, 7).write_all(dict(block, servo_id=2))):
            with pytest.raises(p.NoReply):
                write()
        assert Servo(bus, 1).read("servo_id") == 1 and Servo(bus, 2).read("serial") == 0x51A00002
