#include "doubles/hal_double.h"

#include <string.h>

static uint32_t now_us(void *ctx)
{
    return ((struct hal_double *)ctx)->now_us;
}

static void uart_send(void *ctx, const uint8_t *data, uint16_t len)
{
    struct hal_double *h = ctx;
    h->sending = data;
    h->sending_at = h->sent_length;
    h->sending_length = len;
    memcpy(h->head_at_send, data, len < sizeof h->head_at_send ? len : sizeof h->head_at_send);
    for (uint16_t i = 0; i < len && h->sent_length < HAL_DOUBLE_SENT_MAX; i++) {
        h->sent[h->sent_length++] = data[i];
    }
    h->sends++;
}

void hal_double_dma_reads(struct hal_double *h)
{
    for (size_t i = 0; h->sending != NULL && i < h->sending_length &&
                       h->sending_at + i < h->sent_length; i++) {
        h->sent[h->sending_at + i] = h->sending[i];
    }
    h->sending = NULL;
}

static bool uart_tx_done(void *ctx)
{
    return !((struct hal_double *)ctx)->tx_busy;
}

static void uart_set_baud(void *ctx, uint32_t baud)
{
    struct hal_double *h = ctx;
    h->baud = baud;
    h->baud_changes++;
}

static void motor_drive(void *ctx, int16_t duty)
{
    struct hal_double *h = ctx;
    h->duty = duty;
    h->coasting = false;
    int16_t a = duty < 0 ? (int16_t)-duty : duty;
    if (a > h->max_abs_duty) {
        h->max_abs_duty = a;
    }
}

static void motor_coast(void *ctx)
{
    struct hal_double *h = ctx;
    h->duty = 0;
    h->coasting = true;
}

static uint16_t encoder_read(void *ctx)
{
    struct hal_double *h = ctx;
    return h->encoder_model ? h->encoder_model(h->model) : h->encoder_raw;
}

static uint32_t serial_number(void *ctx)
{
    (void)ctx;
    return 0x12345678u;
}

/* Field by field: a structure copy is a memcpy call on the size-first M0
 * build, which the target benchmark would count as the firmware's. */
static void sensors_read(void *ctx, struct sensor_raw *out)
{
    const struct hal_double *h = ctx;
    out->supply = h->sensors.supply;
    out->current = h->sensors.current;
    out->ntc = h->sensors.ntc;
}

void hal_double_enter_bootloader(void *ctx, uint8_t id, uint8_t baud_index)
{
    struct hal_double *h = ctx;
    h->bootloader_entries++;
    h->bootloader_link = (uint16_t)(id | baud_index << 8);
}

void hal_double_init(struct hal_double *h)
{
    memset(h, 0, sizeof *h);
    h->rx = (struct hal_rx_ring)HAL_RX_RING_OVER(h->rx_bytes);
    flash_double_init(&h->flash, 1024);
    flash_double_init(&h->fault_flash, 1024);
    h->sensors = (struct sensor_raw){.supply = 7400, .current = 0, .ntc = 2048};
    h->calibration = (struct sensor_calibration){.supply_mv_q12 = SENSOR_Q12_FROM_MICRO(1000u),
                                                 .current_ma_q12 = SENSOR_Q12_FROM_MICRO(1000u)};
    h->port = (struct hal_port){HAL_PORT_HOST_FIELDS(h), .calibration = &h->calibration};
}

void hal_double_clear_sent(struct hal_double *h)
{
    h->sent_length = 0;
    h->sends = 0;
    h->sending = NULL;
}
