# QEMU's stm32vldiscovery (STM32F100RB, Cortex-M3, 24 MHz, 128 KB flash,
# 8 KB RAM) with the servo's plant in the image; ID, flash map and front
# end in board.h.
include(${PROJECT_SOURCE_DIR}/cmake/family-stm32f1.cmake)  # CPU, port, startup
set(SERVO_BOARD_PART stm32f100rb)  # its facts: hal/ports/parts.toml, checked against board.h
