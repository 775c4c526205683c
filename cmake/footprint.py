#!/usr/bin/env python3
"""Per-module flash and RAM of an image, from the linker map: only what was
linked (after --gc-sections), grouped by the project folder each object
comes from; libc and libgcc as one row."""
import re
import sys
from collections import defaultdict

MODULES = [  # (part of the object's path in the map, name)
    ("libservo_protocol.a", "protocol: dispatcher, handlers"),
    ("libservo_wire.a", "wire layer: framer, encoder"),
    ("libservo_registers.a", "registers: data table"),
    ("libservo_motion.a", "motion: profile, controller, commands"),
    ("libservo_storage.a", "config store, fault history and CRC"),
    ("libservo_sensors.a", "sensors: scaling, NTC table"),
    ("libservo_protection.a", "protection monitors, bus watchdog, winding model"),
    ("libservo_app.a", "servo core (servo.c, servo_turns.c, servo_store.c, servo_safety.c)"),
    # The application's images optimise servo_app alone at link time
    # (firmware/CMakeLists.txt): what the link-time partitions hold is its.
    (".ltrans", "servo core (servo.c, servo_turns.c, servo_store.c, servo_safety.c)"),
    ("libservo_stm32f1.a", "STM32F1 port (USART)"),
    ("libservo_stm32f0.a", "STM32F0 port (USART)"),
    # The G0's port library compiles the drivers it shares with the F parts
    # itself (hal/ports/stm32g0/CMakeLists.txt): its own are these three.
    ("libservo_stm32g0.a(flash_g0.c", "STM32G0 port (USART, DMAMUX, flash)"),
    ("libservo_stm32g0.a(stm32g0_uart.c", "STM32G0 port (USART, DMAMUX, flash)"),
    ("libservo_stm32g0.a(usart_v2_hd.c", "STM32G0 port (USART, DMAMUX, flash)"),
    ("libservo_stm32g0.a", "STM32 common (DMA receive, SysTick, flash, PWM, IWDG, boot jump)"),
    ("libservo_stm32_common.a", "STM32 common (DMA receive, SysTick, flash, PWM, IWDG, boot jump)"),
    ("startup_stm32", "startup, vector table"),
    ("small_div.c", "the small run-time: mem*, 32-bit division (size first)"),
    ("small_mem.c", "the small run-time: mem*, 32-bit division (size first)"),
    ("boards/", "board (main, wiring, board_io: clocks, pins, ADC; the static servo state)"),
]


def module_of(obj):
    for prefix, name in MODULES:
        if prefix in obj:
            return name
    if re.search(r"lib(c|c_nano|gcc|m|nosys)\.a|/newlib/|/arm-none-eabi/", obj):
        return "libc, libgcc"
    return "other: " + obj.rsplit("/", 1)[-1]  # a project object no row names: add one


def main() -> int:
    text = open(sys.argv[1]).read()
    body = text[text.index("Linker script and memory map"):]
    flash, ram = defaultdict(int), defaultdict(int)
    section = None
    # Input sections: " .text.name  0xADDR  0xSIZE object" (one or two lines)
    for m in re.finditer(r"^ (\.[\w.]+)(?:\s*\n)?\s+0x([0-9a-f]+)\s+0x([0-9a-f]+)\s+(\S+)$",
                         body, re.M):
        section, addr, size, obj = m.group(1), int(m.group(2), 16), int(m.group(3), 16), m.group(4)
        if size == 0 or addr == 0:
            continue
        mod = module_of(obj)
        if section.startswith((".text", ".rodata", ".isr_vector", ".ARM.exidx")):
            flash[mod] += size
        elif section.startswith(".data"):
            flash[mod] += size
            ram[mod] += size
        elif section.startswith((".bss", "COMMON")):
            ram[mod] += size
    rows = sorted(set(flash) | set(ram), key=lambda k: -flash[k])
    print(f"| module | flash (B) | RAM (B) |\n|---|---:|---:|")
    for r in rows:
        print(f"| {r} | {flash[r]} | {ram[r]} |")
    print(f"| **total (without the stack)** | **{sum(flash.values())}** | **{sum(ram.values())}** |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
