/* le_get_u32 as a call (byte_order.h says where). */
#include "registers/byte_order.h"

#if defined(SERVO_SIZE_FIRST) && !defined(STARTUP_BOOTLOADER)
uint32_t le_get_u32(const uint8_t *p)
{
    return le_get_u32_inline(p);
}
#endif
