/* The reference servo board: STM32F103C8 (Cortex-M3, 72 MHz, 64 KB flash,
 * 20 KB RAM; RM0008). The F1 boards' shared main.c, boot_main.c and
 * board_io.c (firmware/boards/common/stm32f1), its linker scripts (made
 * from hal/ports/stm32_common/linker/app.ld.in and boot.ld.in), servoctl's
 * image command and the virtual board read this file: plain numbers, one
 * per line. */
#ifndef BOARD_H
#define BOARD_H

#define BOARD_ID 0x0103 /* the update image header's board field */

/* Flash (RM0008 3.3.3: 1 KB pages): the 4 KB bootloader, the application
 * slot, the fault history's two pages, the config store's two at the end. */
#define BOARD_FLASH_BASE 0x08000000
#define BOARD_FLASH_PAGE 1024
#define BOARD_BOOT_SIZE 4096
#define BOARD_SLOT_BASE 0x08001000
#define BOARD_SLOT_PAGES 56
#define BOARD_FAULT_PAGE0 0x0800F000
#define BOARD_FAULT_PAGE1 0x0800F400
#define BOARD_CONFIG_PAGE0 0x0800F800
#define BOARD_CONFIG_PAGE1 0x0800FC00

/* RAM; its last 16 bytes are the word that keeps the bootloader (boot_jump.h). */
#define BOARD_RAM_BASE 0x20000000
#define BOARD_RAM_SIZE 20480
/* The stack starts on a 256-byte boundary: its bottom 256 bytes are the
 * MPU's guard region, which must be aligned to its size (ARMv7-M B3.5.8;
 * ports/stm32_common/fault_keep.c). */
#define BOARD_STACK_ALIGN 256

/* The bus: USART1, its DMA1 requests on channels 4 (TX) and 5 (RX), as
 * RM0008 Table 78 has them (ports/stm32f1/stm32f1_bus.h checks), its TX
 * on PA9. A pin is 0xPN: port P (0 A, 1 B, 2 C, 3 D), pin N
 * (ports/stm32f1/stm32f1_pins.h checks each is its function's). */
#define BOARD_BUS_USART 1
#define BOARD_BUS_DMA_TX 4
#define BOARD_BUS_DMA_RX 5
#define BOARD_BUS_TX_PIN 0x09

/* The bridge: TIM3's CH1 (PA6) and CH2 (PA7) into IN1 and IN2. */
#define BOARD_BRIDGE_TIMER 3
#define BOARD_BRIDGE_IN1_PIN 0x06
#define BOARD_BRIDGE_IN2_PIN 0x07

/* The ADC1 channels the scan reads: IN0-IN3 on PA0-PA3. */
#define BOARD_ADC_SUPPLY 0
#define BOARD_ADC_CURRENT 1
#define BOARD_ADC_NTC 2
#define BOARD_ADC_POSITION 3


/* The receive ring (hal/hal_rx_ring.h): a page erase stalls the CPU up
 * to 40 ms (DS5319, "Flash memory characteristics", tERASE) while the DMA
 * goes on writing; 40 ms at 1 Mbaud is 4000 bytes, so no frame is lost to
 * flash work at any rate. The bootloader erases only while no request
 * waits: 256 bytes. */
#define BOARD_RX_RING_BYTES 4096
#define BOARD_BOOT_RX_RING_BYTES 256
/* The longest control tick and a main-loop pass at 72 MHz, rounded up to
 * whole us: the target bench's servo_tick_worst + idle_poll, in cycles
 * (docs/benchmark.md; tools/tests/test_doc_figures.py checks it). */
#define BOARD_TICK_AND_PASS_US 18

/* The analogue front end and the motor: the reference servo's. */
#include "boards/common/reference_servo.h"

/* Pins: this folder's README.md. */

#include "boards/board_derived.h"

#endif
