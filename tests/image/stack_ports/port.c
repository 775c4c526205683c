/* One of two ports with the same interrupt handler's name: built -DPORT_B,
 * its handler's callee takes a large frame. tests/image/stack_report_own_objects.sh. */
#include <stdint.h>

void USART1_IRQHandler(void);

#ifdef PORT_B
__attribute__((noinline)) static void drain(void)
{
    volatile uint8_t frame[1200];
    frame[0] = 1;
}
#else
__attribute__((noinline)) static void drain(void)
{
    volatile uint8_t byte = 1;
    (void)byte;
}
#endif

void USART1_IRQHandler(void)
{
    drain();
}
