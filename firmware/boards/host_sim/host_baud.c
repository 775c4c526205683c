/* Alone in its file: <asm/termbits.h> (termios2, any rate as a number)
 * cannot share a translation unit with <termios.h>. */
#include "host_baud.h"

#include <asm/termbits.h>
#include <sys/ioctl.h>

uint32_t host_baud_of(int fd)
{
    struct termios2 t;
    if (ioctl(fd, TCGETS2, &t) != 0) {
        return 0;
    }
    return (uint32_t)t.c_ospeed;
}
