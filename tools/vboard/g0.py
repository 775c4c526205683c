"""The STM32G031's own peripherals (RM0444; registers g0_registers.py's):
its clock tree, its flash interface with 64-bit ECC units, the DMAMUX that
routes requests to DMA1's channels, and its ADC's additions to the F0's.

RCC (RM0444 5): HSI16 from reset (SYSCLK 16 MHz / HSIDIV, 5.2.2), the PLL
from PLLCFGR (PLLRCLK = source / (PLLM + 1) x PLLN / (PLLR + 1), 5.4.4),
ready bits once on, SWS following SW; the reset flags as the F0/F1's but
PWRRSTF (bit 27) for a power-on and RMVF at bit 23 (5.4.26); LSIRDY
follows LSION.

Flash (RM0444 3.3.7, 3.7): unlocked by KEYR's two keys; with PG a
program operation takes a double word: the first word (at an 8-byte
aligned address) is held, the second (the next word) starts it, and the
pair is written with its ECC byte, the CPU standing still for tPROG. A
double word not erased (other than one of zeros) is PROGERR and is left as
it was; a second word outside the first's double word PGAERR; a byte or
half-word store SIZERR; a store without PG PGSERR. PER with PNB and STRT
erases page PNB (by number, not address), the CPU standing still for
tERASE. EOP sets only with EOPIE (3.7.4). A double word whose program
operation the power cut (`cutprogram`) holds data whose ECC does not match:
each read of it sets ECCR's ECCD with its address (3.3.9, 3.7.6) and raises
the NMI (RM0444 3.5: a double ECC error is the NMI); erasing its page
mends it. The torn units live beside the flash file (FILE.ecc). An erase
the power cuts (`cutflash`) leaves its page partly erased: RM0444 3.3.7
gives the erase sequence, not what a power loss in it leaves, so the model
takes what a reader finds hardest: the first half of the page erased, the
double word at its middle torn (it raises the NMI when read, as a program
cut short), the rest as it held.

DMAMUX (RM0444 11): DMA1 channel n serves the request C(n-1)CR's
DMAREQ_ID names (11.3.2: 5 ADC, 50 USART1_RX, 51 USART1_TX); a request no
channel names goes nowhere.

ADC (RM0444 15): the F0's, and CHSELR's write sets CCRDY (15.3.8); the
sampling time codes are the G0's (15.12.6: 1.5 to 160.5 cycles); its clock
is CFGR2's CKMODE (PCLK / 2, / 4, PCLK; 0: the kernel clock, SYSCLK from
reset, RCC_CCIPR ADCSEL)."""
import json
import os

from unicorn import UC_HOOK_MEM_READ

from .adc import AdcF0
from .clocks import Rcc
from .flash import Flash
from .model import Model

HSI16_HZ = 16_000_000  # RM0444 5.2.2
NMI = 2
REQ_ADC, REQ_USART1_RX, REQ_USART1_TX = 5, 50, 51  # RM0444 11.3.2
SAMPLE_CYCLES_G0 = (1.5, 3.5, 7.5, 12.5, 19.5, 39.5, 79.5, 160.5)  # RM0444 15.12.6


class RccG0(Rcc):
    RESET_FLAGS = {"power": ("PWRRSTF", "PINRSTF"), "software": ("SFTRSTF", "PINRSTF"),
                   "watchdog": ("IWDGRSTF", "PINRSTF"), "pin": ("PINRSTF",)}

    def _csr(self, value, old, size):
        lsirdy = self.bit("CSR", "LSIRDY")
        value = value | lsirdy if value & self.bit("CSR", "LSION") else value & ~lsirdy
        if value & self.bit("CSR", "RMVF"):
            value &= 0x00FFFFFF & ~self.bit("CSR", "RMVF")
        self.core.fix(self.addr("CSR"), value)

    def field(self, register: str, name: str, value: int = None) -> int:
        value = self.get(register) if value is None else value
        return (value & self.bit(register, name)) >> self.p.shift(register, name)

    def sysclk(self, cfgr: int) -> int:
        sw = self.field("CFGR", "SW", cfgr)
        if sw == 1:
            return self.hse_hz
        if sw == 2:
            source = {2: HSI16_HZ, 3: self.hse_hz}.get(self.field("PLLCFGR", "PLLSRC"), 0)
            vco = source // (self.field("PLLCFGR", "PLLM") + 1) * self.field("PLLCFGR", "PLLN")
            return vco // (self.field("PLLCFGR", "PLLR") + 1)
        if sw == 3:
            return self.board.part_facts["lsi_hz"]
        return HSI16_HZ >> self.field("CR", "HSIDIV")


class FlashG0(Flash):
    def __init__(self, board, periph, memory, base, size, page, path, program_s, erase_s):
        self.torn = {}      # offset of a torn double word -> its read hook
        self.first = None   # (offset, word) of a program operation's first word
        super().__init__(board, periph, memory, base, size, page, path, program_s, erase_s)
        self.watch("ECCR", self._eccr)
        self.ecc_path = None if path is None else f"{path}.ecc"
        if self.ecc_path and os.path.exists(self.ecc_path) and not self.blank:
            for offset in json.load(open(self.ecc_path)):
                self._tear(offset, save=False)

    def reset(self) -> None:
        """A torn read's NMI not yet taken goes with the reset (the core's
        reset clears what is pending): the new run takes its own."""
        super().reset()
        self.first = None

    def _flag(self, name: str) -> int:
        return self.bit("SR", name)

    def _error(self, name: str) -> None:
        self.put("SR", self.get("SR") | self.bit("SR", name))

    def _done(self) -> None:
        if self.get("CR") & self.bit("CR", "EOPIE"):
            self.put("SR", self.get("SR") | self.bit("SR", "EOP"))

    def _sr(self, value, old, size):
        names = ("EOP", "OPERR", "PROGERR", "WRPERR", "PGAERR", "SIZERR", "PGSERR", "MISERR", "FASTERR",
                 "RDERR", "OPTVERR")
        clear = sum(self.bit("SR", n) for n in names) & value
        self.core.fix(self.addr("SR"), old & ~clear)

    def _eccr(self, value, old, size):
        clear = value & (self.bit("ECCR", "ECCD") | self.bit("ECCR", "ECCC"))  # rc_w1
        keep = self.bit("ECCR", "ECCCIE")
        self.core.fix(self.addr("ECCR"), (old & ~clear & ~keep) | (value & keep))

    def _cr(self, value, old, size):
        lock = self.bit("CR", "LOCK")
        if value & lock and self.keys_seen == 2:
            self.keys_seen = 0
        if old & lock:
            value = old | (value & lock)
        elif value & self.bit("CR", "STRT"):
            if value & self.bit("CR", "PER"):
                self._erase_page((value & self.bit("CR", "PNB")) >> self.p.shift("CR", "PNB"))
            value &= ~self.bit("CR", "STRT")  # cleared by hardware as BSY1 falls
        if not value & self.bit("CR", "PG"):
            self.first = None
        self.core.fix(self.addr("CR"), value)

    def cut_erase(self, start: int) -> None:
        self._mend(start, start + self.page // 2)
        self._tear(start + self.page // 2)
        super().cut_erase(start)

    def _mend(self, begin: int, end: int) -> None:
        """The torn units in [begin, end) erased: whole again."""
        for offset in [o for o in self.torn if begin <= o < end]:
            self.core.uc.hook_del(self.torn.pop(offset))
        self._save_torn()

    def _erase_page(self, number: int) -> None:
        start = number * self.page
        if start < self.size and self.cut(program=False):
            self.erases += 1
            self.erase_began_s = self.core.now_s()
            self.cut_erase(start)
            return
        if start < self.size and self.fail_erases == 0:
            self.memory.write(start, b"\xff" * self.page)
            self.persist(start, self.page)
            self._mend(start, start + self.page)
            self._done()
        else:
            self.fail_erases = max(0, self.fail_erases - 1)
            self._error("WRPERR")
        self.erases += 1
        self.erase_began_s = self.core.now_s()
        self.stalled_s += self.erase_s
        self.core.stop(stall_s=self.erase_s)

    def _store(self, address: int, value: int, size: int) -> None:
        offset = address - self.base
        old = bytes(self.memory.read(offset, size))
        self.core.fix(address, old)  # the cells keep what they hold unless programmed below
        cr = self.get("CR")
        if cr & self.bit("CR", "LOCK"):
            return
        if not cr & self.bit("CR", "PG"):
            self._error("PGSERR")
            return
        if size != 4:
            self._error("SIZERR")
            self.first = None
            return
        if self.first is None:
            if offset & 7:
                self._error("PGAERR")
            else:
                self.first = (offset, value)
            return
        (lo_at, lo), self.first = self.first, None
        if offset != lo_at + 4:
            self._error("PGAERR")
            return
        self._program(lo_at, (lo | value << 32).to_bytes(8, "little"))

    def _program(self, offset: int, data: bytes) -> None:
        was = bytes(self.memory.read(offset, 8))
        self.stalled_s += self.program_s
        if self.cut(program=True):  # cut as it programs: data with no ECC to match
            self.memory.write(offset, bytes(a & b for a, b in zip(was, data)))
            self.persist(offset, 8)
            self.core.fix(self.base + offset, bytes(a & b for a, b in zip(was, data)))
            self._tear(offset)
            self.core.stop(reset="power")
            return
        if self.fail_programs or (was != b"\xff" * 8 and data != bytes(8)):
            self.fail_programs = max(0, self.fail_programs - 1)
            self._error("PROGERR" if was != b"\xff" * 8 else "WRPERR")
        else:
            self.memory.write(offset, data)
            self.persist(offset, 8)
            self.core.fix(self.base + offset, data)
            self._done()
        self.core.stop(stall_s=self.program_s)

    # ---- ECC --------------------------------------------------------------
    def _tear(self, offset: int, save: bool = True) -> None:
        if offset in self.torn:
            return
        begin = self.base + offset
        self.torn[offset] = self.core.uc.hook_add(UC_HOOK_MEM_READ, self._torn_read, begin=begin, end=begin + 7)
        if save:
            self._save_torn()

    def _save_torn(self) -> None:
        if self.ecc_path:
            with open(self.ecc_path, "w") as f:
                json.dump(sorted(self.torn), f)

    def _torn_read(self, uc, access, address, size, value, data) -> None:
        """A read of a torn double word: ECCD, its address, and the NMI,
        taken once the load is done: the run ends before the next
        instruction (the core's instruction count). A stop here would undo
        the load, which would run again and raise it again, for ever; and a
        code hook added now would miss the code Unicorn has translated
        already (a bootloader's loop: the NMI never came)."""
        eccr = self.get("ECCR")
        if not eccr & self.bit("ECCR", "ECCD"):
            unit = ((address - self.base) >> 3) & self.bit("ECCR", "ADDR_ECC")
            self.put("ECCR", (eccr & ~self.bit("ECCR", "ADDR_ECC")) | unit | self.bit("ECCR", "ECCD"))
        self.core.pending.add(NMI)
        if self.core.running:
            self.core.count.limit = self.core.count.executed


class Dmamux(Model):
    def __init__(self, board, periph, dma, usart, adc):
        super().__init__(board, periph)
        self.dma, self.usart, self.adc = dma, usart, adc
        self.routes = {}  # DMA channel -> request
        self.channels = [x + 1 for x in range(8) if f"C{x}CR" in periph.registers]
        for n in self.channels:
            self.watch(f"C{n - 1}CR", self._ccr(n))

    def reset(self) -> None:
        super().reset()
        self.routes = {}
        self._apply()

    def _ccr(self, n: int):
        def handler(value, old, size):
            self.routes[n] = value & self.bit(f"C{n - 1}CR", "DMAREQ_ID")
            self.core.defer(self._apply)
        return handler

    def channel_of(self, request: int) -> int:
        """The channel serving a request, 0 for none (the lowest if several)."""
        return min((n for n, r in self.routes.items() if r == request), default=0)

    def _apply(self) -> None:
        usart, dma = self.usart, self.dma
        usart.dma_channel = self.channel_of(REQ_USART1_RX)
        tx = self.channel_of(REQ_USART1_TX)
        if dma.on_enable.get(usart.tx_dma_channel) == usart.pull:
            del dma.on_enable[usart.tx_dma_channel]
        usart.tx_dma_channel = tx
        if tx:
            dma.on_enable[tx] = usart.pull
        self.adc.dma_channel = self.channel_of(REQ_ADC)


class AdcG0(AdcF0):
    def __init__(self, board, periph, adc_hz, dma, channel_value):
        super().__init__(board, periph, adc_hz, dma, channel_value)
        self.dma_channel = 0  # the DMAMUX's to route
        self.watch("CHSELR", self._chselr)

    def _chselr(self, value, old, size):
        self.put("ISR", self.get("ISR") | self.bit("ISR", "CCRDY"))
        self.core.defer(lambda: None)

    def scan_s(self) -> float:
        sample = SAMPLE_CYCLES_G0[self.get("SMPR") & self.bit("SMPR", "SMP1")]
        return len(self.sequence()) * (sample + 12.5) / self.adc_hz()
