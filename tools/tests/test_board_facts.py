"""A board's facts have one reader (servo_image.board_facts) that every tool
uses, and a board's CPU comes from the chip family its board.cmake names."""
from servo_image import board_facts
from servoctl import image as img
from vboard import board as vb


def test_every_tool_reads_the_same_board_facts():
    for name in ("stm32f103", "stm32f030k6", "qemu_stm32vl", "host_sim"):
        facts = board_facts.defines(name)
        assert facts["BOARD_ID"] == img.boards()[name].id
        assert vb.board_h(name) == facts


def test_the_cpu_is_the_family_s():
    assert {n: b.cpu for n, b in img.boards().items()} == {
        "host_sim": "", "qemu_stm32vl": "cortex-m3", "stm32f030k6": "cortex-m0",
        "stm32f103": "cortex-m3"}


def test_a_family_is_declared_once(tmp_path):
    """A board.cmake names its family; one that sets its CPU itself wins."""
    (tmp_path / "board.cmake").write_text(
        "include(${PROJECT_SOURCE_DIR}/cmake/family-stm32f0.cmake)\n")
    assert board_facts.cpu(tmp_path) == "cortex-m0"
    (tmp_path / "board.cmake").write_text(
        "include(${PROJECT_SOURCE_DIR}/cmake/family-stm32f0.cmake)\nset(SERVO_BOARD_CPU cortex-m4)\n")
    assert board_facts.cpu(tmp_path) == "cortex-m4"


def test_a_board_h_s_includes_are_followed():
    """The reference servo's front end is declared once
    (boards/common/reference_servo.h) and read for every board that includes
    it; host_sim's own ID overrides the reference board's it includes."""
    for name in ("stm32f103", "stm32f030k6", "qemu_stm32vl", "host_sim"):
        facts = board_facts.defines(name)
        assert facts["BOARD_SUPPLY_UV_PER_COUNT"] == 8862, name
        assert facts["BOARD_MOTOR_MOHM"] == 2741, name
    assert board_facts.defines("host_sim")["BOARD_ID"] == 0x5100
