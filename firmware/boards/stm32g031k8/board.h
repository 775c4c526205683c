/* The STM32G031K8 servo board (Cortex-M0+ at 64 MHz, 64 KB flash, 8 KB
 * RAM; RM0444). The G0 boards' shared main.c, boot_main.c and board_io.c
 * (firmware/boards/common/stm32g0), its linker scripts (made from
 * hal/ports/stm32_common/linker/app.ld.in and boot.ld.in), servoctl's
 * image command and the virtual board read this file: plain numbers, one
 * per line. */
#ifndef BOARD_H
#define BOARD_H

#define BOARD_ID 0x0031 /* the update image header's board field */

/* Flash (RM0444 3.3.1: 2 KB pages, 64-bit program units with ECC): the
 * 6 KB (three-page) bootloader (not size-first, with the G0's flash
 * driver it is 4.2 KB), the 50 KB application slot, the fault history's
 * two pages, the config store's two at the end. */
#define BOARD_FLASH_BASE 0x08000000
#define BOARD_FLASH_PAGE 2048
#define BOARD_BOOT_SIZE 6144
#define BOARD_SLOT_BASE 0x08001800
#define BOARD_SLOT_PAGES 25
#define BOARD_FAULT_PAGE0 0x0800E000
#define BOARD_FAULT_PAGE1 0x0800E800
#define BOARD_CONFIG_PAGE0 0x0800F000
#define BOARD_CONFIG_PAGE1 0x0800F800
#define BOARD_FLASH_PAGES 32 /* the whole array: flash_g0.c erases a page by its number */

/* RAM; its last BOARD_RAM_KEPT bytes are kept across resets (board_derived.h).
 * The M0+ has a VTOR: the vector tables stay in flash. */
#define BOARD_RAM_BASE 0x20000000
#define BOARD_RAM_SIZE 8192

/* The bus: USART1, its DMAMUX requests 50 (RX) and 51 (TX) routed to
 * DMA1 channels 3 and 2 (RM0444 11.3.2; ports/stm32g0/stm32g0_bus.h
 * checks; USART2's are 52 and 53), its TX on PA9. A pin is 0xPN: port P
 * (0 A, 1 B, 2 C), pin N (ports/stm32g0/stm32g0_pins.h checks each is its
 * function's: USART1 PA9, USART2 PA2 or PA14, on AF1). */
#define BOARD_BUS_USART 1
#define BOARD_BUS_DMA_TX 2
#define BOARD_BUS_DMA_RX 3
#define BOARD_BUS_DMAMUX_TX 51
#define BOARD_BUS_DMAMUX_RX 50
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
/* The application's stack: the M3's reservation; cmake/stack-report.py
 * checks it after every link. */
#define BOARD_APP_STACK_SIZE 1536

/* The receive ring (hal/hal_rx_ring.h): a page erase stalls the CPU for
 * tens of ms (DS12992, "Flash memory characteristics", tERASE) while the
 * DMA goes on writing; 2 KB holds 40 ms up to 460 800 baud. The bootloader
 * erases only while no request waits. */
#define BOARD_RX_RING_BYTES 2048
#define BOARD_BOOT_RX_RING_BYTES 256
/* The longest control tick and a main-loop pass at 64 MHz, rounded up to
 * whole us: the target bench's servo_tick_worst + idle_poll on the
 * Cortex-M0+, in cycles (docs/benchmark.md; tools/tests/test_doc_figures.py
 * checks it). */
#define BOARD_TICK_AND_PASS_US 32
/* The analogue front end and the motor: the reference servo's. */
#include "boards/common/reference_servo.h"

#include "boards/board_derived.h"

#endif
