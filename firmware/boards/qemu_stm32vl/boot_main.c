/* The bootloader on QEMU's stm32vldiscovery. QEMU models no flash
 * controller, so the slot is read-only here: this image checks the
 * application and starts it, as the board's does; updates are the
 * simulator's and the reference board's. The application keeps its config
 * store in RAM on this board, so the bootloader finds none there (QEMU's
 * unwritten flash reads 0) and answers at the factory ID and baud rate.
 * What differs from the other STM32 boards; the start-up path is the
 * boards' shared one (boards/common/boot_start.h). */
#include "board.h"
#include "qemu_board.h"
#include "ports/stm32f1/stm32f1_regs.h"
#include "ports/stm32f1/stm32f1_bus.h"
#include "ports/stm32f1/stm32f1_uart.h"

static bool refuse_erase(void *ctx, uint32_t addr)
{
    (void)ctx;
    (void)addr;
    return false;
}

static bool refuse_program(void *ctx, uint32_t addr, const uint8_t *data)
{
    (void)ctx;
    (void)addr;
    (void)data;
    return false;
}

static void flash_read(void *ctx, uint32_t addr, uint8_t *dst, uint32_t len)
{
    (void)ctx;
    const volatile uint8_t *src = (const volatile uint8_t *)(uintptr_t)addr;
    for (uint32_t i = 0; i < len; i++) {
        dst[i] = src[i];
    }
}

/* Read-only flash; the application's store is in its RAM: none here. */
static void qemu_flash_init(struct hal_flash *config, struct hal_flash *slot)
{
    *slot = (struct hal_flash){.page_size = 1024u, .erase_page = refuse_erase, .write_block = 2,
                               .program = refuse_program, .read = flash_read};
    *config = *slot;
    config->page_addr[0] = 0x0801F800u;
    config->page_addr[1] = 0x0801FC00u;
}

static void qemu_service(struct usart_hd *usart)
{
    usart_hd_service(usart); /* QEMU's USART raises no transmit interrupts */
    usart_hd_irq(usart);     /* and the receive interrupt is not in the table */
}

#define BOARD_USART struct usart_hd
#define BOARD_BOOT_BUS PORT_UART_BUS_INTERRUPT
#define BOARD_CORE_HZ QEMU_CORE_HZ
#define BOARD_RX_GAP_TOLERANCE_US QEMU_RX_GAP_TOLERANCE_US
#define board_clock_init() ((void)0) /* QEMU's clock is fixed */
#define bus_pins_init() ((void)0)    /* and its USART has no pins to set */
#define board_boot_flash_init qemu_flash_init
STM32F1_BUS_DEFINED

/* No DMA model: by interrupt. */
#define board_boot_uart_start(usart, ring, dma)                          \
    do {                                                                 \
        (void)(dma);                                                     \
        port_uart_init((usart), (ring), NULL, QEMU_CORE_HZ, &bus_hw);    \
        usart_hd_tx_polled(usart);                               \
        usart_hd_no_echo(usart);                                 \
    } while (0)
#define board_boot_stop_dma() ((void)0)
#define board_boot_service qemu_service

#include "boards/common/boot_start.h"
