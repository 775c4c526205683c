#include "ports/stm32g0/stm32g0_uart.h"

#include "ports/stm32g0/stm32g0_regs.h"

static struct usart_v2_hd *bus_usart;
static struct dma_rx *bus_dma;
static uint32_t rx_flags;

/* Both USARTs' handlers: the one the bus is on is the one enabled. */
void USART1_IRQHandler(void);
void USART1_IRQHandler(void)
{
    usart_v2_hd_irq(bus_usart);
}

void USART2_IRQHandler(void);
void USART2_IRQHandler(void)
{
    usart_v2_hd_irq(bus_usart);
}

/* Channels 2 and 3's interrupt: the receiving one's lap (the sending one
 * raises none). */
void DMA1_Channel2_3_IRQHandler(void);
void DMA1_Channel2_3_IRQHandler(void)
{
    DMA1_IFCR = rx_flags;
    dma_rx_lap(bus_dma);
}

void g0_uart_init(struct usart_v2_hd *usart, struct hal_rx_ring *ring, struct dma_rx *dma,
                  const struct g0_bus *bus, uint32_t pclk_hz, enum g0_uart_send send)
{
    bus_usart = usart;
    bus_dma = dma;
    rx_flags = DMA1_FLAGS(bus->dma_rx);
    G0_RCC_AHBENR |= G0_RCC_AHBENR_DMA1;
    /* The requests first, while the channels are off (RM0444 11.4.1). */
    G0_DMAMUX_CCR(bus->dma_rx) = bus->req_rx;
    G0_DMAMUX_CCR(bus->dma_tx) = bus->req_tx;
    dma_rx_start(dma, DMA1_CCR_ADDR(bus->dma_rx), bus->usart + G0_USART_RDR_OFFSET, ring);
    bool by_dma = send == G0_UART_SEND_DMA;
    usart_v2_hd_init(usart, bus->usart, pclk_hz, 115200u, by_dma ? DMA1_CCR_ADDR(bus->dma_tx) : 0u);
    NVIC_ISER(0) = by_dma ? (1u << G0_DMA1_CH2_3_IRQ) | (1u << bus->irq) : 1u << G0_DMA1_CH2_3_IRQ;
}
