#include "ports/stm32f0/stm32f0_uart.h"

#include "ports/stm32f0/stm32f0_regs.h"

static struct usart_v2_hd *bus_usart;
static struct dma_rx *bus_dma;

void USART1_IRQHandler(void);
void USART1_IRQHandler(void)
{
    usart_v2_hd_irq(bus_usart);
}

void DMA1_Channel2_3_IRQHandler(void);
void DMA1_Channel2_3_IRQHandler(void)
{
    DMA1_IFCR = DMA1_FLAGS(3u);
    dma_rx_lap(bus_dma);
}

void port_uart_init(struct usart_v2_hd *usart, struct hal_rx_ring *ring, struct dma_rx *dma,
                    uint32_t pclk_hz, enum port_uart_send send)
{
    bus_usart = usart;
    bus_dma = dma;
    RCC_AHBENR |= RCC_AHBENR_DMA1;
    dma_rx_start(dma, DMA1_CCR_ADDR(3u), USART1_BASE + USART_RDR_OFFSET, ring);
    bool by_dma = send == PORT_UART_SEND_DMA;
    usart_v2_hd_init(usart, USART1_BASE, pclk_hz, 115200u, by_dma ? DMA1_CCR2_ADDR : 0u);
    NVIC_ISER(0) = by_dma ? (1u << DMA1_CH3_IRQ) | (1u << USART1_IRQ) : 1u << DMA1_CH3_IRQ;
}
