/* The image of tests/image/stack_report_lto.sh: a main loop optimised at
 * link time, with a 512-byte frame the report must count. */
#include <stdint.h>

int main(void);
void Reset_Handler(void);
void servo_poll(volatile uint8_t *out);

__attribute__((section(".isr_vector"), used)) static void (*const vectors[2])(void) = {0, Reset_Handler};

__attribute__((noipa)) void servo_poll(volatile uint8_t *out)
{
    volatile uint8_t frame[512];
    for (unsigned i = 0; i < sizeof frame; i++) {
        frame[i] = out[i % 4u];
    }
    out[0] = frame[511];
}

__attribute__((noipa)) int main(void)
{
    static volatile uint8_t out[4];
    for (;;) {
        servo_poll(out);
    }
}

void Reset_Handler(void)
{
    (void)main();
}
