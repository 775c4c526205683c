/* QEMU's stm32vldiscovery (STM32F100RB: 128 KB flash, 8 KB RAM), which
 * models the USART only. Its main.c and boot_main.c, its linker scripts
 * (made from hal/ports/stm32_common/linker/app.ld.in and boot.ld.in) and servoctl read
 * this file: plain numbers, one per line. */
#ifndef BOARD_H
#define BOARD_H

#define BOARD_ID 0x0100 /* the update image header's board field */

/* Flash: the 4 KB bootloader, then the slot. QEMU has no flash controller:
 * the application keeps its config store in RAM, standing for the last two
 * pages (BOARD_RAM_CONFIG_BASE). */
#define BOARD_FLASH_BASE 0x08000000
#define BOARD_FLASH_PAGE 1024
#define BOARD_BOOT_SIZE 4096
#define BOARD_SLOT_BASE 0x08001000
#define BOARD_SLOT_PAGES 120
#define BOARD_RAM_CONFIG_BASE 0x0801F800

#define BOARD_RAM_BASE 0x20000000
#define BOARD_RAM_SIZE 8192

/* The bus: USART1 (QEMU's serial port), received byte by byte (QEMU 7.2
 * models no F1 DMA; the channels are RM0008's for it all the same). */
#define BOARD_BUS_USART 1
#define BOARD_BUS_DMA_TX 4
#define BOARD_BUS_DMA_RX 5

/* The analogue front end and the motor: the reference servo's. */
#include "boards/common/reference_servo.h"

/* The receive ring (hal/hal_rx_ring.h): QEMU's board has no flash
 * controller, so nothing stalls the CPU for longer than a main-loop pass. */
#define BOARD_RX_RING_BYTES 256
#define BOARD_BOOT_RX_RING_BYTES 256
/* The longest control tick and a main-loop pass of the Cortex-M3 bench
 * figures (docs/benchmark.md) at the STM32F100's 24 MHz: 41.2 + 10.7 us. */
#define BOARD_TICK_AND_PASS_US 52

#include "boards/board_derived.h"

#endif
