/* A free-running microsecond clock from SysTick (1 ms interrupt plus the
 * counter in between); wraps at 2^32 us like hal_port.bus.now_us wants. */
#ifndef STM32_SYSTICK_CLOCK_H
#define STM32_SYSTICK_CLOCK_H

#include <stdint.h>

void systick_clock_init(uint32_t core_hz);
/* Safe from any interrupt priority. */
uint32_t systick_now_us(void);
/* The same, shaped as hal_port.bus.now_us (ctx unused). */
uint32_t systick_bus_now_us(void *ctx);

#endif
