/* The application's hooks every STM32 board's hal_port names the same way
 * (app_start.h, and the QEMU board's main.c): the version of the image the
 * bootloader started, and UpdateEnter's restart into the bootloader. */
#ifndef BOARDS_COMMON_APP_HOOKS_H
#define BOARDS_COMMON_APP_HOOKS_H

#include "bootloader/app_image.h"
#include "bootloader/boot_flow.h"
#include "ports/stm32_common/boot_jump.h"
#include "ports/stm32_common/kept_ram.h"

/* Data ID 7: the version of the image the bootloader started. */
static uint16_t image_version(void *ctx)
{
    (void)ctx;
    return app_image_version_in_place(BOARD_SLOT_BASE);
}

/* UpdateEnter: the word that keeps the bootloader, then a restart. */
static void enter_bootloader(void *ctx, uint8_t id, uint8_t baud_index)
{
    (void)ctx;
    kept_note_planned(id, baud_index); /* not a fault: the next start-up is told */
    boot_restart_with(BOOT_STAY_WORD_ADDR(BOARD_RAM_END), BOOT_STAY_MAGIC);
}

/* A hal_port's fields every STM32 application fills alike. */
#define APP_HOOKS_PORT_FIELDS                                                 \
    .image_version = image_version, .enter_bootloader = enter_bootloader,     \
    .board = BOARD_ID, .tick_and_pass_us = BOARD_TICK_AND_PASS_US

#endif
