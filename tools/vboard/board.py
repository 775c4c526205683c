"""A virtual servo board: the shipped images on a Cortex-M core with the
part's peripherals, its analogue inputs and bridge wired to the
simulator's motor (the host build's plant and thermal models).

A board is one folder of firmware/boards/, or one given by its path (its
board.h: the flash map, RAM, the bus, the bridge and the analogue front
end, wiring.py), and one entry of PARTS, by the part its board.cmake names
(the silicon: core, SVD, clock tree). Its flash holds
what a factory would program into a blank chip: the bootloader, the
application's update image in the slot and a config record with the
board's ID; a --state folder keeps it across runs, as on a real chip."""
import ctypes
from pathlib import Path

from servo_image import board_facts
from unicorn import arm_const as arm

from . import svd
from .adc import AdcF0, AdcF1
from .clocks import Rcc
from .core import Core, Stop
from .system_space import FIRST_IRQ
from .dma import Dma
from .flash import Flash
from .g0 import AdcG0, Dmamux, FlashG0, RccG0
from .idle_skip import pass_facts
from .inject import Injector
from .model import Model
from .native import Motor, factory_config, stored_id
from .parts import PARTS, Part, elf, images, name_of, part_of  # noqa: F401 (Part, PARTS: imported from here)
from .timers import BridgeTimer, Watchdog
from .usart import Usart
from . import wiring

REPO = Path(__file__).resolve().parents[2]


HSE_HZ = 8_000_000  # the boards' crystal (firmware/boards/*/board_io.h)


def board_h(board) -> dict:
    """board.h's numbers (servo_image.board_facts: the one reader of a
    board's facts); a board its part contradicts is not run (ValueError,
    the check's lines)."""
    problems = board_facts.check(board)
    if problems:
        raise ValueError("; ".join(problems))
    return board_facts.defines(board)


class Memory:
    """Host memory the core maps (mem_map_ptr), so two addresses can share it."""

    def __init__(self, size: int, fill: int):
        self.size = size
        self.buf = (ctypes.c_ubyte * size)(*([fill] * size))

    def read(self, offset: int, n: int) -> bytes:
        return bytes(self.buf[offset:offset + n])

    def write(self, offset: int, data: bytes) -> None:
        self.buf[offset:offset + len(data)] = data

    def ptr(self) -> int:
        return ctypes.addressof(self.buf)


class Board:
    def __init__(self, board: str, servo_id: int, bus, state_dir=None, supply_v=7.4, ambient_c=25.0,
                 boot_image=None, app_image=None, unit=0, plant=None, build=None):
        # unit: boards started before this one with the same ID (a bus of
        # new servos all at ID 0): it names the flash file and the chip's
        # unique ID apart from theirs.
        self.name, self.servo_id, self.bus, self.unit = name_of(board), servo_id, bus, unit
        self.board, self.build = board, build
        self.part = part_of(board)
        self.h = board_h(board)
        self.part_facts = board_facts.parts()[board_facts.part_name(board)]  # hal/ports/parts.toml
        h, part = self.h, self.part
        self.wiring = wired = wiring.of(self.name, h, part)
        self.core = Core(part.cpu, part.reset_hz, part.cpi, part.has_vtor, part.irq_words)
        self.clock_setting = 0  # counts the firmware's clock switches
        self._pins_for, self._roles = None, None  # _pin_roles's cache
        self.flash_base = h["BOARD_FLASH_BASE"]
        self.flash_size = self.part_facts["flash_size"]
        self.flash_mem = Memory(self.flash_size, 0xFF)
        self.ram = Memory(h["BOARD_RAM_SIZE"], 0)
        self.core.map_host(self.flash_base, self.flash_size, self.flash_mem.buf)
        self.core.map_host(h["BOARD_RAM_BASE"], self.ram.size, self.ram.buf)
        self._alias = None
        self.alias_zero(self.flash_mem, self.flash_size)
        self.core.map_host(0x40000000, 0x30000)
        family = self.family = part.family
        if family == "f0":  # the F0's GPIO ports sit on AHB2
            self.core.map_host(0x48000000, 0x2000)
        if family == "g0":  # the G0's on the IOPORT bus (RM0444 2.2)
            self.core.map_host(0x50000000, 0x2000)
        self.core.map_host(*part.system_memory)
        self.core.map_system_control_space()  # last: see there
        dev = svd.device(part.svd)
        irqs = svd.interrupts(part.svd)
        n = part.names
        self.motor = Motor(supply_v, ambient_c, plant)
        self.rcc = (RccG0 if family == "g0" else Rcc)(self, dev[n["rcc"]], HSE_HZ, 1)
        # A board given as a folder: its name (a path would leave state_dir).
        file = f"{Path(str(board)).name}-{servo_id}" + (f"-{unit + 1}" if unit else "") + ".flash"
        path = None if state_dir is None else Path(state_dir) / file
        self.flash = (FlashG0 if family == "g0" else Flash)(
            self, dev[n["flash"]], self.flash_mem, self.flash_base, self.flash_size, h["BOARD_FLASH_PAGE"], path,
            part.program_s, part.erase_s)
        dma_irqs = dict(part.dma_irqs)
        if family == "f1":  # the bus's receive channel, as board.h names it
            dma_irqs = {1: dma_irqs[1], wired.dma_rx: f"DMA1_Channel{wired.dma_rx}"}
        self.dma = Dma(self, dev[n["dma"]], {ch: irqs[name] for ch, name in dma_irqs.items()})
        self.gpio = Model(self, dev[n["gpio"]])
        # The F1's other ports the board's pins are on (RM0008 9.2: GPIOB-D as GPIOA).
        self.ports = [self.gpio] + [Model(self, dev[f"GPIO{'ABCD'[k]}"]) for k in wired.ports() if k and family == "f1"]
        routed = family == "g0"  # the DMAMUX routes the channels (0: none until it does)
        usart = wired.usart_name
        # USART1 on APB2, USART2 and 3 on APB1 (RM0008 7.2's clock tree).
        pclk = self.pclk_hz if wired.usart == 1 or family != "f1" else self.pclk1_hz
        self.usart = Usart(self, dev[usart], pclk, irqs[usart], self.dma,
                           0 if routed else wired.dma_rx, 0 if routed else wired.dma_tx, self.bus_pin_ok)
        adc_class = {"f1": AdcF1, "f0": AdcF0, "g0": AdcG0}[family]
        self.adc = adc_class(self, dev[n["adc"]], self.adc_hz, self.dma, self.adc_input)
        self.tim = BridgeTimer(self, dev[wired.timer_name], self.bridge_pins_ok)
        self.iwdg = Watchdog(self, dev[n["iwdg"]])
        self.models = [self.rcc, self.flash, self.dma, *self.ports, self.usart, self.adc, self.tim, self.iwdg]
        if "syscfg" in n:
            self.syscfg = Model(self, dev[n["syscfg"]])
            self.syscfg.watch("CFGR1", self._mem_mode)
            self.models.append(self.syscfg)
        if "dmamux" in n:
            self.dmamux = Dmamux(self, dev[n["dmamux"]], self.dma, self.usart, self.adc)
            self.models.append(self.dmamux)
        # The ones with something to do between runs, asked once a step.
        self.timed = [m for m in self.models if type(m).next_event_s is not Model.next_event_s]
        self.stepped = [m for m in self.models if type(m).step is not Model.step]
        self.station = bus.attach(self.usart)
        self.usart.bus_station = self.station
        self.pass_start = pass_facts(elf(board, build))  # (address, (section, code), _ebss) or None
        if self.pass_start is not None:
            self.core.skip_memory(self.ram.buf, h["BOARD_RAM_BASE"], self.pass_start[2] - h["BOARD_RAM_BASE"])
        self.injector_elf = elf(board, build)
        self.injector = Injector(self, self.injector_elf)
        self.resets = {"power": 0, "software": 0, "watchdog": 0}
        self.last_reset = None
        self.last_reset_s = 0.0
        self.powered = True
        # A flash file without a bootloader (a start that failed before the
        # factory's programming) is a blank chip too.
        if self.flash.blank or self.flash_mem.read(0, 8) == b"\xff" * 8:
            self._factory(boot_image, app_image)
        self._write_uid()
        self.reset("power")

    # ---- the chip ---------------------------------------------------------
    def _factory(self, boot_image, app_image) -> None:
        boot, app, _ = images(self.board, self.build)
        boot = Path(boot_image or boot).read_bytes()
        app = Path(app_image or app).read_bytes()
        self.flash_mem.write(0, boot)
        self.flash_mem.write(self.h["BOARD_SLOT_BASE"] - self.flash_base, app)
        page = self.h["BOARD_FLASH_PAGE"]
        offset = self.h["BOARD_CONFIG_PAGE0"] - self.flash_base
        pages = ctypes.create_string_buffer(b"\xff" * 2 * page, 2 * page)
        if not factory_config(pages, page, self.h["BOARD_CONFIG_PAGE0"], self.servo_id):
            raise RuntimeError("the config store refused the factory record")
        self.flash_mem.write(offset, pages.raw)
        self.flash.persist(0, self.flash_size)

    def _write_uid(self) -> None:
        """A unique ID per board: lot and wafer words, and the ID."""
        uid = (0x00310042 + self.servo_id, 0x31353033, 0x4E000000 | self.unit << 16 | self.servo_id << 8)
        self.core.write(self.part.uid, b"".join(w.to_bytes(4, "little") for w in uid))

    def alias_zero(self, memory: Memory, size: int) -> None:
        """What address 0 shows: flash from reset (BOOT0 low), or SRAM on
        the F0 once SYSCFG's MEM_MODE says so (RM0360 9.1.1)."""
        if self._alias is not None:
            self.core.uc.mem_unmap(0, self._alias)
        self.core.uc.mem_map_ptr(0, size, 7, memory.ptr())
        self._alias = size

    def _mem_mode(self, value, old, size):
        if value & 3 == 3:
            self.core.defer(lambda: self.alias_zero(self.ram, self.ram.size))
        else:
            self.core.defer(lambda: self.alias_zero(self.flash_mem, self.flash_size))

    def set_core_hz(self, hz: int) -> None:
        """The firmware switched its clocks (RCC's CFGR): what depends on
        them (the USART's baud rate) is worked out again."""
        self.core.hz = hz
        self.clock_setting += 1

    def pclk_hz(self, field=None) -> int:
        """APB2's clock on the F1 (USART1, the ADC), the APB's on the F0 and G0."""
        field = field or ("PPRE2" if "PPRE2" in self.rcc.p.registers["CFGR"][2] else "PPRE")
        code = (self.rcc.get("CFGR") & self.rcc.bit("CFGR", field)) >> self.rcc.p.shift("CFGR", field)
        return self.core.hz >> (0 if code < 4 else code - 3)

    def pclk1_hz(self) -> int:
        """The F1's APB1 clock (USART2 and 3)."""
        return self.pclk_hz("PPRE1")

    def adc_hz(self) -> float:
        if self.family == "f0":
            return 14e6  # the F0's asynchronous HSI14 (CKMODE 0, RM0360 12.3.3)
        if self.family == "g0":  # CKMODE (RM0444 15.12.4): 0 the kernel clock (SYSCLK from reset), PCLK/2, /4, PCLK
            ckmode = self.adc.get("CFGR2") >> 30 & 3
            return self.core.hz if ckmode == 0 else self.pclk_hz() / {1: 2, 2: 4, 3: 1}[ckmode]
        code = (self.rcc.get("CFGR") >> 14) & 3  # ADCPRE: /2, /4, /6, /8
        return self.pclk_hz() / (2 * (code + 1))

    # ---- pins ---------------------------------------------------------------
    def _f1_pin_af_output(self, pin: int) -> bool:
        """pin: 0xPN (wiring.py)."""
        port = self.ports[self.wiring.ports().index(pin >> 4)]
        reg = port.get("CRL" if pin & 0xF < 8 else "CRH")
        nibble = reg >> (4 * (pin % 8)) & 0xF
        return nibble & 3 != 0 and nibble >> 2 in (2, 3)

    def _f0_pin_af(self, pin: int, af: int) -> bool:
        mode = self.gpio.get("MODER") >> (2 * pin) & 3
        afr = self.gpio.get("AFRL" if pin < 8 else "AFRH") >> (4 * (pin % 8)) & 0xF
        return mode == 2 and afr == af

    def _pins(self) -> tuple:
        """The ports' configuration words that say what the bus's and the
        bridge's pins are."""
        if self.family != "f1":
            g = self.gpio
            return g.w[g.i["MODER"]], g.w[g.i["AFRL"]], g.w[g.i["AFRH"]]
        return tuple(w for g in self.ports for w in (g.w[g.i["CRL"]], g.w[g.i["CRH"]]))

    def _pin_roles(self) -> tuple:
        """(the TX pin is the USART's, the bridge's pins are its timer's
        CH1/CH2), worked out again only when a port's configuration changed."""
        key = self._pins()
        if key != self._pins_for:
            w = self.wiring
            if self.family != "f1":  # F0, G0: PA9, PA6, PA7 on AF1 (DS9773, DS12992 alternate functions)
                roles = (self._f0_pin_af(9, 1), self._f0_pin_af(6, 1) and self._f0_pin_af(7, 1))
            else:  # F1: alternate-function outputs
                roles = (self._f1_pin_af_output(w.tx_pin), all(map(self._f1_pin_af_output, w.bridge_pins)))
            self._pins_for, self._roles = key, roles
        return self._roles

    def bus_pin_ok(self) -> bool:
        """The bus's TX pin is its USART's (F1: alternate-function output; F0, G0: AF1)."""
        return self._pin_roles()[0]

    def bridge_pins_ok(self) -> bool:
        """The bridge's pins are its timer's CH1/CH2."""
        return self._pin_roles()[1]

    def adc_input(self, channel: int) -> int:
        """The front end's reading of the models (board.h's scaling; no noise)."""
        what = self.wiring.adc.get(channel)
        h = self.h
        if what == "supply":
            counts = self.motor.get("supply_v") * 1e6 / h["BOARD_SUPPLY_UV_PER_COUNT"]
        elif what == "current":
            counts = abs(self.motor.get("current_a")) * 1e6 / h["BOARD_CURRENT_UA_PER_COUNT"] + \
                h["BOARD_CURRENT_ZERO_COUNTS"]
        elif what == "ntc":
            counts = self.motor.ntc_adc()
        elif what == "encoder":
            counts = self.motor.encoder()
        else:
            counts = 0
        return max(0, min(4095, int(counts + 0.5)))

    # ---- running --------------------------------------------------------
    def reset(self, cause: str) -> None:
        self.resets[cause] += 1
        self.last_reset = cause
        self.last_reset_s = self.core.time_s
        for m in self.models:
            m.reset()
        self.rcc.reset_with(cause)
        if "syscfg" in self.part.names:
            self.alias_zero(self.flash_mem, self.flash_size)
        self.core.reset(self.flash_base)
        self.injector.reset()
        self.core.skip_at = self._pass_start()
        self.motor.coast()
        self.duty = None  # the bridge's, as the motor was last told

    def _pass_start(self) -> int:
        """Where the main loop's pass begins, if the flash holds the ELF's
        code section (an update may have brought another image): else 0."""
        if self.pass_start is None:
            return 0
        address, (section, code), _ = self.pass_start
        return address if self.flash_mem.read(section - self.flash_base, len(code)) == code else 0

    def power_cycle(self, off_s: float = 0.1) -> None:
        """Power off (the motor coasts, RAM is lost), then on."""
        self.ram.write(0, bytes(self.ram.size))
        self.core.idle(off_s)
        self._write_uid()
        self.reset("power")

    def brownout(self, dip_s: float = 5e-3) -> None:
        """VDD dips below the power-down reset level (VPOR/PDR, 1.88 V
        typical falling: DS5319 and DS9773, "Embedded reset and power
        control block characteristics") for dip_s and comes back: a
        power-on reset (PORRSTF), the motor coasting meanwhile, but the
        SRAM keeps what it held (a short dip; power_cycle loses it)."""
        self.injector.brownouts += 1
        self.core.idle(dip_s)
        self._write_uid()
        self.reset("power")

    def run_until(self, t_s: float, max_step_s: float = 1e-3) -> None:
        """Runs the board to t_s, in steps of at most max_step_s, each
        ending where a model or SysTick next has something to do, and no
        further than the end of a byte it starts sending: the runner
        delivers it then, to the host and to the other boards."""
        core, motor, bus = self.core, self.motor, self.bus
        while (now := core.time_s) < t_s:
            t_s = min(t_s, bus.next_event_s())
            soon = min(t_s, now + max_step_s, now + core.cycles_to_systick() / core.hz)
            for m in self.timed:
                soon = min(soon, m.next_event_s(now))
            step = max(soon - now, 1e-6)
            try:
                passed = core.run(step)
            except Stop as stop:
                if stop.args[0] == "power":
                    self.power_cycle()
                else:
                    self.reset(stop.args[0])
                continue
            motor.step(passed)
            now = core.time_s
            if core.ran and not self.flash.check_wait_states(core.hz):
                core.pending.add(3)  # reads at this clock return garbage: a fault
            for m in self.stepped:
                m.step(now)
            if core.ran:  # the clock, the bridge and its pins change only by the code's stores
                duty = self.tim.duty()
                if duty != self.duty:
                    self.duty = duty
                    if duty is None:
                        motor.coast()
                    else:
                        motor.drive(duty)
            if now >= self.iwdg.bites_s:
                self.reset("watchdog")

    def bus_id(self) -> int:
        """The ID the board answers at: its config store's (as its
        bootloader reads it; the application takes a new one as it
        stores it)."""
        page = self.h["BOARD_FLASH_PAGE"]
        page0 = self.h["BOARD_CONFIG_PAGE0"]
        return stored_id(self.flash_mem.read(page0 - self.flash_base, 2 * page), page, page0)

    def in_application(self) -> bool:
        pc = self.core.uc.reg_read(arm.UC_ARM_REG_PC)
        return self.h["BOARD_SLOT_BASE"] <= pc < self.h["BOARD_CONFIG_PAGE0"]

    def state(self) -> dict:
        m = self.motor
        return {"id": self.bus_id(), "board": self.name, "sim_ms": round(self.core.now_s() * 1000, 3),
                "angle": round(m.get("angle_deg"), 3), "velocity": round(m.get("velocity_dps"), 2),
                "current": round(m.get("current_a"), 3), "winding": round(m.get("winding_c"), 2),
                "case": round(m.get("case_c"), 2), "ambient": round(m.get("ambient_c"), 1),
                "supply": round(m.get("supply_v"), 3), "load": round(m.get("load_nm"), 3),
                "payload": round(m.get("payload_gcm2"), 1),
                "core_mhz": round(self.core.hz / 1e6, 3), "resets_power": self.resets["power"],
                "resets_software": self.resets["software"], "resets_watchdog": self.resets["watchdog"],
                "last_reset": self.last_reset, "last_reset_ms": round(self.last_reset_s * 1000, 6), "mode": "app" if self.in_application() else "bootloader",
                "locked_up": int(self.core.locked_up), "asleep_ms": round(self.core.slept_s * 1000, 3),
                "usart_interrupts": self.core.taken.get(FIRST_IRQ + self.usart.irq, 0),
                "rx_bytes": self.usart.rx_bytes,
                "page_erases": self.flash.erases, "flash_ops": self.flash.ops, "flash_stall_ms": round(self.flash.stalled_s * 1000, 3),
                "erase_began_ms": round(self.flash.erase_began_s * 1000, 3),
                "last_sent_ms": round(self.bus.last_sent_s.get(self.station, 0.0) * 1000, 3),
                "framing_errors": self.usart.framing_errors, "begun_deaf": self.usart.begun_deaf, "overruns": self.usart.overruns,
                "pc": f"{self.core.uc.reg_read(arm.UC_ARM_REG_PC):#010x}", **self.injector.state()}
