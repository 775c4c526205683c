/* The image of tests/image/stack_report_nmi.sh: a naked NMI handler that
 * calls, from assembly, a function with a 128-byte frame (the G0's
 * flash_g0_nmi_ecc), beside an interrupt handler with a 64-byte one. */
#include <stdint.h>

int main(void);
void Reset_Handler(void);
void NMI_Handler(void);
void USART1_IRQHandler(void);
int flash_g0_nmi_ecc(void);

__attribute__((section(".isr_vector"), used)) static void (*const vectors[4])(void) = {
    0, Reset_Handler, NMI_Handler, USART1_IRQHandler};
static volatile uint8_t out[4];

__attribute__((noipa, used)) int flash_g0_nmi_ecc(void)
{
    volatile uint8_t frame[128];
    for (unsigned i = 0; i < sizeof frame; i++) {
        frame[i] = out[i % 4u];
    }
    return frame[127];
}

__attribute__((naked)) void NMI_Handler(void)
{
    __asm__ volatile("push {r0, lr}\n bl flash_g0_nmi_ecc\n pop {r0, pc}\n");
}

__attribute__((noipa, used)) void USART1_IRQHandler(void)
{
    volatile uint8_t frame[64];
    for (unsigned i = 0; i < sizeof frame; i++) {
        frame[i] = out[i % 4u];
    }
    out[0] = frame[63];
}

__attribute__((noipa)) int main(void)
{
    for (;;) {
        out[1]++;
    }
}

void Reset_Handler(void)
{
    (void)main();
}
