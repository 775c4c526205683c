#ifndef PORT_STM32F103_H
#define PORT_STM32F103_H

#include "hal/hal_port.h"
#include "servo.h"

/* Fills port and routes the receive interrupt to servo. */
void port_init(struct hal_port *port, struct servo *servo);

#endif
