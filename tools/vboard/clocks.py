"""The reset and clock control (RM0008 7, RM0360 6): oscillators and the PLL
report ready once switched on, the clock switch reports the source it
selects, the reset flags say why the chip last reset. The core's clock
follows what the firmware selects: HSI 8 MHz from reset, HSE (the board's
crystal) or the PLL."""
from .model import Model

HSI_HZ = 8_000_000  # RM0008 7.2.1, RM0360 6.2.2


class Rcc(Model):
    # RM0008 7.3.10, RM0360 6.4.10: a power-on sets PORRSTF, every reset PINRSTF
    RESET_FLAGS = {"power": ("PORRSTF", "PINRSTF"), "software": ("SFTRSTF", "PINRSTF"),
                   "watchdog": ("IWDGRSTF", "PINRSTF"), "pin": ("PINRSTF",)}

    def __init__(self, board, periph, hse_hz: int, pll_from_hse_div: int):
        super().__init__(board, periph)
        self.hse_hz, self.pll_div = hse_hz, pll_from_hse_div
        self.watch("CR", self._cr)
        self.watch("CFGR", self._cfgr)
        self.watch("CSR", self._csr)

    def reset_with(self, cause: str) -> None:
        """Registers to their reset values, the flags of this reset set
        (RM0008 7.3.10: a power-on sets PORRSTF, every reset PINRSTF)."""
        flags = self.get("CSR") & 0xFF000000 if cause != "power" else 0
        self.reset()
        named = self.RESET_FLAGS[cause]
        for f in named:
            flags |= self.bit("CSR", f)
        self.put("CSR", (self.get("CSR") & 0x00FFFFFF) | flags)
        self.board.set_core_hz(self.sysclk(self.get("CFGR")))

    def _cr(self, value, old, size):
        for on, ready in (("HSEON", "HSERDY"), ("PLLON", "PLLRDY"), ("HSION", "HSIRDY")):
            value = value | self.bit("CR", ready) if value & self.bit("CR", on) else value & ~self.bit("CR", ready)
        self.core.fix(self.addr("CR"), value)

    def _cfgr(self, value, old, size):
        sw = value & self.bit("CFGR", "SW")
        value = (value & ~self.bit("CFGR", "SWS")) | (sw << self.p.shift("CFGR", "SWS"))
        self.core.fix(self.addr("CFGR"), value)
        self.board.set_core_hz(self.sysclk(value))

    def _csr(self, value, old, size):
        if value & self.bit("CSR", "RMVF"):
            value &= 0x00FFFFFF & ~self.bit("CSR", "RMVF")
        self.core.fix(self.addr("CSR"), value)

    def sysclk(self, cfgr: int) -> int:
        sw = cfgr & self.bit("CFGR", "SW")
        if sw == 1:
            return self.hse_hz
        if sw == 2:
            mul = min(((cfgr & self.bit("CFGR", "PLLMUL")) >> self.p.shift("CFGR", "PLLMUL")) + 2, 16)
            from_hse = cfgr & (1 << 16)  # PLLSRC's HSE bit, on both parts
            source = self.hse_hz // self.pll_div if from_hse else HSI_HZ // 2
            return source * mul
        return HSI_HZ
