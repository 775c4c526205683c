/* The baud rate the host has set on its end of the pseudo-terminal: a pty
 * carries bytes whatever the rate, so the simulator reads the rate the host
 * asked for and drops what a UART at another rate could not have received. */
#ifndef SIM_HOST_BAUD_H
#define SIM_HOST_BAUD_H

#include <stdint.h>

/* The output speed set on the terminal behind fd, in baud; 0 if unknown. */
uint32_t host_baud_of(int fd);

#endif
