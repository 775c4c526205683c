#include "ports/stm32f1/stm32f1_uart.h"

#include <stddef.h>

#include "ports/stm32f1/stm32f1_regs.h"
#include "ports/stm32_common/systick_clock.h"

static struct usart_hd *bus_usart;
static struct dma_rx *bus_dma;
static const struct stm32f1_bus *bus_hw;

void port_uart_irq(void)
{
    usart_hd_irq(bus_usart);
}

void port_uart_dma_irq(void)
{
    DMA1_IFCR = bus_hw->dma_rx_flags;
    dma_rx_lap(bus_dma);
}

void port_uart_send_by_dma(struct usart_hd *usart)
{
    usart_hd_tx_dma(usart, bus_hw->dma_tx_ccr);
}

void port_uart_init(struct usart_hd *usart, struct hal_rx_ring *ring, struct dma_rx *dma,
                    uint32_t pclk_hz, const struct stm32f1_bus *bus)
{
    bus_usart = usart;
    bus_hw = bus;
    usart_hd_init(usart, bus->usart_base, pclk_hz, 115200u, true, ring, systick_now_us);
    if (dma != NULL) {
        bus_dma = dma;
        RCC_AHBENR |= RCC_AHBENR_DMA1;
        dma_rx_start(dma, bus->dma_rx_ccr, bus->usart_base + USART_DR_OFFSET, ring);
        usart_hd_rx_dma(usart);
        NVIC_ISER(bus->dma_rx_irq / 32u) = 1u << (bus->dma_rx_irq % 32u);
    }
}
