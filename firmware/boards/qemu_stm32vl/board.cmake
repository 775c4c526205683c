# QEMU's stm32vldiscovery (STM32F100RB, Cortex-M3, 24 MHz, 128 KB flash,
# 8 KB RAM) with the servo's plant in the image; ID, flash map and front
# end in board.h.
set(SERVO_BOARD_CPU cortex-m3)
set(SERVO_BOARD_PORT servo_stm32f1)
set(SERVO_BOARD_STARTUP ${PROJECT_SOURCE_DIR}/firmware/startup/startup_stm32f103.c)
