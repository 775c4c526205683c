/* le_get_u32 as a call (byte_order.h says where). */
#include "registers/byte_order.h"

#if defined(SERVO_SIZE_FIRST) && !defined(STARTUP_BOOTLOADER)
uint32_t le_get_u32(const uint8_t *p)
{
    return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) |
           ((uint32_t)p[3] << 24);
}
#endif
