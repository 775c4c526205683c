# The reference servo board: STM32F103C8 (Cortex-M3, 72 MHz, 64 KB flash,
# 20 KB RAM), its pins in README.md; ID, flash map and front end in board.h.
include(${PROJECT_SOURCE_DIR}/cmake/family-stm32f1.cmake)  # CPU, port, startup
set(SERVO_BOARD_PART stm32f103c8)  # its facts: hal/ports/parts.toml, checked against board.h
set(SERVO_BOARD_SOURCES ${CMAKE_CURRENT_LIST_DIR}/board_io.c)         # pins, clocks, ADC, PWM: this board's
