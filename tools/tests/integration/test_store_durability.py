"""The config store against the bus: every acknowledged change survives a
power cut (kill -9) whatever the traffic, and flash work loses no frame
silently and sends no answer late (docs/decisions.md, "The config store").

The simulator stalls a servo's CPU for each flash operation at DS5319's
longest times (40 ms a page erase, 70 us a half-word)."""

import pytest

from servoctl import protocol as p
from servoctl.servo import Refused, Servo
from servoctl.sim import Simulator

from tests.store_pages import bus_to_baud, sync_move_frame, without_soft_start


SLOTS = 21  # records in a 1 KB page (48 bytes each)


def clean_stop(sim):
    err = sim.stop()
    assert "runtime error" not in err and "AddressSanitizer" not in err, err


def power_cut(sim, ids, state_dir):
    """kill -9 and start again on the same flash files."""
    sim.process.kill()
    sim.process.wait()
    return Simulator(fast=True, ids=ids, state_dir=state_dir).start()


def test_changes_survive_a_cut_while_another_servos_monitor_traffic_never_pauses(tmp_path):
    """Servo 2 is read back to back, so the line is never quiet for 2 ms:
    servo 1 never erases. Each of its changes is in flash before its
    answer; once its free slots are spent it refuses further ones (and
    says why) rather than acknowledge what it cannot keep."""
    state_dir = str(tmp_path / "state")
    sim = Simulator(fast=True, ids=[1, 2], state_dir=state_dir).start()
    try:
        with sim.bus(timeout=0.2) as bus:
            one, two = Servo(bus, 1), Servo(bus, 2)
            accepted, refused = None, 0
            for n in range(2 * SLOTS + 10):
                try:
                    one.write("stall_power", 5000 + n)  # a new value each time
                    accepted = 5000 + n
                except Refused as e:
                    assert "release it" in str(e), e
                    refused += 1
                for _ in range(3):
                    two.monitor()
        assert accepted is not None and refused > 0, (accepted, refused)
        sim = power_cut(sim, [1, 2], state_dir)
        with sim.bus(timeout=0.2) as bus:
            assert Servo(bus, 1).read("stall_power") == accepted
        assert sim.state(1)["collisions"] == 0
    finally:
        clean_stop(sim)


def test_a_new_id_survives_a_cut(tmp_path):
    state_dir = str(tmp_path / "state")
    sim = Simulator(fast=True, ids=[1], state_dir=state_dir).start()
    try:
        with sim.bus(timeout=0.2) as bus:
            Servo(bus, 1).write("servo_id", 9)  # answered by ID 1, then 9
            assert Servo(bus, 9).ping()
        sim = power_cut(sim, [1], state_dir)
        with sim.bus(timeout=0.2) as bus:
            assert Servo(bus, 9).ping()
            assert not Servo(bus, 1).ping()
    finally:
        clean_stop(sim)


def fill_until_the_spare_page_is_dirty(servo, sim):
    """Changes until one starts the other page: the old page is then
    erased once the servo is released and the line quiet for 100 ms.
    Returns the simulated time of the last answer."""
    n = 0
    while True:
        n += 1
        servo.write("current_limit", 3000 + n % 2)  # servoctl reads back one unanswered
        saves = sim.state(servo.id)["saves"]
        if saves % SLOTS == 1 and saves > 1:
            return max(sim.state(i)["last_sent_ms"] for i in (1, 2)) / 1000.0


def send_at(sim, at_s, frame):
    """The host's frame on the wire from simulated time at_s (the
    simulator's hostsend, 100 bytes a line, each queued behind the last)."""
    for k in range(0, len(frame), 100):
        assert sim.control(f"hostsend {at_s * 1000.0:.3f} {frame[k:k + 100].hex()}").startswith("ok")


@pytest.mark.parametrize("baud", [115200, 1000000])
def test_sync_commands_sent_into_an_erase_are_carried_out(tmp_path, baud):
    """Both servos have a dirty spare page. Servo 2 holds its position, so
    it never erases, and takes the SyncCommands. Servo 1 is released: 100
    ms after the line fell quiet it erases (at the next 1 ms control tick),
    and the SyncCommands go on the wire 103 ms after the quiet began, 2 to
    3 ms into that erase: one (707 bytes, 61 ms) at 115200; at 1
    Mbaud five back to back (3535 bytes in 35 ms, nearly an erase's worth),
    the last to 30 degrees. The reference board's 4 KB ring holds every
    byte the 40 ms erase brings in at either rate (its board.h): servo 1
    carries them out, and loses nothing."""
    sim = Simulator(fast=True, ids=[1, 2], state_dir=str(tmp_path / "state")).start()
    try:
        bus_to_baud(sim, (1, 2), baud, timeout=0.2)
        with sim.bus(baud=baud, timeout=0.2) as bus:
            one, two = without_soft_start(bus, (1, 2))
            fill_until_the_spare_page_is_dirty(two, sim)
            two.move(0, interval_ms=100)
            two.hold()
            fill_until_the_spare_page_is_dirty(one, sim)
            one.release()
            assert one.ping()
            quiet_from = sim.state(1)["last_sent_ms"] / 1000.0
            stalled = sim.state(1)["flash_stall_ms"]
            angles = [300] if baud == 115200 else [-300, 200, -100, 100, 300]
            send_at(sim, quiet_from + 0.103, b"".join(sync_move_frame(a) for a in angles))
            sim.sleep(quiet_from + 1.3 - sim.clock_s())
            assert sim.state(1)["flash_stall_ms"] - stalled >= 40.0, "no erase: the test proves nothing"
            assert abs(sim.state(2)["angle"] - 30.0) < 1.0, "the holding servo missed it"
            assert two.read_store().bytes_lost == 0
            assert one.read_store().bytes_lost == 0
            assert abs(sim.state(1)["angle"] - 30.0) < 1.0, "the erasing servo lost the SyncCommand"
        assert sim.state(1)["collisions"] == 0
    finally:
        clean_stop(sim)


def test_sixty_four_servos_save_and_sync_monitor_without_a_collision(tmp_path):
    """64 servos on a bus; every eighth fills its store's page, then all
    eight take the change that starts the other page, so each must erase
    the old one at the next quiet. The host leaves 100 ms of quiet and
    sends a Sync Monitor of all 64 into those erases, then a round with
    nothing to erase. An erasing servo carries the round out but does not
    answer late, or, its ring overflowing with the others' answers during
    the erase, loses the request; the others pass its turn after 3 ms of
    silence. No collision, the answers in list order, every missing one
    counted in its servo's ReadStore (an answer dropped, or bytes lost), no
    tick dropped, and every change kept."""
    ids = list(range(1, 65))
    savers = ids[::8]
    sim = Simulator(fast=True, ids=ids, state_dir=str(tmp_path / "state")).start()
    try:
        with sim.bus(timeout=0.3) as bus:
            servos = {i: Servo(bus, i) for i in ids}
            for i in savers:  # the page full: the next change starts the other
                n = 0
                while sim.state(i)["saves"] % SLOTS != 0:
                    n += 1
                    servos[i].write("current_limit", 2000 + n % 2)
            missing = {i: 0 for i in ids}
            for group in (savers, []):
                for i in group:
                    servos[i].write("current_limit", 3000 + i)
                assert servos[64].ping()
                quiet_from = sim.state(64)["last_sent_ms"] / 1000.0
                # Into the erases: 100 ms of quiet, then 2.5 ms into 40.
                send_at(sim, quiet_from + 0.1025,
                        p.request_frame(p.SYNC, bytes([p.MONITOR, 1, len(ids)] + ids)))
                end = quiet_from + 0.1025 + 0.08 + 0.003 * len(ids)
                data = b""

                def round_over():
                    nonlocal data
                    data += bus.serial.read(4096)
                    return sim.clock_s() >= end

                sim.wait_until(round_over, 60.0)
                assert len(data) % 21 == 0, data.hex()
                answered = [data[k + 4] for k in range(0, len(data), 21)]
                assert answered == sorted(answered), answered  # list order
                for i in ids:
                    missing[i] += i not in answered
            health = {i: servos[i].read_store() for i in ids}
            held = {i: servos[i].read("current_limit") for i in savers}
        assert sum(missing.values()) > 0, "no Sync Monitor landed in an erase: the test proves nothing"
        for i in ids:
            # An erasing servo hears the round's answers too: its ring may
            # overflow and lose the request itself, which it counts.
            h = health[i]
            assert h.answers_dropped == missing[i] or (missing[i] and h.bytes_lost > 0), (i, missing[i], h)
        assert held == {i: 3000 + i for i in savers}
        assert sim.state(1)["collisions"] == 0
        assert all(sim.state(i)["dropped_ticks"] == 0 for i in ids)
    finally:
        clean_stop(sim)
