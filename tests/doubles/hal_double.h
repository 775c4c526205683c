/* A hal_port for unit tests: a clock the test moves, a UART that records
 * what the servo sends, and the flash double. */
#ifndef TEST_HAL_DOUBLE_H
#define TEST_HAL_DOUBLE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "doubles/flash_double.h"
#include "hal/hal_port.h"

#define HAL_DOUBLE_SENT_MAX 4096u

struct hal_double {
    struct hal_port port;
    struct flash_double flash;
    struct flash_double fault_flash; /* the fault history's pages */
    struct hal_rx_ring rx; /* servo_on_rx_byte puts received bytes here */
    uint8_t rx_bytes[512];  /* the smallest an application has (the Cortex-M0 board) */
    uint32_t now_us;
    uint8_t sent[HAL_DOUBLE_SENT_MAX];
    size_t sent_length;
    unsigned sends;       /* bus.send calls */
    /* The last send's bytes, read again as a DMA reads them, while they
     * go out: an answer may be built behind its first bytes. */
    const uint8_t *sending;
    size_t sending_at;
    uint16_t sending_length;
    uint8_t head_at_send[5]; /* its first bytes as they were at the send */
    bool tx_busy;         /* bus.tx_done answers !tx_busy */
    uint32_t baud;        /* last bus.set_baud */
    unsigned baud_changes;
    int16_t duty;         /* last motor.drive */
    int16_t max_abs_duty; /* largest |duty| since the test last cleared it */
    bool coasting;        /* motor.coast since the last motor.drive */
    uint16_t encoder_raw; /* what motor.read_encoder answers without a model */
    /* If set, motor.read_encoder answers this (a plant, an ideal tracker). */
    uint16_t (*encoder_model)(void *model);
    void *model;
    /* What motor.read_sensors answers; with the double's calibration, supply in
     * mV, current in mA, NTC as the protocol's ADC value. Healthy at init:
     * 7400 mV, 0 mA, 2048 (25 degC). */
    struct sensor_raw sensors;
    struct sensor_calibration calibration;
    unsigned bootloader_entries; /* hal_double_enter_bootloader calls */
    uint16_t bootloader_link;    /* the last one's ID | baud index << 8 */
};

void hal_double_init(struct hal_double *h);
/* The last send's bytes as its buffer holds them now (the poll's end). */
void hal_double_dma_reads(struct hal_double *h);
/* Forgets what was sent so far. */
void hal_double_clear_sent(struct hal_double *h);
/* An enter_bootloader op that counts its calls (port.enter_bootloader is
 * NULL until a test sets it to this). */
void hal_double_enter_bootloader(void *ctx, uint8_t id, uint8_t baud_index);

#endif
