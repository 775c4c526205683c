"""Every board folder is built by a preset and runs on its virtual board,
and a new board of a supported family is its data alone.

Each folder of firmware/boards whose part a virtual board emulates runs
its images (the checkout's build, as CI makes it) through ping, info and a
save then a power cycle, and the application must be what answers: the
UpdateStatus answer's mode is the application's and a saved item
survives the cycle (a bootloader alone answers a ping, and saves
nothing). The folders without one are named here: host_sim is the
simulator itself, qemu_stm32vl runs under QEMU (tests/qemu).

A variant of the reference board, in a copy of the tree, is its board.h
and board.cmake alone, no code: an STM32F103CB with its bus on USART2
(TX PA2), its bridge on TIM4 (PB6, PB7) and its NTC and encoder on ADC
inputs 4 and 5. It is built and run the same way, and its motor moves
(the bridge's timer and pins are the ones it declared) and its supply and
temperature read true (its ADC channels are). Time is the boards'
simulated time."""
import json
import shutil
import subprocess
import tarfile
from pathlib import Path

import pytest

from servoctl import ntc
from servoctl import update as upd
from servoctl.servo import Servo
from servoctl.sim import Simulator
from servo_image import board_facts
from vboard.board import REPO, images
from vboard.parts import EMULATED

from .test_virtual_boards import finish

NOT_VIRTUAL = {"host_sim": "the simulator (servo_sim) itself", "qemu_stm32vl": "QEMU's board (tests/qemu)"}
VARIANT = "f103cb_usart2"
VARIANT_EDITS = [  # (the reference board's line, the variant's)
    ("#define BOARD_ID 0x0103", "#define BOARD_ID 0x0779"),
    ("#define BOARD_BUS_USART 1", "#define BOARD_BUS_USART 2"),
    ("#define BOARD_BUS_DMA_TX 4", "#define BOARD_BUS_DMA_TX 7"),
    ("#define BOARD_BUS_DMA_RX 5", "#define BOARD_BUS_DMA_RX 6"),
    ("#define BOARD_BUS_TX_PIN 0x09", "#define BOARD_BUS_TX_PIN 0x02"),
    ("#define BOARD_BRIDGE_TIMER 3", "#define BOARD_BRIDGE_TIMER 4"),
    ("#define BOARD_BRIDGE_IN1_PIN 0x06", "#define BOARD_BRIDGE_IN1_PIN 0x16"),
    ("#define BOARD_BRIDGE_IN2_PIN 0x07", "#define BOARD_BRIDGE_IN2_PIN 0x17"),
    ("#define BOARD_ADC_NTC 2", "#define BOARD_ADC_NTC 4"),
    ("#define BOARD_ADC_POSITION 3", "#define BOARD_ADC_POSITION 5"),
]


def board_folders() -> list:
    return sorted(f.name for f in (REPO / "firmware/boards").iterdir() if (f / "board.h").is_file())


def built_boards() -> set:
    """The boards the presets build: each arm preset's SERVO_BOARDS, or the
    firmware's default list, and host_sim in the host builds."""
    presets = json.loads((REPO / "CMakePresets.json").read_text())["configurePresets"]
    text = (REPO / "firmware/CMakeLists.txt").read_text()
    default = text.split('set(SERVO_BOARDS "', 1)[1].split('"', 1)[0]
    found = {"host_sim"}
    for preset in presets:
        if preset["name"].startswith("arm"):
            found |= set(preset.get("cacheVariables", {}).get("SERVO_BOARDS", default).split(";"))
    return found


def run_ping_info_save(sim) -> dict:
    """Ping, info and a save then a power cycle, answered by the
    application; what info read."""
    with sim.bus(timeout=0.3) as bus:
        servo = Servo(bus, 1)
        assert servo.ping()
        assert upd.status(bus, 1).mode == upd.MODE_APP  # the application's answer, not the bootloader's
        m = servo.monitor()  # servoctl info's reading
        info = {"voltage_mv": m.voltage_mv, "temperature_c": ntc.celsius_or_none(m.temperature_adc, 2),
                "serial": servo.read("serial"), "firmware": servo.read("firmware")}
        saved = 900 if servo.read("angle_max") != 900 else 800
        servo.write("angle_max", saved)
        sim.sleep(0.1)
        sim.control("powercycle 1")
        sim.sleep(0.6)  # the bootloader's window, then the application
        assert upd.status(bus, 1).mode == upd.MODE_APP
        assert servo.read("angle_max") == saved
        state = sim.state(1)
        assert state["mode"] == "app" and state["resets_power"] == 2
    return info


def test_every_board_folder_is_built_and_has_a_virtual_board_or_is_named():
    folders = board_folders()
    assert not set(folders) - built_boards(), "a board folder no preset builds"
    virtual = [f for f in folders if board_facts.part_name(f) in EMULATED]
    assert sorted(set(folders) - set(virtual)) == sorted(NOT_VIRTUAL)


@pytest.mark.parametrize("board", [f for f in board_folders() if f not in NOT_VIRTUAL])
def test_each_board_folder_answers_from_its_application_and_keeps_a_save(tmp_path, board):
    sim = Simulator(ids=(1,), state_dir=str(tmp_path / "state"), board=board, fast=True).start()
    try:
        info = run_ping_info_save(sim)
    finally:
        finish(sim, [1])
    assert info["serial"] != 0 and info["voltage_mv"] == pytest.approx(7400, abs=150)


def _variant_tree(tmp_path) -> Path:
    """The checkout's tree (no builds) with the variant's folder beside the
    reference board's: its data files, edited, and no code."""
    tree = tmp_path / "tree"
    with tarfile.open(tmp_path / "tree.tar", "w") as tar:
        for top in REPO.iterdir():
            if top.name not in ("build", ".git", ".venv", "demo-output") and not top.name.startswith(".venv"):
                tar.add(top, top.name, filter=lambda t: None if "__pycache__" in t.name else t)
    with tarfile.open(tmp_path / "tree.tar") as tar:
        tar.extractall(tree, filter="tar")
    reference, folder = tree / "firmware/boards/stm32f103", tree / "firmware/boards" / VARIANT
    folder.mkdir()
    header = (reference / "board.h").read_text()
    for old, new in VARIANT_EDITS:
        assert old in header, old
        header = header.replace(old, new)
    (folder / "board.h").write_text(header)
    cmake = (reference / "board.cmake").read_text()
    (folder / "board.cmake").write_text(cmake.replace("set(SERVO_BOARD_PART stm32f103c8)",
                                                      "set(SERVO_BOARD_PART stm32f103cb)"))
    shutil.copy(reference / "CMakeLists.txt", folder)
    assert not [f for f in folder.iterdir() if f.suffix in (".c", ".h") and f.name != "board.h"]
    return tree


def test_a_variant_board_from_data_alone_builds_and_runs_on_its_virtual_board(tmp_path):
    tree = _variant_tree(tmp_path)
    build = tree / "build/arm"
    configure = subprocess.run(["cmake", "--preset", "arm", f"-DSERVO_BOARDS={VARIANT}"], cwd=tree,
                               capture_output=True, text=True)
    assert configure.returncode == 0, configure.stderr[-2000:]
    made = subprocess.run(["cmake", "--build", build, "-j", "2", "--target", f"servo_{VARIANT}.elf",
                           f"servo_{VARIANT}_boot.elf"], cwd=tree, capture_output=True, text=True)
    assert made.returncode == 0, made.stdout[-3000:]
    folder = tree / "firmware/boards" / VARIANT
    assert all(path.is_file() for path in images(folder, build))
    sim = Simulator(ids=(1,), state_dir=str(tmp_path / "state"), board=str(folder), build=build, fast=True).start()
    try:
        info = run_ping_info_save(sim)
        with sim.bus(timeout=0.3) as bus:
            servo = Servo(bus, 1)
            servo.write("soft_start_on", 0)
            servo.move(450, interval_ms=300)  # the bridge: TIM4's CH1/CH2 on PB6/PB7
            sim.sleep(0.6)
            assert servo.angle() == pytest.approx(450, abs=2)
            assert sim.state(1)["angle"] == pytest.approx(45, abs=0.5)
    finally:
        finish(sim, [1])
    # The supply on IN0, the NTC on IN4: the channels the variant declared.
    assert info["voltage_mv"] == pytest.approx(7400, abs=150)
    assert info["temperature_c"] == pytest.approx(25, abs=3)
