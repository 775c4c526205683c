/* Start-up for the benchmarks on QEMU's lm3s6965evb (any Cortex-M): the
 * vector table, .data and .bss, semihosting for printf, main, and exit
 * through semihosting. */
#include <stdint.h>
#include <stdlib.h>

extern uint32_t _sidata, _sdata, _edata, _sbss, _ebss, _estack;
extern int main(void);
extern void initialise_monitor_handles(void);
void Reset_Handler(void);
void SysTick_Handler(void); /* the STM32F1 port's clock, read by bench_protocol */
void Unused_Handler(void);

__attribute__((weak)) void SysTick_Handler(void)
{
}

void Unused_Handler(void)
{
    for (;;) {
    }
}

void Reset_Handler(void)
{
    const uint32_t *from = &_sidata;
    for (uint32_t *to = &_sdata; to < &_edata;) {
        *to++ = *from++;
    }
    for (uint32_t *to = &_sbss; to < &_ebss;) {
        *to++ = 0;
    }
    initialise_monitor_handles();
    exit(main());
}

__attribute__((section(".vectors"), used)) static const void *const vectors[16] = {
    &_estack,
    (const void *)Reset_Handler,
    [2 ... 14] = (const void *)Unused_Handler,
    [15] = (const void *)SysTick_Handler,
};
