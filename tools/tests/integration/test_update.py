"""Firmware update over the bus, on a simulated three-servo bus.

The simulator runs the bootloader core on each servo (firmware/boards/
host_sim/sim_servo.c): its answers, its boot decision and the slot in a
flash file are the real ones; the image itself is not executed, its version
is what the application then reports (data item 7). A power cut inside a
flash step is the unit test's (test_bootloader.c, every erase and program
step); here the power goes between the update's packets, and the host
gives up with it."""
import random

import pytest

from servoctl import image as img
from servoctl import protocol as p
from servoctl import update as upd
from servoctl.cli import main
from servoctl.protocol import Bus, NoReply, Refused, UsageError
from servoctl.servo import Servo

OLD = 0x0010  # the simulator's factory image: this firmware's version
NEW = 0x0042


def make_image(version=NEW, size=3000, board=img.BOARDS["host_sim"], seed=1):
    code = bytes(random.Random(seed).randrange(256) for _ in range(size))
    return img.parse(img.build(code, version, board))


def firmware(bus, servo_id):
    return Servo(bus, servo_id).read("firmware")


def test_an_update_on_a_shared_bus(sim3):
    image = make_image()
    others_answered = []

    with sim3.bus(timeout=0.2) as bus:
        assert [firmware(bus, i) for i in (1, 2, 3)] == [OLD, OLD, OLD]

        calls = []

        def progress(done, total):
            # The other servos keep working while servo 2 is in its bootloader.
            calls.append(done)
            if len(calls) % 20 == 0:
                others_answered.append(Servo(bus, 1).ping() and Servo(bus, 3).ping())

        before, after = upd.update(bus, 2, image, progress)
        assert (before, after) == (OLD, NEW)
        assert [firmware(bus, i) for i in (1, 2, 3)] == [OLD, NEW, OLD]
        assert upd.status(bus, 2).mode == upd.MODE_APP
    assert len(others_answered) > 5 and all(others_answered)
    assert sim3.state(2)["mode"] == "app"


@pytest.mark.parametrize("cut_at", ["enter", "first erase", "last erase", "a quarter",
                                    "three quarters", "before the header", "before verify"])
def test_a_power_cut_during_an_update_is_recovered(sim3, cut_at):
    """The power goes at a point of the update and the host gives up; the
    servo then runs the old image whole or waits in its bootloader, and
    `servoctl update` again brings the new image."""
    image = make_image(size=2000)
    pages = (len(image.data) + 1023) // 1024
    total = pages + len(image.data)
    points = {"enter": 0, "first erase": 1, "last erase": pages, "a quarter": pages + total // 4,
              "three quarters": pages + 3 * total // 4, "before the header": total - 24,
              "before verify": total}

    class Cut(Exception):
        pass

    def progress(done, _total):
        if done >= points[cut_at]:
            sim3.control("powercycle 2")
            raise Cut()

    with sim3.bus(timeout=0.2) as bus:
        if cut_at == "enter":
            bus.request(upd.UPDATE_ENTER, bytes([2]))
            sim3.control("powercycle 2")
        else:
            with pytest.raises(Cut):
                upd.update(bus, 2, image, progress)
        st = upd._wait_for_mode(bus, 2, upd.MODE_BOOTLOADER) if cut_at != "enter" else None
        if st is not None:
            assert st.verdict != 0  # no half image is started
        before, after = upd.update(bus, 2, image)  # the recovery
        assert after == NEW
        assert before in (None, OLD)
        assert [firmware(bus, i) for i in (1, 2, 3)] == [OLD, NEW, OLD]


def test_a_power_cut_after_every_step_of_an_update_is_recovered(sim3):
    """The power goes after each step of an update in turn (UpdateEnter,
    every erase, every write, before verify); each time `servoctl update`
    again brings the image, and the other servos never stop answering."""
    image = make_image(size=400)  # 1 page, 28 writes: every step in seconds

    class Cut(Exception):
        pass

    with sim3.bus(timeout=0.2) as bus:
        steps = []
        upd.update(bus, 2, image, lambda done, total: steps.append(done))
        assert len(steps) > 20
        for k in range(len(steps) + 1):  # k = 0: just after UpdateEnter
            calls = []

            def progress(done, total):
                calls.append(done)
                if len(calls) >= k:
                    sim3.control("powercycle 2")
                    raise Cut()

            if k == 0:
                bus.request(upd.UPDATE_ENTER, bytes([2]))
                sim3.control("powercycle 2")
            else:
                with pytest.raises(Cut):
                    upd.update(bus, 2, make_image(version=NEW + k, size=400, seed=k), progress)
            before, after = upd.update(bus, 2, image)
            assert after == NEW
            assert Servo(bus, 1).ping() and Servo(bus, 3).ping()
        assert [firmware(bus, i) for i in (1, 2, 3)] == [OLD, NEW, OLD]


def test_a_servo_is_caught_in_its_bootloader_at_power_up(sim):
    """An application that does not answer can still be updated: the tool
    asks for UpdateStatus while the servo powers up, and the bootloader
    stays instead of starting it."""
    with sim.bus(timeout=0.2) as bus:
        sim.control("powercycle 1")
        st = upd.catch(bus, 1, 2.0)
        assert (st.mode, st.verdict) == (upd.MODE_BOOTLOADER, 0)  # a valid image, kept waiting
        assert sim.state(1)["mode"] == "bootloader"
        before, after = upd.update(bus, 1, make_image())
        assert (before, after) == (OLD, NEW)
    with sim.bus(timeout=0.2) as bus:
        with pytest.raises(NoReply, match="no bootloader answered"):
            upd.catch(bus, 1, 0.3)  # the application answers, not a bootloader


def test_the_bootloader_answers_ping_and_stays_without_an_image(sim):
    with sim.bus(timeout=0.2) as bus:
        image = make_image(size=2000)

        class HostGone(Exception):
            pass

        def erase_then_cut(done, total):
            if done == 1:  # page 0, the header's, is gone
                sim.control("powercycle 1")
                raise HostGone()

        with pytest.raises(HostGone):
            upd.update(bus, 1, image, erase_then_cut)
        st = upd._wait_for_mode(bus, 1, upd.MODE_BOOTLOADER)
        assert st.verdict == 1  # no image
        assert Servo(bus, 1).ping()  # tools find it
        with pytest.raises(NoReply):
            Servo(bus, 1).read("firmware")  # nothing else answers
        assert (st.page_size, st.write_block, st.largest_write) == (1024, 2, 24)


def run(sim, capsys, *args):
    rc = main(["--port", sim.url, *args], clock=sim.clock_s)
    out = capsys.readouterr()
    return rc, out.out, out.err


def test_servoctl_image_and_update_several_servos(sim3, capsys, tmp_path):
    binary = tmp_path / "app.bin"
    binary.write_bytes(bytes(random.Random(2).randrange(256) for _ in range(1501)))
    out = tmp_path / "app.img"
    rc, text, _ = run(sim3, capsys, "image", str(binary), "--version", "0x0042", "--board", "host_sim",
                      "-o", str(out))
    assert rc == 0 and "version 0x0042" in text
    rc, text, err = run(sim3, capsys, "update", "1", "3", str(out))  # IDs first, as a user types them
    assert rc == 0, err
    assert "servo 1: version 0x0010 -> 0x0042" in text
    assert "servo 3: version 0x0010 -> 0x0042" in text
    with sim3.bus(timeout=0.2) as bus:
        assert [firmware(bus, i) for i in (1, 2, 3)] == [NEW, OLD, NEW]


def test_an_image_larger_than_the_slot_is_refused_before_writing(sim, capsys, tmp_path):
    """Refused before a byte of it is written: exit 2, as every value
    servoctl refuses before sending; the old application runs on."""
    big = tmp_path / "big.img"  # 256 KB: more than any slot
    big.write_bytes(img.build(b"\x01" * 256 * 1024, NEW, img.BOARDS["host_sim"]))
    rc, text, _ = run(sim, capsys, "update", str(big), "1")
    assert rc == UsageError.exit_code and "larger than the slot" in text, text
    with sim.bus(timeout=0.2) as bus:
        assert firmware(bus, 1) == OLD


def test_servoctl_update_refuses_what_cannot_be_right(sim, capsys, tmp_path):
    foreign = tmp_path / "f103.img"
    foreign.write_bytes(img.build(b"\x00" * 64, 0x0042, img.BOARDS["stm32f103"]))
    rc, text, _ = run(sim, capsys, "update", str(foreign), "1")
    assert rc == UsageError.exit_code  # refused before sending, as every value is
    assert "servo 1 is host_sim (0x5100); the image is for stm32f103 (0x0103)" in text, text
    not_an_image = tmp_path / "app.bin"
    not_an_image.write_bytes(b"\x00" * 600)
    rc, _, err = run(sim, capsys, "update", str(not_an_image), "1")
    assert rc == UsageError.exit_code and "not an update image" in err
    rc, _, err = run(sim, capsys, "update", "1", "2")
    assert rc == UsageError.exit_code and "one image" in err
    damaged = tmp_path / "damaged.img"
    data = bytearray(img.build(b"\x01" * 600, 0x0042, img.BOARDS["host_sim"]))
    data[400] ^= 1
    damaged.write_bytes(bytes(data))
    rc, _, err = run(sim, capsys, "update", str(damaged), "1")
    assert rc == UsageError.exit_code and "does not match its CRC" in err
    with sim.bus(timeout=0.2) as bus:
        assert firmware(bus, 1) == OLD  # nothing was written


def test_update_enter_is_refused_while_a_load_is_held(sim, capsys, tmp_path):
    """A servo holding 44 deg under 1.2 N m refuses UpdateEnter, with its
    reason: a restart would let go of the output and drop the load.
    servoctl says why and how to release it; once released, it updates."""
    with sim.bus(timeout=0.2) as bus:
        s = Servo(bus, 1)
        s.write("soft_start_on", 0)
        s.move(angle_decideg=440, interval_ms=300)
        sim.wait_until(lambda: not s.status() & 1, 3)
        sim.control("load 1.2")
        sim.sleep(0.5)
        held = sim.state(1)["angle"]  # within a degree of 44 (the hold sags)
        assert abs(held - 44.0) < 1.5
        assert bus.request(upd.UPDATE_ENTER, bytes([1]))[1:] == bytes([0, upd.ENTER_OUTPUT_DRIVEN])
    path = tmp_path / "app.img"
    path.write_bytes(img.build(b"\x02" * 600, NEW, img.BOARDS["host_sim"]))
    rc, out, err = run(sim, capsys, "update", "1", str(path))
    said = out + err
    assert rc == Refused.exit_code and "output is driven" in said and "servoctl stop 1" in said, said
    sim.sleep(0.5)
    state = sim.state(1)
    assert state["mode"] == "app" and abs(state["angle"] - held) <= 0.2  # still held
    sim.control("load 0")
    with sim.bus(timeout=0.2) as bus:
        Servo(bus, 1).release()
        assert upd.update(bus, 1, make_image()) == (OLD, NEW)


def test_the_bootloader_drops_a_partial_frame_after_an_idle_gap(sim):
    """After UpdateEnter, the start of a frame whose length says 65535 and
    a frame cut short each cost nothing once the line has been quiet for
    the idle timeout (1 ms at 115200), as in the application."""
    with sim.bus(timeout=0.2) as bus:
        assert bus.request(upd.UPDATE_ENTER, bytes([1]))[1] == 1
        upd._wait_for_mode(bus, 1, upd.MODE_BOOTLOADER)
        bus.serial.write(bytes([0x12, 0x4C, 0x55, 0xFF, 0xFF, 0xFF]))
        sim.sleep(0.01)
        assert Servo(bus, 1).ping()
        whole = p.request_frame(upd.UPDATE_WRITE, bytes([1]) + bytes(4) + b"\xff" * 8 + bytes(4))
        bus.serial.write(whole[:10])
        sim.sleep(0.01)
        assert upd.status(bus, 1).mode == upd.MODE_BOOTLOADER
        assert Servo(bus, 1).ping()


def test_a_slot_left_invalid_stays_invalid_across_a_kill(tmp_path):
    """Killed during an update (the old image erased, the new one not yet
    written), a servo comes back waiting in its bootloader, not as the
    factory application: only a blank state folder gets that."""
    from servoctl.sim import Simulator

    state = str(tmp_path / "state")
    with Simulator(fast=True, ids=[1], state_dir=state) as sim, sim.bus(timeout=0.2) as bus:
        assert bus.request(upd.UPDATE_ENTER, bytes([1]))[1] == 1
        upd._wait_for_mode(bus, 1, upd.MODE_BOOTLOADER)
        assert bus.request(upd.UPDATE_ERASE, bytes([1, 0, 0]))[1] == 1
        sim.process.kill()  # kill -9: no clean stop
        sim.process.wait()
    with Simulator(fast=True, ids=[1], state_dir=state) as sim, sim.bus(timeout=0.2) as bus:
        st = upd.status(bus, 1)
        assert (st.mode, st.verdict) == (upd.MODE_BOOTLOADER, 1)  # no image
        assert sim.state(1)["mode"] == "bootloader"
        with pytest.raises(NoReply):
            Servo(bus, 1).read("firmware")
        assert upd.update(bus, 1, make_image()) == (None, NEW)


def test_flash_faults_are_reported_not_hidden(sim):
    """The control port's failerase and failprogram make the next erases or
    programs fail as a worn page's do: the update says which step the
    flash refused, and a retry once the fault is gone succeeds."""
    with sim.bus(timeout=0.2) as bus:
        sim.control("failerase 1 1")
        with pytest.raises(Refused, match="erasing page 0 refused: the flash refused"):
            upd.update(bus, 1, make_image())
        sim.control("failprogram 1 1")
        with pytest.raises(Refused, match="the flash refused"):
            upd.update(bus, 1, make_image())
        assert upd.update(bus, 1, make_image()) == (None, NEW)


@pytest.mark.parametrize("lost", [upd.UPDATE_ENTER, upd.UPDATE_ERASE, upd.UPDATE_WRITE,
                                  upd.UPDATE_VERIFY, upd.UPDATE_BOOT])
def test_every_step_survives_a_lost_answer(sim, lost):
    """The servo carries out a request whose answer the host
    never sees (the answer is read off the wire and thrown away). The update
    still ends with the new version running and exit 0: a repeated write
    finds its bytes in place, and after UpdateEnter or UpdateBoot the mode
    the servo answers in shows the request was done."""
    image = make_image(seed=7)
    with sim.bus(timeout=0.2) as bus:
        read_response = bus.read_response
        dropped = []

        def lossy(code, servo_id, timeout=None):
            content = read_response(code, servo_id, timeout)
            if code == lost and len(dropped) < 2:  # the first two of that packet
                dropped.append(code)
                raise NoReply(f"servo {servo_id}: answer to packet {code} lost (test)")
            return content

        bus.read_response = lossy
        before, after = upd.update(bus, 1, image)
        bus.read_response = read_response
        # Enter and Boot are not sent again: the servo answers in its new mode.
        assert dropped == [lost] * (1 if lost in (upd.UPDATE_ENTER, upd.UPDATE_BOOT) else 2)
        assert (before, after) == (OLD, NEW)
        assert firmware(bus, 1) == NEW
