# QEMU's stm32vldiscovery (STM32F100RB, Cortex-M3, 24 MHz, 128 KB flash,
# 8 KB RAM) with the servo's plant in the image; the reference board's
# calibration.
set(SERVO_BOARD_CPU cortex-m3)
set(SERVO_BOARD_PORT servo_stm32f1)
set(SERVO_BOARD_STARTUP ${PROJECT_SOURCE_DIR}/firmware/startup/startup_stm32f103.c)
set(SERVO_BOARD_LINKER ${CMAKE_CURRENT_LIST_DIR}/stm32f100xb.ld)
set(SERVO_BOARD_ID 0x0100)
set(SERVO_BOARD_BOOT_LINKER ${CMAKE_CURRENT_LIST_DIR}/stm32f100xb_boot.ld)
