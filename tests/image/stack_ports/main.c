/* The image of tests/image/stack_report_own_objects.sh: it links port A. */
#include <stdint.h>

int main(void);
void Reset_Handler(void);
void USART1_IRQHandler(void);

__attribute__((section(".isr_vector"), used)) static void (*const vectors[3])(void) = {
    0, Reset_Handler, USART1_IRQHandler};

int main(void)
{
    for (;;) {
    }
}

void Reset_Handler(void)
{
    (void)main();
}
