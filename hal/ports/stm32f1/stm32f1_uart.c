#include "ports/stm32f1/stm32f1_uart.h"

#include <stddef.h>

#include "ports/stm32f1/stm32f1_regs.h"
#include "ports/stm32_common/systick_clock.h"

static struct usart_hd *bus_usart;
static struct dma_rx *bus_dma;

void USART1_IRQHandler(void);
void USART1_IRQHandler(void)
{
    usart_hd_irq(bus_usart);
}

void DMA1_Channel5_IRQHandler(void);
void DMA1_Channel5_IRQHandler(void)
{
    DMA1_IFCR = DMA1_CH5_FLAGS;
    dma_rx_lap(bus_dma);
}

void port_uart_send_by_dma(struct usart_hd *usart)
{
    usart_hd_tx_dma(usart, DMA1_CCR4_ADDR);
}

void port_uart_init(struct usart_hd *usart, struct hal_rx_ring *ring, struct dma_rx *dma,
                    uint32_t pclk_hz)
{
    bus_usart = usart;
    usart_hd_init(usart, USART1_BASE, pclk_hz, 115200u, true, ring, systick_now_us);
    if (dma != NULL) {
        bus_dma = dma;
        RCC_AHBENR |= RCC_AHBENR_DMA1;
        dma_rx_start(dma, DMA1_CCR5_ADDR, USART1_BASE + USART_DR_OFFSET, ring);
        usart_hd_rx_dma(usart);
        NVIC_ISER(DMA1_CH5_IRQ / 32u) = 1u << (DMA1_CH5_IRQ % 32u);
    }
}
