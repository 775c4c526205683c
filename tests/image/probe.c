/* Tiny images for testing cmake/check-image.sh: built with -DUSE_FLOAT or
 * -DBIG_RAM to break one rule, or plain to pass. */
#include <stdint.h>

void Reset_Handler(void);

#ifdef USE_FLOAT
volatile float gain = 1.5f;
volatile int32_t out;
#endif
#ifdef BIG_RAM
volatile uint8_t big[9000];
#endif

__attribute__((section(".isr_vector"), used)) static const uint32_t vectors[2] = {0, 0};

void Reset_Handler(void)
{
#ifdef USE_FLOAT
    out = (int32_t)(gain * (float)out);
#endif
#ifdef BIG_RAM
    big[8999] = 1;
#endif
    for (;;) {
    }
}
