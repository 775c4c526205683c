"""The STM32G031's registers, as the models read them (svd.device
"STM32G031"). cmsis-svd 0.4 has no G0 file, so this table is written from
RM0444 (the STM32G0x1 reference manual) and ST's STM32G031 SVD, each
register with its section; only what the models and the firmware touch.

Where the G031 has the F0's IP unchanged, its F030 description is taken
and moved (RM0444 2.2's memory map): the USART (RM0444 33.8: CR1 to TDR at
the F0's offsets and bits, PRESC at 0x2C added), DMA1 (RM0444 10.6: the
F0's channel registers, 5 channels on the G031, 10.3.2), TIM3 (RM0444 23.4,
the F0's general-purpose timer), the IWDG (RM0444 27.7) and GPIOA, on the
IOPORT bus at 0x50000000 (RM0444 7.4, the F0's layout; MODER resets to
0xEBFFFFFF: every pin analogue but PA13/PA14, 7.4.1). The RCC, the flash
interface and the DMAMUX are the G0's own; its ADC is the F0's with the
voltage regulator (CR.ADVREGEN) and the channel-configuration flag
(ISR.CCRDY) added (RM0444 15.12)."""
import functools

# RM0444 table 54 (the vector table): the same lines as the F030's.
INTERRUPTS = {"DMA1_Channel1": 9, "DMA1_Channel2_3": 10, "DMA1_Ch4_5_DMAMUX_OVR": 11, "ADC": 12,
              "TIM3": 16, "USART1": 27, "USART2": 28}


def _bits(**fields) -> dict:
    return {name: spec for name, spec in fields.items()}


# name -> (offset, reset value, {field: (bit, width)})
RCC = {
    # RM0444 5.4.1: HSI16 on and ready from reset (0x00000500); HSIDIV 13:11 (/1 at reset)
    "CR": (0x00, 0x00000500, _bits(HSION=(8, 1), HSIKERON=(9, 1), HSIRDY=(10, 1), HSIDIV=(11, 3),
                                   HSEON=(16, 1), HSERDY=(17, 1), HSEBYP=(18, 1), CSSON=(19, 1),
                                   PLLON=(24, 1), PLLRDY=(25, 1))),
    "ICSCR": (0x04, 0x00004000, _bits(HSICAL=(0, 8), HSITRIM=(8, 7))),       # RM0444 5.4.2
    # RM0444 5.4.3: SW 2:0 (0 HSISYS, 1 HSE, 2 PLLRCLK, 3 LSI, 4 LSE), SWS 5:3, HPRE 11:8, PPRE 14:12
    "CFGR": (0x08, 0x00000000, _bits(SW=(0, 3), SWS=(3, 3), HPRE=(8, 4), PPRE=(12, 3), MCOSEL=(24, 3),
                                     MCOPRE=(28, 3))),
    # RM0444 5.4.4: PLLSRC 1:0 (2 HSI16, 3 HSE), PLLM 6:4 (/M+1), PLLN 14:8, PLLR 31:29 (/R+1)
    "PLLCFGR": (0x0C, 0x00001000, _bits(PLLSRC=(0, 2), PLLM=(4, 3), PLLN=(8, 7), PLLPEN=(16, 1),
                                        PLLP=(17, 5), PLLQEN=(24, 1), PLLQ=(25, 3), PLLREN=(28, 1),
                                        PLLR=(29, 3))),
    "CIER": (0x18, 0, {}), "CIFR": (0x1C, 0, {}), "CICR": (0x20, 0, {}),   # RM0444 5.4.5-5.4.7
    "IOPRSTR": (0x24, 0, {}), "AHBRSTR": (0x28, 0, {}), "APBRSTR1": (0x2C, 0, {}), "APBRSTR2": (0x30, 0, {}),
    "IOPENR": (0x34, 0, _bits(GPIOAEN=(0, 1))),                               # RM0444 5.4.12
    "AHBENR": (0x38, 0x00000100, _bits(DMA1EN=(0, 1), FLASHEN=(8, 1))),      # RM0444 5.4.13
    "APBENR1": (0x3C, 0, _bits(TIM3EN=(1, 1), USART2EN=(17, 1))),            # RM0444 5.4.14
    "APBENR2": (0x40, 0, _bits(SYSCFGEN=(0, 1), USART1EN=(14, 1), ADCEN=(20, 1))),  # RM0444 5.4.15
    "CCIPR": (0x54, 0, _bits(USART1SEL=(0, 2), ADCSEL=(30, 2))),             # RM0444 5.4.21
    "BDCR": (0x5C, 0, {}),                                                    # RM0444 5.4.25
    # RM0444 5.4.26: LSION, LSIRDY; RMVF (bit 23, not the F0/F1's 24) clears the
    # flags: OBLRSTF 25, PINRSTF 26, PWRRSTF 27 (BOR/POR), SFTRSTF 28, IWDGRSTF 29,
    # WWDGRSTF 30, LPWRRSTF 31.
    "CSR": (0x60, 0x0C000000, _bits(LSION=(0, 1), LSIRDY=(1, 1), RMVF=(23, 1), OBLRSTF=(25, 1),
                                    PINRSTF=(26, 1), PWRRSTF=(27, 1), SFTRSTF=(28, 1), IWDGRSTF=(29, 1),
                                    WWDGRSTF=(30, 1), LPWRRSTF=(31, 1))),
}

FLASH = {
    # RM0444 3.7.1; reset 0x00000600 as ST's STM32G031 SVD has it (ICEN set)
    "ACR": (0x00, 0x00000600, _bits(LATENCY=(0, 3), PRFTEN=(8, 1), ICEN=(9, 1), ICRST=(11, 1),
                                    EMPTY=(16, 1), DBG_SWEN=(18, 1))),
    "KEYR": (0x08, 0, _bits(KEYR=(0, 32))),                                   # RM0444 3.7.2
    "OPTKEYR": (0x0C, 0, _bits(OPTKEYR=(0, 32))),                             # RM0444 3.7.3
    # RM0444 3.7.4: EOP and the errors write-1-to-clear; BSY1 16, CFGBSY 18
    "SR": (0x10, 0, _bits(EOP=(0, 1), OPERR=(1, 1), PROGERR=(3, 1), WRPERR=(4, 1), PGAERR=(5, 1),
                          SIZERR=(6, 1), PGSERR=(7, 1), MISERR=(8, 1), FASTERR=(9, 1), RDERR=(14, 1),
                          OPTVERR=(15, 1), BSY1=(16, 1), CFGBSY=(18, 1))),
    # RM0444 3.7.5: PG, PER, MER, PNB 8:3 (the page's number), STRT 16, LOCK 31, OPTLOCK 30
    "CR": (0x14, 0xC0000000, _bits(PG=(0, 1), PER=(1, 1), MER=(2, 1), PNB=(3, 6), STRT=(16, 1),
                                   OPTSTRT=(17, 1), FSTPG=(18, 1), EOPIE=(24, 1), ERRIE=(25, 1),
                                   RDERRIE=(26, 1), OBL_LAUNCH=(27, 1), SEC_PROT=(28, 1),
                                   OPTLOCK=(30, 1), LOCK=(31, 1))),
    # RM0444 3.7.6: ADDR_ECC 13:0 (the failing double word's offset), SYSF_ECC 20,
    # ECCCIE 24, ECCC 30 (corrected), ECCD 31 (two bits wrong: the NMI); both rc_w1
    "ECCR": (0x18, 0, _bits(ADDR_ECC=(0, 14), SYSF_ECC=(20, 1), ECCCIE=(24, 1), ECCC=(30, 1),
                            ECCD=(31, 1))),
}

# RM0444 11.6.1: DMAMUX_CxCR, x = 0..4 on the G031 (11.3.2: as many as DMA1's
# channels); DMAREQ_ID 5:0 the request (11.3.2's table: 5 ADC, 50 USART1_RX,
# 51 USART1_TX).
DMAMUX = {f"C{x}CR": (4 * x, 0, _bits(DMAREQ_ID=(0, 6), SOIE=(8, 1), EGE=(9, 1), SE=(16, 1),
                                      SPOL=(17, 2), NBREQ=(19, 5), SYNC_ID=(24, 5)))
          for x in range(5)}
DMAMUX["CSR"] = (0x80, 0, {})
DMAMUX["CFR"] = (0x84, 0, {})

BASES = {"RCC": 0x40021000, "FLASH": 0x40022000, "DMAMUX": 0x40020800}  # RM0444 2.2, table 6


@functools.lru_cache(maxsize=None)
def device() -> dict:
    from .svd import Peripheral, device as svd_device
    f0 = svd_device("STM32F030")

    def moved(name: str, base: int, drop=(), add=None, resets=None, fields=None) -> Peripheral:
        regs = {r: spec for r, spec in f0[name].registers.items() if r not in drop}
        regs.update(add or {})
        for reg, value in (resets or {}).items():
            regs[reg] = (regs[reg][0], value, regs[reg][2])
        for reg, extra in (fields or {}).items():
            regs[reg] = (regs[reg][0], regs[reg][1], {**regs[reg][2], **extra})
        return Peripheral(name, base, regs)

    out = {name: Peripheral(name, BASES[name], regs) for name, regs in
           (("RCC", RCC), ("FLASH", FLASH), ("DMAMUX", DMAMUX))}
    out["USART1"] = moved("USART1", 0x40013800, add={"PRESC": (0x2C, 0, _bits(PRESCALER=(0, 4)))})
    out["DMA1"] = moved("DMA", 0x40020000, drop=[f"{r}{n}" for r in ("CCR", "CNDTR", "CPAR", "CMAR") for n in (6, 7)])
    out["TIM3"] = moved("TIM3", 0x40000400)
    out["IWDG"] = moved("IWDG", 0x40003000)
    out["GPIOA"] = moved("GPIOA", 0x50000000, resets={"MODER": 0xEBFFFFFF, "OSPEEDR": 0x0C000000})
    # RM0444 15.12: CR.ADVREGEN 28; ISR.CCRDY 13; CFGR2.CKMODE 31:30 (0 the
    # ADCSEL kernel clock, 1 PCLK/2, 2 PCLK/4, 3 PCLK); SMPR's SMP1 2:0.
    out["ADC"] = moved("ADC", 0x40012400, resets={"CFGR2": 0},
                       fields={"CR": {"ADVREGEN": (28, 1)}, "ISR": {"CCRDY": (13, 1)},
                               "CFGR2": {"CKMODE": (30, 2)}, "SMPR": {"SMP1": (0, 3)}})
    return out
