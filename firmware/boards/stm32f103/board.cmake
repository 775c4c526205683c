# The reference servo board: STM32F103C8 (Cortex-M3, 72 MHz, 64 KB flash,
# 20 KB RAM), its pins in README.md; ID, flash map and front end in board.h.
include(${PROJECT_SOURCE_DIR}/cmake/family-stm32f1.cmake)  # CPU, port, startup
set(SERVO_BOARD_PART stm32f103c8)  # its facts: hal/ports/parts.toml, checked against board.h
# Its code: the F1 boards' shared main.c, boot_main.c and board_io.c (pins,
# clocks, ADC, PWM), which take every pin and instance from board.h; a
# board whose code differs names its own folder here.
set(SERVO_BOARD_CODE ${PROJECT_SOURCE_DIR}/firmware/boards/common/stm32f1)
set(SERVO_BOARD_SOURCES ${SERVO_BOARD_CODE}/board_io.c)
