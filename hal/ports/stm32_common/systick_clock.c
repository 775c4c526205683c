#include "ports/stm32_common/systick_clock.h"

#include "ports/stm32_common/stm32_core_regs.h"

static volatile uint32_t uptime_ms;
static uint32_t reload;
static uint32_t us_per_tick_q16; /* 2^16 / ticks per us: a multiply, not a division */

void SysTick_Handler(void);

void SysTick_Handler(void)
{
    uptime_ms++;
}

void systick_clock_init(uint32_t core_hz)
{
    reload = core_hz / 1000u - 1u;
    /* Rounded down, so (reload * us_per_tick_q16) >> 16 stays below 1000. */
    us_per_tick_q16 = 65536u / (core_hz / 1000000u);
    SYSTICK_LOAD = reload;
    SYSTICK_VAL = 0;
    SYSTICK_CTRL = SYSTICK_ENABLE_CORE_CLOCK_IRQ;
}

uint32_t systick_now_us(void)
{
    uint32_t ms;
    uint32_t val;
    uint32_t pending;
    do {
        ms = uptime_ms;
        val = SYSTICK_VAL;
        pending = SCB_ICSR & SCB_ICSR_PENDSTSET;
    } while (ms != uptime_ms);
    /* Called from an interrupt that holds off SysTick: the counter may have
     * wrapped with the millisecond not yet counted. A value read near the
     * top of the count was read after that wrap. */
    if (pending && val > reload / 2u) {
        ms++;
    }
    return ms * 1000u + (((reload - val) * us_per_tick_q16) >> 16);
}

uint32_t systick_bus_now_us(void *ctx)
{
    (void)ctx;
    return systick_now_us();
}
