"""How the storm (tests/storm/storm.py) counts an answer that did not come:
a finished move's answer, or one the host asked for, that a request of the
host's own garbled (it started less than a byte time before the answer,
docs/decisions.md, "The host") is the host's, not a servo's loss. Only the
counting: no simulator runs."""
import importlib.util
from pathlib import Path

import pytest

STORM = Path(__file__).resolve().parents[2] / "tests/storm/storm.py"


@pytest.fixture(scope="module")
def storm():
    spec = importlib.util.spec_from_file_location("storm_under_test", STORM)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def counts():
    return {"finished_lost": 0, "finished_talked_over": 0, "frames_lost": 0,
            "answers_talked_over": 0, "answers_missed_reported": 0, "lost_examples": []}


def bus(garbled, collisions=0):
    """The part of servo_sim's `state` line the storm reads."""
    return {"garbled": str(garbled), "collisions": str(collisions)}


def test_a_finished_answer_missing_after_the_host_talked_over_one_is_the_hosts(storm):
    # Seed 4 after 13 s: servo 2's answer began 75 us into a 6-byte request
    # (6 bytes garbled, no collision), and servo 2 owed one answer more.
    stats, lines = counts(), []
    storm.count_finished(stats, {1: 9, 2: 15}, {1: 9, 2: 14}, bus(6), lines.append)
    assert (stats["finished_lost"], stats["finished_talked_over"]) == (0, 1)
    assert "talked over" in lines[0]


def test_a_finished_answer_missing_on_a_clean_wire_is_lost(storm):
    stats, lines = counts(), []
    storm.count_finished(stats, {1: 3, 2: 2}, {1: 3, 2: 1}, bus(0), lines.append)
    assert (stats["finished_lost"], stats["finished_talked_over"]) == (1, 0)
    assert "lost {2: 1}" in lines[0]


def test_a_collision_of_two_servos_excuses_nothing(storm):
    stats = counts()
    storm.count_finished(stats, {1: 3, 2: 2}, {1: 2, 2: 2}, bus(7, collisions=7), lambda _: None)
    assert (stats["finished_lost"], stats["finished_talked_over"]) == (1, 0)


def test_every_answer_heard_counts_nothing(storm):
    stats, lines = counts(), []
    storm.count_finished(stats, {1: 3, 2: 2}, {1: 3, 2: 2}, bus(14), lines.append)
    assert (stats["finished_lost"], stats["finished_talked_over"], lines) == (0, 0, [])


class QuietSim:
    """servo_sim as the host's missed() sees it: its `state` counts only."""

    def __init__(self, garbled):
        self.garbled = garbled

    def state_of(self, servo_id):
        return bus(self.garbled)


def test_an_asked_answer_missing_after_the_host_talked_over_one_is_the_hosts(storm):
    stats = counts()
    host = storm.Host(QuietSim(garbled=7), stats)
    host.store_counts = lambda servo_id: 0  # the servo's own counters did not rise
    assert host.missed(3, "packet 1 to 3")
    assert (stats["frames_lost"], stats["answers_talked_over"]) == (0, 1)
    # The same talk-over does not excuse a second answer.
    assert not host.missed(3, "packet 1 to 3")
    assert (stats["frames_lost"], stats["answers_talked_over"]) == (1, 1)


def test_a_garbled_frame_after_the_host_talked_over_an_answer_is_the_hosts(storm):
    # The answer's first three bytes came, the rest was lost under the
    # request: with the next answer's they make a frame that fails its check,
    # and the answer after that is whole.
    stats = counts()
    stats.update(garbled=0, garbled_talked_over=0, stray_bytes=0)
    host = storm.Host(QuietSim(garbled=5), stats)
    ping = bytes([0x05, 0x1C, 0x01, 0x01, 0x03])
    ping += bytes([storm.checksum(ping)])
    host.buffer = bytes([0x05, 0x1C, 0x08]) + ping * 3
    frames = list(host._frames())
    assert (stats["garbled"], stats["garbled_talked_over"]) == (0, 1)
    # The same talk-over does not excuse a second garbled frame.
    host.buffer = bytes([0x05, 0x1C, 0x08]) + ping * 3
    frames += list(host._frames())
    assert (stats["garbled"], stats["garbled_talked_over"]) == (1, 1)
    assert frames == [(0x01, bytes([0x03]))] * 2
