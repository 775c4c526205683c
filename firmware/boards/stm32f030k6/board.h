/* The Cortex-M0 servo board: STM32F030K6 (48 MHz, 32 KB flash, 4 KB RAM;
 * RM0360). The F0 boards' shared main.c, boot_main.c and board_io.c
 * (firmware/boards/common/stm32f0), its linker scripts (made from
 * hal/ports/stm32_common/linker/app.ld.in and boot.ld.in), servoctl's
 * image command and the virtual board read this file: plain numbers, one
 * per line. */
#ifndef BOARD_H
#define BOARD_H

#define BOARD_ID 0x0030 /* the update image header's board field */

/* Flash (RM0360 3.2: 1 KB pages): the 4 KB bootloader, the 24 KB
 * application slot, the fault history's two pages, the config store's two
 * at the end. */
#define BOARD_FLASH_BASE 0x08000000
#define BOARD_FLASH_PAGE 1024
#define BOARD_BOOT_SIZE 4096
#define BOARD_SLOT_BASE 0x08001000
#define BOARD_SLOT_PAGES 24
#define BOARD_FAULT_PAGE0 0x08007000
#define BOARD_FAULT_PAGE1 0x08007400
#define BOARD_CONFIG_PAGE0 0x08007800
#define BOARD_CONFIG_PAGE1 0x08007C00

/* RAM; its last BOARD_RAM_KEPT bytes are kept across resets (board_derived.h).
 * The M0 has no vector table offset register: the application builds its
 * table at the start of RAM and maps RAM at 0 (RM0360 9.1.1, MEM_MODE). */
#define BOARD_RAM_BASE 0x20000000
#define BOARD_RAM_SIZE 4096
#define BOARD_RAM_VECTORS_SIZE 192

/* The bus: USART1, its DMA1 requests on channels 2 (TX) and 3 (RX)
 * (RM0360; ports/stm32f0/stm32f0_bus.h checks), its TX on PA9. A pin is
 * 0xPN: port P (0 A, 1 B), pin N (ports/stm32f0/stm32f0_pins.h checks
 * each is its function's). */
#define BOARD_BUS_USART 1
#define BOARD_BUS_DMA_TX 2
#define BOARD_BUS_DMA_RX 3
#define BOARD_BUS_TX_PIN 0x09

/* The bridge: TIM3's CH1 (PA6) and CH2 (PA7) into IN1 and IN2. */
#define BOARD_BRIDGE_TIMER 3
#define BOARD_BRIDGE_IN1_PIN 0x06
#define BOARD_BRIDGE_IN2_PIN 0x07

/* The ADC channels the scan reads, in ascending order: IN0-IN3 on PA0-PA3. */
#define BOARD_ADC_SUPPLY 0
#define BOARD_ADC_CURRENT 1
#define BOARD_ADC_NTC 2
#define BOARD_ADC_POSITION 3
/* The application's stack: cmake/stack-report.py's static worst case is
 * 760 B (main's deepest path, every packet handler and HAL operation
 * behind its pointers, the deepest interrupt and its 32 B frame). It does
 * not see a pointer call to a function also called directly, nor the
 * fault handlers' frame: 1280 B leaves 520 B over the worst case for
 * them (the check's 25 % margin asks 1014 B). The deepest it has been is
 * item 74's (docs/footprint.md). */
#define BOARD_APP_STACK_SIZE 1280


/* The receive ring (hal/hal_rx_ring.h): a page erase stalls the CPU up
 * to 40 ms (DS9773, "Flash memory characteristics", tERASE) while the DMA
 * goes on writing; 40 ms at 115200 baud is 460 bytes. 4 KB of RAM covers
 * that rate, not 1 Mbaud (4000 bytes): above 115200 what an erase overruns
 * is counted (ReadStore), not prevented. The bootloader erases only while
 * no request waits. */
#define BOARD_RX_RING_BYTES 512
#define BOARD_BOOT_RX_RING_BYTES 256
/* The longest control tick and a main-loop pass at 48 MHz, rounded up to
 * whole us: the target bench's servo_tick_worst + idle_poll, in cycles
 * (docs/benchmark.md; tools/tests/test_doc_figures.py checks it). */
#define BOARD_TICK_AND_PASS_US 48
/* The analogue front end and the motor: the reference servo's. */
#include "boards/common/reference_servo.h"

/* Pins: this folder's README.md. */

#include "boards/board_derived.h"

#endif
