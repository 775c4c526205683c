/* Reference board: STM32F103 servo controller. */
#include "port_stm32f103.h"
#include "servo.h"

static struct servo servo;
static struct hal_port port;

int main(void)
{
    port_init(&port, &servo);
    servo_init(&servo, &port);
    for (;;) {
        servo_poll(&servo);
    }
}
