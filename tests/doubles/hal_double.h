/* A hal_port for unit tests: a clock the test moves, a UART that records
 * what the servo sends, and the flash double. */
#ifndef TEST_HAL_DOUBLE_H
#define TEST_HAL_DOUBLE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "flash_double.h"
#include "hal/hal_port.h"

#define HAL_DOUBLE_SENT_MAX 4096u

struct hal_double {
    struct hal_port port;
    struct flash_double flash;
    uint32_t now_us;
    uint8_t sent[HAL_DOUBLE_SENT_MAX];
    size_t sent_length;
    unsigned sends;       /* uart_send calls */
    bool tx_busy;         /* uart_tx_done answers !tx_busy */
    uint32_t baud;        /* last uart_set_baud */
    unsigned baud_changes;
};

void hal_double_init(struct hal_double *h);
/* Forgets what was sent so far. */
void hal_double_clear_sent(struct hal_double *h);

#endif
