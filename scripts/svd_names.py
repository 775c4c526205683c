"""How the ports' register headers name what ST's SVD files name otherwise,
for check_regs_svd.py: the instance a function-like macro is checked at,
fields and registers by other names, values made of several fields, the
interrupts' numbers, and what no SVD describes (the core's registers)."""

# Arguments for the function-like macros: the instance each port uses.
CALLS = {
    "USART_": "USART1_BASE", "TIM_": "TIM3_BASE", "NVIC_": "0u",
    "DMA_": "DMA1_CCR_ADDR(1u)", "DMA1_CCR_ADDR": "1u", "DMA1_FLAGS": "1u", "GPIO_CR": "GPIOA_BASE",
}

# A part's own instances where its header names them otherwise.
PART_CALLS = {"STM32G031": {"USART_": "G0_USART1_BASE", "G0_DMAMUX_CCR": "1u"}}

# Where a field's name in the SVD is not the macro's.
FIELD_NAMES = {
    ("STM32F103xx", "RCC_APB2ENR_AFIO"): "AFIOEN",
    ("STM32F103xx", "RCC_APB2ENR_GPIOA"): "IOPAEN",
    ("STM32F103xx", "RCC_APB2ENR_GPIOB"): "IOPBEN",
    ("STM32F103xx", "RCC_APB2ENR_GPIOC"): "IOPCEN",
    ("STM32F103xx", "RCC_APB2ENR_GPIOD"): "IOPDEN",
    ("STM32F103xx", "RCC_APB1ENR_TIM2"): "TIM2EN",
    ("STM32F103xx", "RCC_APB1ENR_TIM4"): "TIM4EN",
    ("STM32F103xx", "RCC_AHBENR_DMA1"): "DMA1EN",
    ("STM32F103xx", "RCC_APB2ENR_ADC1"): "ADC1EN",
    ("STM32F103xx", "RCC_APB1ENR_USART2"): "USART2EN",
    ("STM32F103xx", "RCC_APB1ENR_USART3"): "USART3EN",
    ("STM32F030", "RCC_AHBENR_GPIOA"): "IOPAEN",
    ("STM32F030", "RCC_AHBENR_DMA1"): "DMAEN",
    ("STM32F030", "RCC_APB2ENR_ADC1"): "ADCEN",
    ("STM32F030", "RCC_APB2ENR_SYSCFG"): "SYSCFGEN",
    ("STM32F030", "FLASH_SR_WRPRTERR"): "WRPRT",
    (None, "RCC_APB2ENR_USART1"): "USART1EN",
    (None, "RCC_APB1ENR_TIM3"): "TIM3EN",
    ("STM32F030", "RCC_CFGR_PPRE1_DIV2"): None,  # F1 only (F0's is PPRE)
    ("STM32G031", "RCC_CSR_PORRSTF"): "PWRRSTF",
    (None, "G0_RCC_IOPENR_GPIOA"): "IOPAEN",
    (None, "G0_RCC_AHBENR_DMA1"): "DMAEN",
    (None, "G0_RCC_APBENR1_TIM3"): "TIM3EN",
    (None, "G0_RCC_APBENR1_USART2"): "USART2EN",
    (None, "G0_RCC_APBENR2_USART1"): "USART1EN",
    (None, "G0_RCC_APBENR2_ADC"): "ADCEN",
    (None, "G0_FLASH_SR_BSY1"): "BSY",
    (None, "G0_FLASH_ECCR_ADDR_MASK"): "ADDR_ECC",
}

# Where a register's name in the SVD is not the macro's last word.
REGISTER_NAMES = {"G0_RCC_PLLCFGR": "PLLSYSCFGR", "G0_DMAMUX_CCR": "C0CR"}

# Values that set several fields: {macro: (register macro, {field: value})}.
# Function-like ones are evaluated with CALLS' argument.
COMPOSITES = {
    "DMA_CCR_ADC_CIRCULAR": ("DMA_CCR", {"MINC": 1, "CIRC": 1, "PSIZE": 1, "MSIZE": 1, "EN": 1}),
    "DMA1_FLAGS": ("DMA1_ISR", {"GIF1": 1, "TCIF1": 1, "HTIF1": 1, "TEIF1": 1}),
    "TIM_CCMR1_PWM1_BOTH": ("TIM_CCMR1", {"OC1M": 6, "OC1PE": 1, "OC2M": 6, "OC2PE": 1}),
    "TIM_CCER_CC1E_CC2E": ("TIM_CCER", {"CC1E": 1, "CC2E": 1}),
    "USART_ICR_CLEAR": ("USART_ICR", {"PECF": 1, "FECF": 1, "NCF": 1, "ORECF": 1,
                                      "IDLECF": 1, "TCCF": 1}),
    # A 4-bit pin configuration of CRL/CRH: MODE in bits 0-1, CNF in 2-3
    # (checked on pin 0's pair).
    "GPIO_ANALOG": ("GPIOA_CRL", {"MODE0": 0, "CNF0": 0}),
    "GPIO_AF_PUSH_PULL_50MHZ": ("GPIOA_CRL", {"MODE0": 3, "CNF0": 2}),
    "GPIO_AF_OPEN_DRAIN_50MHZ": ("GPIOA_CRL", {"MODE0": 3, "CNF0": 3}),
    "GPIO_MODE_AF": ("GPIOA_MODER", {"MODER0": 2}),
    "GPIO_MODE_ANALOG": ("GPIOA_MODER", {"MODER0": 3}),
    # PLL multiplication factor: x N is N - 2 (RM0008 7.3.2, RM0360 6.4.2).
    "RCC_CFGR_PLLMUL9": ("RCC_CFGR", {"PLLMUL": 9 - 2}),
    "RCC_CFGR_PLLMUL6": ("RCC_CFGR", {"PLLMUL": 6 - 2}),
    "RCC_CFGR_PLLMUL12": ("RCC_CFGR", {"PLLMUL": 12 - 2}),
    "G0_GPIO_MODE_AF": ("G0_GPIOA_MODER", {"MODER0": 2}),
    "G0_GPIO_MODE_ANALOG": ("G0_GPIOA_MODER", {"MODER0": 3}),
    "G0_RCC_PLLCFGR_64MHZ_FROM_HSI16": ("G0_RCC_PLLCFGR", {"PLLSRC": 2, "PLLM": 0, "PLLN": 8,
                                                           "PLLREN": 1, "PLLR": 1}),
    "G0_FLASH_SR_ERRORS": ("G0_FLASH_SR", {f: 1 for f in ("OPERR", "PROGERR", "WRPERR", "PGAERR", "SIZERR",
                                                          "PGSERR", "MISERR", "FASTERR", "RDERR",
                                                          "OPTVERR")}),
}
# A part's own meaning of a shared one. ST's STM32G031 SVD numbers DMA
# ISR's flags by their bit (GIF0, TCIF1, HTIF2, TEIF3 for channel 1).
PART_COMPOSITES = {
    "STM32G031": {"DMA1_FLAGS": ("DMA1_ISR", {"GIF0": 1, "TCIF1": 1, "HTIF2": 1, "TEIF3": 1})},
}

# Interrupt numbers: {macro: {part: the SVD's interrupt name}}.
IRQS = {
    "USART1_IRQ": {"STM32F103xx": "USART1", "STM32F030": "USART1"},
    "USART2_IRQ": {"STM32F103xx": "USART2"},
    "USART3_IRQ": {"STM32F103xx": "USART3"},
    "DMA1_CH1_IRQ": {"STM32F103xx": "DMA1_Channel1"},
    "DMA1_CH7_IRQ": {"STM32F103xx": "DMA1_Channel7"},
    "DMA1_CH3_IRQ": {"STM32F030": "DMA_CH2_3"},
    "G0_USART1_IRQ": {"STM32G031": "USART1"},
    "G0_USART2_IRQ": {"STM32G031": "USART2"},
    "G0_DMA1_CH2_3_IRQ": {"STM32G031": "DMA_Channel2_3"},
}

# Not described by ST's SVD files: where the value comes from.
NOT_IN_SVD = {
    "REG32": "the access helper itself",
    "SYSTICK_CTRL": "ARM core (ARMv7-M ARM B3.3.2, ARMv6-M ARM B3.3.2)",
    "SYSTICK_LOAD": "ARM core (ARMv7-M ARM B3.3.2)",
    "SYSTICK_VAL": "ARM core (ARMv7-M ARM B3.3.2)",
    "SYSTICK_ENABLE_CORE_CLOCK_IRQ": "ARM core SYST_CSR (ARMv7-M ARM B3.3.3)",
    "SCB_ICSR": "ARM core (ARMv7-M ARM B3.2.2)",
    "SCB_ICSR_PENDSTSET": "ARM core ICSR (ARMv7-M ARM B3.2.4)",
    "SCB_AIRCR": "ARM core (ARMv7-M ARM B3.2.2)",
    "SCB_AIRCR_RESET": "ARM core AIRCR (ARMv7-M ARM B3.2.6)",
    # The fault registers and the MPU: the M3 only (ARMv6-M has none of them).
    "SCB_SHCSR": "ARM core (ARMv7-M ARM B3.2.2; PM0056 SHCSR)",
    "SCB_SHCSR_FAULTS_OWN": "ARM core SHCSR MEMFAULTENA/BUSFAULTENA/USGFAULTENA (PM0056)",
    "SCB_CFSR": "ARM core (ARMv7-M ARM B3.2.2; PM0056 CFSR)",
    "SCB_HFSR": "ARM core (ARMv7-M ARM B3.2.2; PM0056 HFSR)",
    "MPU_CTRL": "ARM core PMSAv7 (ARMv7-M ARM B3.5; PM0056 MPU_CTRL)",
    "MPU_RNR": "ARM core PMSAv7 (ARMv7-M ARM B3.5; PM0056 MPU_RNR)",
    "MPU_RBAR": "ARM core PMSAv7 (ARMv7-M ARM B3.5; PM0056 MPU_RBAR)",
    "MPU_RASR": "ARM core PMSAv7 (ARMv7-M ARM B3.5; PM0056 MPU_RASR)",
    "MPU_CTRL_ON_DEFAULT_MAP": "ARM core MPU_CTRL ENABLE|PRIVDEFENA (PM0056)",
    "FLASH_KEY1": "RM0008 3.3.1 / RM0360 3.2.2 (key values)",
    "FLASH_KEY2": "RM0008 3.3.1 / RM0360 3.2.2 (key values)",
    "IWDG_KEY_START": "RM0008 19.4.1 / RM0360 18.4.1 (key values)",
    "IWDG_KEY_ACCESS": "RM0008 19.4.1 / RM0360 18.4.1 (key values)",
    "IWDG_KEY_RELOAD": "RM0008 19.4.1 / RM0360 18.4.1 (key values)",
    "UID_ADDR": "system memory: RM0008 30.2, RM0360 29.1",
    "G0_UID_ADDR": "system memory: RM0444 40.1",
    "G0_FLASH_KEY1": "RM0444 3.3.6 (key values)",
    "G0_FLASH_KEY2": "RM0444 3.3.6 (key values)",
    "IWDG_COUNTS_PER_MS": "the LSI's frequency (DS12992; parts.toml lsi_hz) over PR 0's 4",
    "G0_DMAMUX_REQ_ADC": "DMAMUX request numbers: RM0444 11.3.2",
    "G0_DMAMUX_REQ_USART1_RX": "DMAMUX request numbers: RM0444 11.3.2",
    "G0_DMAMUX_REQ_USART1_TX": "DMAMUX request numbers: RM0444 11.3.2",
    "G0_DMAMUX_REQ_USART2_RX": "DMAMUX request numbers: RM0444 11.3.2",
    "G0_DMAMUX_REQ_USART2_TX": "DMAMUX request numbers: RM0444 11.3.2",
}
# Not in one part's SVD only.
PART_NOT_IN_SVD = {
    "STM32G031": {n: "ARM core NVIC (ARMv6-M ARM B3.4): ST's STM32G031 SVD has no NVIC"
                  for n in ("NVIC_ISER", "NVIC_ICER", "NVIC_ICPR")},
}
